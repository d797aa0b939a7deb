"""Where room tasks run: a local pool of spawned worker processes, or Ray actors.

Both executors run the same per-room functions (:mod:`sgdata.pipeline.room_tasks`) with the
same plain arguments; every output is written by the task itself, so the dataset's bytes do
not depend on which executor ran it, in which order, or on how many workers.

Workers are spawned, never forked: an EGL context does not survive ``fork`` (DESIGN §9). Each
worker keeps its renderer alive across the rooms it is given. Every worker rasterises on one
llvmpipe thread (``LP_NUM_THREADS=1``, ignored by GPU EGL): llvmpipe's output can differ in
edge pixels with its thread count, and parallelism comes from the workers instead (two
single-threaded workers render 2.1x the views of one default process on 2 cores).

No worker outlives its parent: local workers ask the kernel for SIGKILL when their parent dies
(``PR_SET_PDEATHSIG``) and re-check the parent's pid once armed, so a ``kill -9`` of
``sgdata generate`` takes them with it (the multiprocessing resource tracker then sees its pipe
close and exits too). A local Ray instance started by the run shares the driver's fate the
same way (Ray starts its processes with ``fate_share``).

A local worker that dies of a signal (a segfault in the driver, an abort, the kernel's
out-of-memory killer) breaks the pool; the run then ends in one :class:`WorkerError` naming the
worker, the signal and the task it was on (each worker notes its task in a file of a temporary
folder while it runs it), and ``--resume`` finishes it.
"""

from __future__ import annotations

import ctypes
import multiprocessing
import os
import signal
import tempfile
import time
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass
from multiprocessing.process import BaseProcess
from pathlib import Path
from typing import Any

from sgdata.errors import ConfigError, WorkerError

__all__ = [
    "EXECUTORS",
    "WORKER_ENV",
    "run_tasks",
    "executor_session",
    "die_with_parent",
    "task_name",
]

EXECUTORS = ("local", "ray")
WORKER_ENV = {"LP_NUM_THREADS": "1"}  # set in every worker before pyrender or Mesa load
_PR_SET_PDEATHSIG = 1  # <linux/prctl.h>


def run_tasks(
    fn: Callable[..., dict],
    payloads: Iterable[tuple],
    *,
    workers: int = 1,
    executor: str = "local",
    address: str | None = None,
    retries: int = 2,
) -> Iterator[dict]:
    """Run ``fn(*payload)`` for every payload; yield results as they finish.

    Args:
        executor: ``local`` (a pool of spawned processes) or ``ray``.
        address: with ``ray``, the cluster to join (``ray start --head`` prints it); without
            it, a local instance bound to 127.0.0.1 with the dashboard off.
        retries: with ``ray``, how often a task whose worker died is tried again.

    A task's exception (an ``SgdataError`` included) is re-raised here after the workers are
    stopped, so finished tasks stay recorded and the run can resume.
    """
    _check(executor, address)
    jobs = list(payloads)
    if not jobs:
        return
    if executor == "ray":
        run_on_ray = _ray_executor().run_on_ray

        yield from run_on_ray(fn, jobs, workers=workers, address=address, retries=retries,
                              env=WORKER_ENV, name=task_name)  # fmt: skip
        return
    yield from _run_local(fn, jobs, workers=workers)


@contextmanager
def executor_session(
    executor: str = "local", *, workers: int, address: str | None = None
) -> Iterator[None]:
    """Keep the executor's engine up across several :func:`run_tasks` calls: a local Ray
    instance, or the local pool, starts once per command, not once per phase. A spawned
    worker takes seconds to import torch and the renderer; a command of many phases (the
    stop policy's four navigations, each with maps and episodes) paid that 24 times.
    Sessions nest: an inner one with the same workers keeps the outer one's pool."""
    _check(executor, address)
    if executor == "ray":
        with _ray_executor().ray_session(address, workers, WORKER_ENV):
            yield
        return
    outer = _LOCAL_SESSION.get()
    if outer is not None and outer.workers == workers:
        yield
        return
    with tempfile.TemporaryDirectory(prefix="sgdata-tasks-") as notes:
        session = _LocalSession(workers, Path(notes))
        token = _LOCAL_SESSION.set(session)
        try:
            yield
        finally:
            _LOCAL_SESSION.reset(token)
            session.close()


@dataclass
class _LocalSession:
    """A local pool kept across :func:`run_tasks` calls; started by the first task."""

    workers: int
    notes: Path
    pool: ProcessPoolExecutor | None = None

    def started_pool(self) -> ProcessPoolExecutor:
        if self.pool is None or getattr(self.pool, "_broken", False):  # a dead worker broke it
            self.close()
            self.pool = _pool(self.workers)
        return self.pool

    def close(self) -> None:
        if self.pool is not None:
            self.pool.shutdown(cancel_futures=True)


