"""A reaper for a run's process tree: when the run's main process dies, even by ``kill -9``,
every process it started dies within a second.

Ray's local instance shares the driver's fate only in part: its GCS server and raylet die with
the driver, but the raylet's agents noticed only ~60 s later (measured here). The reaper is a
small process in a session of its own, holding the read end of a pipe whose write end only the
run holds. Twice a second it notes the run's descendants started since the reaper (pid and
start time, so a reused pid is never killed); when the pipe reaches end of file (the run
exited or was killed), it kills what it noted and what those started, then exits. Linux only
(it reads ``/proc``); elsewhere it is not started.
"""

from __future__ import annotations

import os
import select
import signal
import subprocess
import sys
from pathlib import Path

__all__ = ["start_reaper"]

_TICK = 0.5  # seconds between looks at the process tree


def start_reaper() -> subprocess.Popen | None:
    """Start a reaper for this process's descendants; keep the returned handle alive (its
    stdin is the pipe) and close its stdin when done. None where ``/proc`` is missing."""
    if not Path("/proc/self/stat").exists():
        return None
    return subprocess.Popen(
        [sys.executable, "-m", "sgdata.pipeline.reaper", str(os.getpid())],
        stdin=subprocess.PIPE,
        start_new_session=True,  # not in the run's process group: a group kill spares it
    )


def _stat(pid: int) -> tuple[int, int] | None:
    """(parent pid, start time) of a live process; None when gone or a zombie."""
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except (OSError, IndexError):
        return None
    return None if fields[0] == "Z" else (int(fields[1]), int(fields[19]))


def _descendants(roots: set[int]) -> dict[int, int]:
    """Live descendants of ``roots``: pid -> start time."""
    children: dict[int, list[int]] = {}
    starts: dict[int, int] = {}
    for name in os.listdir("/proc"):
        if name.isdigit() and (s := _stat(int(name))) is not None:
            children.setdefault(s[0], []).append(int(name))
            starts[int(name)] = s[1]
    found: dict[int, int] = {}
    todo = [c for r in roots for c in children.get(r, [])]
    while todo:
        pid = todo.pop()
        if pid not in found and pid != os.getpid():
            found[pid] = starts[pid]
            todo += children.get(pid, [])
    return found


def _reap(parent: int) -> None:
    # what the run had started before it asked for a reaper (a resource tracker, a pool) is
    # not the reaper's: it reaps only what came after
    before = _descendants({parent})
    noted: dict[int, int] = {}
    while True:
        now = _descendants({parent})
        noted.update({p: s for p, s in now.items() if before.get(p) != s})
        ready, _, _ = select.select([sys.stdin], [], [], _TICK)
        if ready and not os.read(sys.stdin.fileno(), 4096):
            break  # end of file: the run is gone (or done)
    # what the noted processes started since, then everything still alive as noted
    noted.update({p: s for p, s in _descendants(set(noted)).items() if before.get(p) != s})
    for pid, start in noted.items():
        s = _stat(pid)
        if s is not None and s[1] == start:
            try:
                os.kill(pid, signal.SIGKILL)
            except OSError:
                pass


if __name__ == "__main__":
    _reap(int(sys.argv[1]))
