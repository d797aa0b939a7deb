"""A real ``sgdata label`` server in a subprocess on a free port, stopped in ``finally``.

The server's stdout and stderr go to a temporary file, never to a pipe: nobody reads a pipe
while the server runs, and once its 64 KiB buffer is full (uvicorn logs the traceback of every
500 and a warning per malformed request) the server's next log line blocks its event loop and
it answers nothing more. A fuzzing campaign hung that way after about 200 requests.
"""

from __future__ import annotations

import contextlib
import signal
import socket
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path

import httpx

SGDATA = str(Path(sys.executable).parent / "sgdata")


def free_port(host: str = "127.0.0.1") -> int:
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    with socket.socket(family) as s:
        s.bind((host, 0))
        return s.getsockname()[1]


@contextlib.contextmanager
def label_server(
    photos: Path, out: Path, *extra: str, host: str = "127.0.0.1"
) -> Iterator[tuple[str, subprocess.Popen]]:
    """Yield (base URL, process); the server is stopped (SIGINT, then kill) on exit."""
    port = free_port(host)
    url = f"http://[{host}]:{port}" if ":" in host else f"http://{host}:{port}"
    with tempfile.TemporaryFile() as log:  # a file never fills up; read once the server exited
        proc = subprocess.Popen(
            [SGDATA, "label", str(photos), "--out", str(out), "--port", str(port), "--host", host]
            + list(extra),
            stdout=log,
            stderr=subprocess.STDOUT,
        )
        try:
            deadline = time.monotonic() + 30
            while True:
                if proc.poll() is not None:
                    log.seek(0)
                    raise RuntimeError(f"server exited: {log.read().decode(errors='replace')}")
                try:
                    if httpx.get(url + "/api/photos", timeout=1).status_code == 200:
                        break
                except httpx.TransportError:
                    pass
                if time.monotonic() > deadline:
                    raise RuntimeError("server did not start in 30 s")
                time.sleep(0.1)
            yield url, proc
        finally:
            if proc.poll() is None:
                proc.send_signal(signal.SIGINT)
                try:
                    proc.wait(timeout=10)
                except subprocess.TimeoutExpired:
                    proc.kill()
                    proc.wait()
