"""Manifest checks: dataset.json against its JSON Schema, the format version, the cross-field
rules, and every listed file (present, rows, bytes, sha256); no unlisted shards."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import jsonschema
import pyarrow as pa
import pyarrow.parquet as pq

from sgdata.dataset.manifest import Manifest
from sgdata.dataset.paths import MANIFEST
from sgdata.dataset.schema import check_compatible, manifest_json_schema
from sgdata.errors import DatasetError, one_line
from sgdata.fileio import sha256_file
from sgdata.validate.problems import Collector

__all__ = ["read_raw_manifest", "check_manifest", "check_files", "check_splits"]


def read_raw_manifest(root: Path, out: Collector) -> dict[str, Any] | None:
    """The parsed dataset.json when it is usable for the other checks, else None.

    Raises:
        DatasetError: ``root`` is not a directory or holds no dataset.json (not a dataset).
    """
    if not root.is_dir():
        raise DatasetError(f"{root}: no such directory; expected an sgdata dataset root")
    path = root / MANIFEST
    if not path.is_file():
        raise DatasetError(
            f"{root}: no {MANIFEST}; not an sgdata dataset "
            "(or generation did not finish: run sgdata generate --resume)"
        )
    out.count("manifest.json")
    try:
        raw = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        out.add("manifest.json", MANIFEST, f"not readable JSON ({one_line(exc)})")
        return None
    if not isinstance(raw, dict):
        out.add("manifest.json", MANIFEST, f"expected a JSON object, got {type(raw).__name__}")
        return None
    return raw


def check_manifest(raw: dict[str, Any], out: Collector) -> bool:
    """Schema, version and cross-field checks; True when the other checks can rely on it."""
    out.count("manifest.version")
    try:
        check_compatible(raw.get("format_version"))
    except DatasetError as exc:
        out.add("manifest.version", MANIFEST, str(exc), field="format_version")
        return False
    validator = jsonschema.Draft202012Validator(manifest_json_schema())
    errors = sorted(validator.iter_errors(raw), key=lambda e: list(map(str, e.absolute_path)))
    out.count("manifest.schema")
    for error in errors:
        where = "/".join(str(p) for p in error.absolute_path) or None
        out.add("manifest.schema", MANIFEST, error.message, field=where)
    if errors:
        return False
    out.count("manifest.consistency")
    try:
        Manifest.from_dict(raw)
    except DatasetError as exc:
        text = str(exc)
        detail = text.split("): ", 1)[-1] if "): " in text else text
        for line in detail.split("; "):
            out.add("manifest.consistency", MANIFEST, line)
    return True


def check_files(root: Path, raw: dict[str, Any], out: Collector) -> None:
    """Every listed file: present, rows (Parquet), bytes, sha256; then unlisted shards."""
    listed = set()
    for k, entry in enumerate(raw["files"]):
        rel = entry["path"]
        listed.add(rel)
        path = root / rel
        where = f"files[{k}]"
        out.count("files.exist")
        if not path.is_file():
            out.add("files.exist", rel, f"listed in {MANIFEST} ({where}) but missing")
            continue
        if entry.get("rows") is not None:
            out.count("files.rows")
            try:
                rows = pq.ParquetFile(path).metadata.num_rows
            except (pa.ArrowException, OSError) as exc:
                out.add("files.rows", rel, f"not a readable Parquet file ({one_line(exc)})")
            else:
                if rows != entry["rows"]:
                    out.add(
                        "files.rows", rel, f"{rows} rows; {MANIFEST} {where} says {entry['rows']}"
                    )
        digest, size = sha256_file(path)
        out.count("files.bytes")
        if size != entry["bytes"]:
            out.add("files.bytes", rel, f"{size} bytes; {MANIFEST} {where} says {entry['bytes']}")
        out.count("files.sha256")
        if digest != entry["sha256"]:
            out.add(
                "files.sha256",
                rel,
                f"sha256 {digest[:12]}...; {MANIFEST} {where} says {entry['sha256'][:12]}...",
            )
    found = [*root.glob("observations/**/*.parquet"), *root.glob("triplets/**/*.parquet")]
    out.count("files.unlisted", len(found))
    for path in sorted(found):
        rel = path.relative_to(root).as_posix()
        if rel not in listed:
            out.add("files.unlisted", rel, f"a shard not listed in {MANIFEST} files")
    for split, rooms in raw["splits"].items():
        for room in rooms:
            rel = f"observations/{split}/{room}.parquet"
            if rel not in listed:
                out.add(
                    "files.exist",
                    MANIFEST,
                    f"room {room} of split {split}: its shard {rel} is not listed in files",
                    field=f"splits/{split}",
                )


def check_splits(raw: dict[str, Any], out: Collector) -> None:
    """A room belongs to exactly one split."""
    seen: dict[str, str] = {}
    for split, rooms in raw["splits"].items():
        for room in rooms:
            out.count("splits.disjoint")
            if room in seen and seen[room] != split:
                out.add(
                    "splits.disjoint",
                    MANIFEST,
                    f"room {room} is in splits {seen[room]} and {split}; a room belongs to one",
                    field=f"splits/{split}",
                )
            seen.setdefault(room, split)
