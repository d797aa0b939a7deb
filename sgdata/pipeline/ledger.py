"""The ledger of a generation (``<root>/.sgdata/``): which rooms are done, with which config.

A record is written atomically and last, so a task killed half-way leaves nothing that counts
as done and ``--resume`` redoes exactly the rooms in flight.
"""

from __future__ import annotations

import json
from pathlib import Path

from sgdata.errors import DatasetError
from sgdata.fileio import atomic_write_text

__all__ = ["LEDGER", "CONFIG_RECORD", "scene_record", "views_record", "read_record", "write_record"]

LEDGER = ".sgdata"  # the ledger directory under the dataset root
CONFIG_RECORD = "config.json"  # the resolved config the run was started with
_SCENE_RECORD = "scene-{room_id}.json"  # phase 1 of a room: seed and reachable cells
_VIEWS_RECORD = "views-{room_id}.json"  # phase 3 of a room: its observation shard


def scene_record(root: Path, room_id: str) -> Path:
    return root / LEDGER / _SCENE_RECORD.format(room_id=room_id)


def views_record(root: Path, room_id: str) -> Path:
    return root / LEDGER / _VIEWS_RECORD.format(room_id=room_id)


def read_record(path: Path) -> dict:
    """A ledger record; an unreadable one is a one-line :class:`DatasetError`."""
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except (OSError, json.JSONDecodeError) as exc:
        raise DatasetError(
            f"{path}: unreadable progress record ({exc}); rerun with --force"
        ) from None


def write_record(path: Path, record: dict) -> None:
    """Write a record atomically; an OS error names the file."""
    try:
        atomic_write_text(path, json.dumps(record, sort_keys=True))
    except OSError as exc:
        raise DatasetError(
            f"{path}: cannot write ({exc.strerror}); fix it and rerun with --resume"
        ) from None