_LOCAL_SESSION: ContextVar[_LocalSession | None] = ContextVar("sgdata_local_pool", default=None)


def _ray_executor():  # noqa: ANN202
    """The Ray executor module; a clear error when Ray is not installed."""
    try:
        from sgdata.pipeline import ray_executor
    except ModuleNotFoundError as exc:
        if exc.name != "ray":
            raise
        raise ConfigError(
            "--executor ray needs Ray: pip install 'sgdata[ray]' (or pip install 'ray==2.60.*')"
        ) from None
    return ray_executor


def _check(executor: str, address: str | None) -> None:
    if executor not in EXECUTORS:
        raise ConfigError(f"--executor {executor!r}: expected one of {', '.join(EXECUTORS)}")
    if address is not None and executor != "ray":
        raise ConfigError("--address is for --executor ray; drop it or add --executor ray")


def _run_local(fn: Callable[..., dict], jobs: list[tuple], *, workers: int) -> Iterator[dict]:
    session = _LOCAL_SESSION.get()
    if session is not None and session.workers == workers:
        yield from _drain(session.started_pool(), fn, jobs, session.notes)
        return
    with (
        tempfile.TemporaryDirectory(prefix="sgdata-tasks-") as notes,
        _pool(min(workers, len(jobs))) as pool,
    ):
        yield from _drain(pool, fn, jobs, Path(notes))


def _pool(workers: int) -> ProcessPoolExecutor:
    return ProcessPoolExecutor(
        max_workers=workers,
        mp_context=multiprocessing.get_context("spawn"),
        initializer=_init_worker,
        initargs=(os.getpid(),),
    )


def _drain(
    pool: ProcessPoolExecutor, fn: Callable[..., dict], jobs: list[tuple], notes: Path
) -> Iterator[dict]:
    """Submit every job to ``pool``; yield results as they finish."""
    pending: set[Future[Any]] = {
        pool.submit(_noted, notes, task_name(payload, k), fn, *payload)
        for k, payload in enumerate(jobs)
    }
    # every worker has started once all is submitted; kept to read a dead one's exit code
    started: dict[int, BaseProcess] = dict(getattr(pool, "_processes", None) or {})
    try:
        while pending:
            finished, pending = wait(pending, return_when=FIRST_COMPLETED)
            for future in finished:
                try:
                    result = future.result()
                except BrokenProcessPool:
                    raise WorkerError(_death(started, notes)) from None
                yield result
    except BaseException:
        for future in pending:
            future.cancel()
        raise


def task_name(payload: tuple, index: int) -> str:
    """How a message names a task: its room when it has one."""
    room = getattr(payload[0], "room_id", None) if payload else None
    return f"room {room}" if room else f"task {index + 1}"


def _noted(notes: Path, name: str, fn: Callable[..., dict], *payload: Any) -> dict:
    """Run ``fn`` in a worker with a note of what it is on, for the message should it die."""
    note = notes / str(os.getpid())
    note.write_text(name)
    result = fn(*payload)
    note.unlink()
    return result


def _death(started: dict[int, BaseProcess], notes: Path) -> str:
    """One line on the worker that broke the pool: its pid, the signal, the task it was on.
    The pool stops the other workers with SIGTERM; the dead one is the one without it."""
    deadline = time.monotonic() + 10
    for pid, process in sorted(started.items()):
        code = _exit_code(process, deadline)
        if code is None or code >= 0 or -code == signal.SIGTERM:
            continue
        name = signal.Signals(-code).name
        note = notes / str(pid)
        task = note.read_text() if note.exists() else "no task (between tasks)"
        hint = " (SIGKILL is what the out-of-memory killer sends: try fewer --workers)"
        return (
            f"worker {pid} died of {name} while on {task}"
            f"{hint if -code == signal.SIGKILL else ''}; rerun with --resume"
        )
    return "a worker died and its signal is unknown; rerun with --resume"


def _exit_code(process: BaseProcess, deadline: float) -> int | None:
    """A worker's exit code, asked again until the deadline: the pool's own thread may reap
    the worker at the same moment, and then this side's waitpid answers ECHILD and sees the
    code only once that thread has stored it."""
    while True:
        process.join(timeout=max(0.0, deadline - time.monotonic()))
        code = process.exitcode
        if code is not None or time.monotonic() >= deadline:
            return code
        time.sleep(0.02)


def die_with_parent(parent: int) -> None:
    """Ask the kernel to SIGKILL this process when its parent dies (Linux); if the parent is
    already gone (it died before this ran), exit now."""
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
    except (OSError, AttributeError):  # not Linux: the parent's own shutdown stops the workers
        return
    if os.getppid() != parent:
        os._exit(1)


def _init_worker(parent: int) -> None:
    # Runs first in each spawned worker, before pyrender or Mesa load.
    die_with_parent(parent)
    os.environ.update(WORKER_ENV)
