"""sgdata.validate's channel checks: a dataset with depth and masks is clean; each kind of
damage to a channel is found and located at its row and field."""

from __future__ import annotations

import json
import shutil
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from sgdata.dataset import read_manifest, write_manifest, write_parquet
from sgdata.dataset.channels import decode_channel, encode_mask
from sgdata.validate import validate_dataset
from sgdata.validate.channel_checks import CHANNEL_CHECKS

SHARD = "observations/train/bathroom_000.parquet"


@pytest.fixture
def copy(channels_dataset: Path, tmp_path: Path) -> Path:
    target = tmp_path / "copy"
    shutil.copytree(channels_dataset, target)
    return target


def damage(root: Path, column: str, change: Callable[[np.ndarray, dict], bytes | None]) -> int:
    """Replace row ``r``'s ``column`` PNG by ``change(decoded, row)`` in the train shard, where
    ``r`` is the first row with at least two objects; the manifest is updated as a writer
    would. Returns ``r``."""
    table = pq.read_table(root / SHARD)
    rows = table.to_pylist()
    r = next(k for k, row in enumerate(rows) if len(row["objects"]) >= 2)
    cells = table.column(column).to_pylist()
    new = change(decode_channel(cells[r]["bytes"]), rows[r])
    cells[r] = None if new is None else {"bytes": new, "path": None}
    at = table.schema.get_field_index(column)
    table = table.set_column(
        at, table.schema.field(at), pa.array(cells, table.schema.field(at).type)
    )
    info = write_parquet(table, root / SHARD)
    raw = json.loads((root / "dataset.json").read_text())
    for entry in raw["files"]:
        if entry["path"] == SHARD:
            entry.update(rows=info.rows, sha256=info.sha256, bytes=info.bytes)
    (root / "dataset.json").write_text(json.dumps(raw, indent=2))
    write_manifest(read_manifest(root), root)  # the card and croissant.json as a writer would
    return r


def test_a_dataset_with_channels_is_clean(channels_dataset: Path) -> None:
    report = validate_dataset(channels_dataset)
    assert report.ok, [(p.check, p.location(), p.message) for p in report.problems]
    rows = sum(report.checked[c] for c in ("channels.decode",))
    assert rows > 0 and all(report.checked[c] == rows for c in CHANNEL_CHECKS[1:])
    quick = validate_dataset(channels_dataset, quick=True)
    assert set(CHANNEL_CHECKS) <= set(quick.skipped)


def _stray_pixel(mask: np.ndarray, row: dict) -> bytes:
    out = mask.copy()
    u1, v1, u2, v2 = row["objects"][0]["box2d"]
    far = (0, 0) if (u1, v1) != (0, 0) else (mask.shape[0] - 1, mask.shape[1] - 1)
    out[far] = 1  # object 1 now also seen at a far corner: its extent is no longer its box
    return encode_mask(out)


def _unlisted(mask: np.ndarray, row: dict) -> bytes:
    out = mask.copy()
    out[mask == 1] = len(row["objects"]) + 1
    return encode_mask(out)


def _depth_hole(depth: np.ndarray, row: dict) -> bytes:
    from sgdata.dataset.channels import depth_metres, encode_depth

    metres = depth_metres(depth)
    u1, v1, u2, v2 = row["objects"][0]["box2d"]
    metres[v1:v2, u1:u2] = 0.0
    return encode_depth(metres)


def _too_deep(depth: np.ndarray, row: dict) -> bytes:
    out = depth.copy()
    out[0, 0] = 60_000  # 60 m: beyond any room's diagonal
    return encode_mask(out)


def _part_on_object(parts: np.ndarray, row: dict) -> bytes:
    out = parts.copy()
    u1, v1, u2, v2 = row["objects"][0]["box2d"]
    out[v1:v2, u1:u2] = 1  # a wall painted over the first object
    return encode_mask(out)


def _unknown_part(parts: np.ndarray, row: dict) -> bytes:
    out = parts.copy()
    out[parts > 0] = 9
    return encode_mask(out)


def _floor_without_depth(depth: np.ndarray, row: dict) -> bytes:
    from sgdata.dataset.channels import depth_metres, encode_depth

    metres = depth_metres(depth)
    metres[-1, :] = 0.0  # the bottom row sees the floor (or an object) in these views
    return encode_depth(metres)


def _wrong_size(values: np.ndarray, row: dict) -> bytes:
    return encode_mask(values[::2, ::2].copy())


def _eight_bit(values: np.ndarray, row: dict) -> bytes:
    from sgdata.dataset.rows import encode_image

    return encode_image(np.zeros((*values.shape, 3), np.uint8))


@pytest.mark.parametrize(
    ("column", "change", "check"),
    [
        ("instances", _stray_pixel, "masks.extent"),
        ("instances", _unlisted, "masks.unlisted"),
        ("depth", _depth_hole, "depth.hits"),
        ("depth", _too_deep, "depth.range"),
        ("instances", _wrong_size, "channels.size"),
        ("depth", _eight_bit, "channels.decode"),
        ("depth", lambda values, row: None, "channels.present"),
        ("structure", _part_on_object, "masks.structure"),
        ("structure", _unknown_part, "masks.structure"),
        ("depth", _floor_without_depth, "depth.hits"),
        ("structure", lambda values, row: None, "channels.present"),
    ],
)
def test_damaged_channel_is_named(copy: Path, column: str, change: Callable, check: str) -> None:
    row = damage(copy, column, change)
    report = validate_dataset(copy)
    found = [p for p in report.problems if p.check == check]
    assert found, sorted({p.check for p in report.problems})
    assert {(p.file, p.row, p.field) for p in found} == {(SHARD, row, column)}
    # nothing else broke (a mask pixel painted where nothing is drawn also has no depth, one
    # painted on the room also overlaps its structure mask)
    also = {"masks.extent", "depth.hits", "masks.structure"}
    assert {p.check for p in report.problems} <= {check, *also}
