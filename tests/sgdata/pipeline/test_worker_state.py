"""A worker's threads by origin and its context switches, read from /proc."""

from __future__ import annotations

import threading
import time
from concurrent.futures import ThreadPoolExecutor

from sgdata.pipeline.worker_state import context_switches, threads_by_origin, worker_threads


def test_a_pools_threads_count_under_one_origin_and_add_up_to_the_kernels_count() -> None:
    started = threading.Barrier(3)
    with ThreadPoolExecutor(max_workers=2, thread_name_prefix="probe-pool") as pool:
        waits = [pool.submit(started.wait) for _ in range(2)]
        started.wait()
        before = worker_threads()
        origins = threads_by_origin()
        after = worker_threads()
        for w in waits:
            w.result()
    assert origins["probe-pool"] == 2
    assert origins["MainThread"] == 1
    assert sum(origins.values()) in (before, after)  # the kernel's count, read around it


def test_context_switches_grow_when_the_process_waits() -> None:
    before = context_switches()
    for _ in range(5):
        time.sleep(0.01)  # each sleep gives the core away: a voluntary switch
    after = context_switches()
    assert after[0] >= before[0] + 5
    assert after[1] >= before[1]
