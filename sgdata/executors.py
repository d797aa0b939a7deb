"""Where room tasks run: in this process (one worker) or in a pool of spawned processes.

Workers are spawned, never forked: an EGL context does not survive ``fork`` (DESIGN §9). Each
worker keeps its renderer alive across the rooms it is given (see :mod:`sgdata.room_work`).
With several workers each gets an equal share of the cores for Mesa's llvmpipe, which
otherwise spreads every render over all cores and makes the workers fight.
"""

from __future__ import annotations

import multiprocessing
import os
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from typing import Any

__all__ = ["run_tasks"]


def run_tasks(
    fn: Callable[..., dict], payloads: Iterable[tuple], *, workers: int = 1
) -> Iterator[dict]:
    """Run ``fn(*payload)`` for every payload; yield results as they finish.

    With ``workers == 1`` everything runs here, in order. A worker's exception (an
    ``SgdataError`` included) is re-raised here after the pool is shut down, so finished
    tasks stay recorded and the run can resume.
    """
    jobs = list(payloads)
    if workers == 1 or len(jobs) <= 1:
        for payload in jobs:
            yield fn(*payload)
        return
    threads = max(1, (os.cpu_count() or 1) // workers)
    context = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(
        max_workers=min(workers, len(jobs)),
        mp_context=context,
        initializer=_init_worker,
        initargs=(threads,),
    ) as pool:
        pending: set[Future[Any]] = {pool.submit(fn, *payload) for payload in jobs}
        try:
            while pending:
                finished, pending = wait(pending, return_when=FIRST_COMPLETED)
                for future in finished:
                    yield future.result()
        except BaseException:
            for future in pending:
                future.cancel()
            raise


def _init_worker(llvmpipe_threads: int) -> None:
    # Runs first in each spawned worker, before pyrender or Mesa load.
    os.environ.setdefault("LP_NUM_THREADS", str(llvmpipe_threads))
