"""Room tasks on Ray: long-lived actors with one renderer each, bounded retries, same bytes.

Imported only for ``--executor ray`` (Ray is a heavy import). Each actor is one worker process
that keeps its renderer alive across the rooms it is given, exactly like a local pool worker;
the tasks write their own outputs to the dataset path (a shared filesystem on a real cluster).
See docs/scale.md for the cluster recipe.
"""

from __future__ import annotations

import subprocess
from collections import Counter, deque
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

import ray
from ray.exceptions import RayActorError, RayTaskError, WorkerCrashedError

from sgdata.errors import SgdataError, WorkerError
from sgdata.pipeline.reaper import start_reaper

__all__ = ["run_on_ray", "ray_session"]


@ray.remote(num_cpus=1)
class _RoomWorker:
    """One worker process; the room-task module keeps its renderer alive between calls."""

    def run(self, fn: Callable[..., dict], payload: tuple) -> dict:
        return fn(*payload)


def run_on_ray(
    fn: Callable[..., dict],
    jobs: list[tuple],
    *,
    workers: int,
    address: str | None,
    retries: int,
    env: dict[str, str],
    name: Callable[[tuple, int], str],
) -> Iterator[dict]:
    """Run ``fn(*job)`` for every job on ``workers`` actors; yield results as they finish.

    A task whose worker died is tried again on a fresh worker, at most ``retries`` more times,
    then reported by ``name(job, index)`` (its room id; the caller's, so this module never
    imports the executors that import it). A task that raises an ``SgdataError`` (bad input, a
    file that cannot be written) is not retried: its message is re-raised as it is.
    """
    with ray_session(address, workers, env):
        yield from _run(fn, jobs, workers=workers, retries=retries, name=name)


def _run(
    fn: Callable[..., dict], jobs: list[tuple], *, workers: int, retries: int,
    name: Callable[[tuple, int], str],
) -> Iterator[dict]:  # fmt: skip
    actors: list[Any] = []
    try:
        actors = [_RoomWorker.remote() for _ in range(min(workers, len(jobs)))]
        idle = list(actors)
        queue = deque(range(len(jobs)))
        tries: Counter[int] = Counter()
        running: dict[Any, tuple[Any, int]] = {}
        while queue or running:
            while idle and queue:
                actor, index = idle.pop(), queue.popleft()
                running[actor.run.remote(fn, jobs[index])] = (actor, index)
            (ref,), _ = ray.wait(list(running), num_returns=1)
            actor, index = running.pop(ref)
            try:
                result = ray.get(ref)
            except RayTaskError as exc:
                cause = exc.cause
                if isinstance(cause, SgdataError):
                    raise cause from None
                why = f"{type(cause).__name__}: {cause}"
                _retry(index, name(jobs[index], index), tries, retries, why)
                queue.appendleft(index)
                idle.append(actor)
                continue
            except (RayActorError, WorkerCrashedError) as exc:
                why = f"its worker died ({type(exc).__name__})"
                _retry(index, name(jobs[index], index), tries, retries, why)
                queue.appendleft(index)
                replacement = _RoomWorker.remote()
                actors.append(replacement)
                idle.append(replacement)
                continue
            idle.append(actor)
            yield result
    finally:
        for actor in actors:
            ray.kill(actor)


def _retry(index: int, task: str, tries: Counter[int], retries: int, why: str) -> None:
    tries[index] += 1
    if tries[index] > retries:
        raise WorkerError(f"{task} failed {tries[index]} times on Ray ({why}); rerun with --resume")


@contextmanager
def ray_session(address: str | None, workers: int, env: dict[str, str]) -> Iterator[None]:
    """Ray connected for the duration: joins the cluster at ``address``, or starts a local
    instance, its workers getting ``env``; shuts down only what it started (a session
    already open is reused)."""
    if ray.is_initialized():
        yield
        return
    options: dict[str, Any] = {
        "runtime_env": {"env_vars": dict(env)},
        "log_to_driver": False,
        "logging_level": "ERROR",
    }
    reaper = start_reaper() if address is None else None
    try:
        if address is None:
            # Ray listens on every interface unless told otherwise: keep it on loopback.
            ray.init(
                num_cpus=workers,
                include_dashboard=False,
                _node_ip_address="127.0.0.1",
                **options,
            )
        else:
            ray.init(address=address, **options)
    except (ConnectionError, RuntimeError, ValueError) as exc:
        where = address or "a local instance"
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        _stop(reaper)
        raise WorkerError(f"cannot start Ray on {where}: {first}") from None
    try:
        yield
    finally:
        ray.shutdown()
        _stop(reaper)


def _stop(reaper: subprocess.Popen | None) -> None:
    """Close the reaper's pipe: it kills what Ray left behind, then exits."""
    if reaper is not None:
        reaper.stdin.close()
        reaper.wait()
