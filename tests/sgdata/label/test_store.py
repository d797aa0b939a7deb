"""The label store: a save is on disk at once, and a server killed with -9 loses nothing."""

from __future__ import annotations

import json
import signal
from pathlib import Path

import httpx

from ...cli_runner import run_cli
from .server_process import label_server

LABELS = {
    "room_id": "k1",
    "room_type": "kitchen",
    "objects": [{"id": 0, "class_name": "Mug", "box": [10, 10, 50, 40]}],
    "relations": [],
}


def test_kill_9_after_a_save_loses_nothing(photos_dir: Path, tmp_path: Path) -> None:
    out = tmp_path / "ds"
    with label_server(photos_dir, out) as (url, proc):
        saved = httpx.put(f"{url}/api/labels/a.png", json=LABELS)
        assert saved.status_code == 200
        proc.send_signal(signal.SIGKILL)
        proc.wait(timeout=10)
    on_disk = json.loads((out / "labels" / "a.png.json").read_text())
    assert on_disk["objects"] == LABELS["objects"] and on_disk["revision"] == 1
    assert not list((out / "labels").glob(".*.tmp"))
    with label_server(photos_dir, out) as (url, _):
        again = httpx.get(f"{url}/api/labels/a.png").json()["labels"]
        assert again["room_id"] == "k1" and again["revision"] == 1
        second = httpx.put(f"{url}/api/labels/a.png", json={**LABELS, "revision": 1})
        assert second.json()["labels"]["revision"] == 2


def test_cli_reports_bad_inputs_in_one_line(tmp_path: Path) -> None:
    done = run_cli("sgdata", "label", tmp_path / "nowhere", "--out", tmp_path / "ds", "--export")
    assert done.returncode == 2
    assert done.stderr.count("\n") == 1 and "does not exist" in done.stderr
    bad = tmp_path / "map.toml"
    bad.write_text('mug = "Unicorn"\n')
    (tmp_path / "photos").mkdir()
    done = run_cli(
        "sgdata", "label", tmp_path / "photos", "--out", tmp_path / "ds", "--classes", bad
    )
    assert done.returncode == 2 and "Traceback" not in done.stderr
    assert "not a catalog class" in done.stderr
