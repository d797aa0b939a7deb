"""Source checks (``--sources DIR``): the user's room files a dataset was made from are unchanged.

A dataset generated from ``[rooms] files`` records each file's path (relative to the config
file's folder) and SHA-256 in its manifest's ``config.rooms.files``; its scenes hold a flattened
copy (``scenes/<room>/source.usda``, checked by ``files.sha256``). Given the config's folder, this
check names every user file that is missing there or whose bytes are no longer those the dataset
was made from.
"""

from __future__ import annotations

from pathlib import Path

from sgdata.dataset.paths import MANIFEST
from sgdata.dataset.rows import sha256_file
from sgdata.validate.problems import Collector

__all__ = ["check_sources", "user_room_files"]

CHECK = "sources.unchanged"


def user_room_files(raw: dict) -> list[dict]:
    """The ``config.rooms.files`` entries of a raw manifest (empty for procedural datasets)."""
    rooms = raw.get("config", {}).get("rooms", {})
    files = rooms.get("files", []) if isinstance(rooms, dict) else []
    return [f for f in files if isinstance(f, dict)] if isinstance(files, list) else []


def check_sources(raw: dict, folder: Path, out: Collector) -> None:
    """Each user room's file under ``folder`` has the sha256 the manifest records."""
    for k, entry in enumerate(user_room_files(raw)):
        out.count(CHECK)
        field = f"config.rooms.files[{k}]"
        rel, recorded = str(entry.get("path", "")), str(entry.get("sha256", ""))
        path = Path(folder) / rel
        if not rel or not path.is_file():
            out.add(CHECK, MANIFEST, f"{rel!r}: not found under {folder}", field=field)
            continue
        digest, _ = sha256_file(path)
        if digest != recorded:
            out.add(
                CHECK,
                MANIFEST,
                f"{rel!r} changed since the dataset was made from it: sha256 {digest}, "
                f"recorded {recorded}; regenerate (sgdata generate --force) to take it in",
                field=field,
            )
