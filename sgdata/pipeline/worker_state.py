"""What a generate worker reports of itself after each room: its peak memory, its threads (by
origin) and its context switches, so contention shows in the numbers (issue 55: a GPU
machine's workers lost half their speed to it) and growth across rooms fails a test."""

from __future__ import annotations

import os
import re
import resource
import threading
from collections import Counter
from pathlib import Path

__all__ = [
    "context_switches",
    "peak_rss_mib",
    "threads_by_origin",
    "worker_state",
    "worker_threads",
]

_INDEX = re.compile(r"[-_:]?\d+$")  # a pool's or a driver's per-thread index


def peak_rss_mib() -> float:
    """This process's peak resident memory so far, in MiB (Linux reports KiB)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def _status(field: str) -> int | None:
    try:
        status = Path("/proc/self/status").read_text()
    except OSError:
        return None
    found = re.search(rf"^{field}:\s+(\d+)", status, re.MULTILINE)
    return int(found.group(1)) if found else None


def worker_threads() -> int:
    """This process's threads, native ones included (the GL driver's, Arrow's, OpenMP's):
    Linux's count, else Python's own."""
    count = _status("Threads")
    return threading.active_count() if count is None else count


def _origin(name: str) -> str:
    """A thread's name without its index: every thread of one pool has one origin."""
    while (stripped := _INDEX.sub("", name)) != name:
        name = stripped
    return name or "unnamed"


def threads_by_origin() -> dict[str, int]:
    """This process's threads counted by origin, most first.

    Python's threads by their Python name (``ThreadPoolExecutor-0_1`` counts as
    ``ThreadPoolExecutor``); the native ones by the name the kernel shows (``llvmpipe-3``,
    Mesa's rasteriser, as ``llvmpipe``; ``jemalloc_bg_thd``, Arrow's allocator), prefixed
    ``native:``. A native thread its library left unnamed carries the process's name (OpenMP's,
    OpenBLAS's, Arrow's pools): ``native:python`` and the like.
    """
    python = {t.native_id: _origin(t.name) for t in threading.enumerate()}
    counts: Counter[str] = Counter()
    try:
        tasks = list(Path(f"/proc/{os.getpid()}/task").iterdir())
    except OSError:
        return dict(Counter(python.values()).most_common())
    for task in tasks:
        tid = int(task.name)
        if tid in python:
            counts[python[tid]] += 1
            continue
        try:
            comm = (task / "comm").read_text().strip()
        except OSError:  # the thread ended while we looked
            continue
        counts[f"native:{_origin(comm)}"] += 1
    return dict(counts.most_common())


def context_switches() -> tuple[int, int]:
    """This process's context switches so far, its ended threads' included: (voluntary: a
    thread waited, involuntary: the kernel took its core away)."""
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_nvcsw, usage.ru_nivcsw


def worker_state() -> dict:
    """What a task's result says of the worker that ran it."""
    return {
        "pid": os.getpid(),
        "peak_rss_mib": peak_rss_mib(),
        "threads": worker_threads(),
        "threads_by_origin": threads_by_origin(),
        "context_switches": list(context_switches()),
    }
