"""Where room tasks run: a pool of spawned worker processes, even for one worker.

Workers are spawned, never forked: an EGL context does not survive ``fork`` (DESIGN §9). Each
worker keeps its renderer alive across the rooms it is given (see
:mod:`sgdata.pipeline.room_tasks`).

Every worker rasterises on one llvmpipe thread (``LP_NUM_THREADS=1``, ignored by GPU EGL):
llvmpipe's output differs in rare edge pixels with its thread count (seen here: one pixel of
one view in 23), so a fixed count is what makes a dataset byte-identical whatever
``--workers`` is. Parallelism comes from the workers instead: two single-threaded workers
render 2.1x the views of one default process on 2 cores (DESIGN §9).
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

    A worker's exception (an ``SgdataError`` included) is re-raised here after the pool is
    shut down, so finished tasks stay recorded and the run can resume.
    """
    jobs = list(payloads)
    if not jobs:
        return
    context = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(
        max_workers=min(workers, len(jobs)),
        mp_context=context,
        initializer=_init_worker,
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


def _init_worker() -> None:
    # Runs first in each spawned worker, before pyrender or Mesa load.
    os.environ["LP_NUM_THREADS"] = "1"
