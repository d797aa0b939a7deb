"""The tests' label server (server_process.py): however much the server logs, it keeps answering."""

from __future__ import annotations

from pathlib import Path

import httpx

from .server_process import label_server

# Connection: Upgrade to a WebSocket, which the server does not speak: uvicorn answers the request
# as usual and logs two warnings (183 bytes); 600 such requests log 110 kB, past a pipe's 64 KiB
UPGRADE = {"Connection": "Upgrade", "Upgrade": "websocket"}


def test_a_server_that_logs_more_than_a_pipe_holds_keeps_answering(
    photos_dir: Path, tmp_path: Path
) -> None:
    # its log once went to a pipe nobody read: once 64 KiB were logged (a fuzzing campaign's
    # 500s, about 200 requests in) the next log line blocked the server, and it answered nothing
    with (
        label_server(photos_dir, tmp_path / "ds") as (url, _),
        httpx.Client(base_url=url, timeout=10) as client,
    ):
        for _ in range(600):
            assert client.get("/api/classes", headers=UPGRADE).status_code == 200
        assert client.get("/api/labels/a.png").status_code == 200
