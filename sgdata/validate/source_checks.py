"""Source checks (``--sources DIR``): the user's files a dataset was made from are unchanged.

A dataset generated from ``[rooms] files`` records each file's path (relative to the config
file's folder) and SHA-256 in its manifest's ``config.rooms.files``; its scenes hold a flattened
copy (``scenes/<room>/source.usda``, checked by ``files.sha256``). One made with ``[catalog]
files`` records likewise its catalog files and every mesh and texture file they read, in
``config.catalog.assets``. Given the config's folder, this check names every user file that is
missing there or whose bytes are no longer those the dataset was made from.
"""

from __future__ import annotations

from pathlib import Path

from sgdata.dataset.paths import MANIFEST
from sgdata.fileio import sha256_file
from sgdata.validate.problems import Collector

__all__ = ["catalog_asset_files", "check_sources", "user_room_files"]

CHECK = "sources.unchanged"


def user_room_files(raw: dict) -> list[dict]:
    """The ``config.rooms.files`` entries of a raw manifest (empty for procedural datasets)."""
    rooms = raw.get("config", {}).get("rooms", {})
    files = rooms.get("files", []) if isinstance(rooms, dict) else []
    return [f for f in files if isinstance(f, dict)] if isinstance(files, list) else []


def catalog_asset_files(raw: dict) -> list[dict]:
    """The ``config.catalog.assets`` entries of a raw manifest: the user's catalog files and
    the mesh and texture files they read (empty without ``[catalog] files``)."""
    catalog = raw.get("config", {}).get("catalog", {})
    files = catalog.get("assets", []) if isinstance(catalog, dict) else []
    return [f for f in files if isinstance(f, dict)] if isinstance(files, list) else []


def check_sources(raw: dict, folder: Path, out: Collector) -> None:
    """Each user room's file, and each file of the user's catalog (meshes, textures), under
    ``folder`` has the sha256 the manifest records."""
    entries = [(f"config.rooms.files[{k}]", e) for k, e in enumerate(user_room_files(raw))]
    entries += [(f"config.catalog.assets[{k}]", e) for k, e in enumerate(catalog_asset_files(raw))]
    for field, entry in entries:
        out.count(CHECK)
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
