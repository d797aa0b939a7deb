"""Channel checks: the optional ``depth``, ``instances`` and ``structure`` PNGs of each row
agree with the row.

- ``channels.present``: a synthetic row has each channel its config's ``[outputs]`` turned on;
- ``channels.decode``: a channel cell is a 16-bit greyscale PNG;
- ``channels.size``: of the row's camera size;
- ``masks.extent``: each listed object's mask pixels span exactly its stored 2D box (+-1 px);
- ``masks.unlisted``: no mask pixel names an object the row does not list;
- ``masks.structure``: the structure mask names a known part, and none where an object is seen;
- ``depth.hits``: depth is positive wherever the masks see an object, a wall, floor or ceiling;
- ``depth.range``: no depth beyond the room's diagonal (the room read from the row's scene).

The decoding is the slow part, so ``quick`` validation skips these checks as it skips images.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from sgdata.dataset.channels import (
    CHANNELS,
    DEPTH_UNITS_PER_METRE,
    STRUCTURE_PARTS,
    decode_channel,
    stored_channels,
)
from sgdata.dataset.schema import observations_schema
from sgdata.dataset.storage import memory_column
from sgdata.errors import SgdataError
from sgdata.validate.problems import Collector

__all__ = ["CHANNEL_CHECKS", "check_channels", "inspect_channels"]

CHANNEL_CHECKS = (
    "channels.present",
    "channels.decode",
    "channels.size",
    "masks.extent",
    "masks.unlisted",
    "masks.structure",
    "depth.hits",
    "depth.range",
)
EXTENT_TOLERANCE_PX = 1  # a mask's extent may differ from its stored box by this much


def inspect_channels(
    cells: dict[str, bytes | None],
    *,
    width: int,
    height: int,
    boxes: np.ndarray,
    diagonal: float | None,
) -> list[tuple[str, str, str]]:
    """``(check, field, message)`` for each problem of one row's channels.

    Args:
        cells: channel name -> encoded PNG (None: absent).
        width: the row's camera width; height likewise.
        boxes: ``(k, 4)`` stored boxes ``[u1, v1, u2, v2]`` of the listed objects.
        diagonal: the room's diagonal in metres (None: unknown, not checked).
    """
    out: list[tuple[str, str, str]] = []
    arrays: dict[str, np.ndarray] = {}
    for name, data in cells.items():
        if data is None:
            continue
        try:
            values = decode_channel(data, where=name)
        except SgdataError as exc:
            out.append(("channels.decode", name, str(exc)))
            continue
        if values.shape != (height, width):
            h, w = values.shape
            out.append(("channels.size", name, f"{w}x{h} pixels; camera says {width}x{height}"))
            continue
        arrays[name] = values
    mask, depth = arrays.get("instances"), arrays.get("depth")
    if mask is not None:
        out.extend(("masks.extent", "instances", m) for m in _extent_problems(mask, boxes))
        if int(mask.max(initial=0)) > len(boxes):
            extra = np.unique(mask[mask > len(boxes)])
            out.append(
                (
                    "masks.unlisted",
                    "instances",
                    f"mask values {extra[:5].tolist()} name objects beyond the {len(boxes)} listed",
                )
            )
    parts = arrays.get("structure")
    if parts is not None:
        out.extend(("masks.structure", "structure", m) for m in _structure_problems(parts, mask))
    if depth is not None and (mask is not None or parts is not None):
        seen = np.zeros(depth.shape, bool)
        if mask is not None:
            seen |= mask > 0
        if parts is not None:  # the door's opening has no surface, so no depth
            seen |= (parts > 0) & (parts < STRUCTURE_PARTS.index("door") + 1)
        holes = int(np.count_nonzero(seen & (depth == 0)))
        if holes:
            out.append(("depth.hits", "depth", f"depth 0 at {holes} pixel(s) the masks see"))
    if depth is not None and diagonal is not None:
        deepest = int(depth.max(initial=0)) / DEPTH_UNITS_PER_METRE
        if deepest > diagonal + 1.0 / DEPTH_UNITS_PER_METRE:
            out.append(
                (
                    "depth.range",
                    "depth",
                    f"depth {deepest:.3f} m beyond the room's diagonal {diagonal:.3f} m",
                )
            )
    return out


def _structure_problems(parts: np.ndarray, mask: np.ndarray | None) -> list[str]:
    """A structure mask's values beyond the known parts, or set where an object is seen."""
    out = []
    if int(parts.max(initial=0)) > len(STRUCTURE_PARTS):
        extra = np.unique(parts[parts > len(STRUCTURE_PARTS)])
        known = ", ".join(f"{k} {p}" for k, p in enumerate(STRUCTURE_PARTS, start=1))
        out.append(f"structure values {extra[:5].tolist()}; expected 0 or {known}")
    if mask is not None:
        both = int(np.count_nonzero((mask > 0) & (parts > 0)))
        if both:
            out.append(f"{both} pixel(s) hold both an object and a structure part")
    return out


def _extent_problems(mask: np.ndarray, boxes: np.ndarray) -> list[str]:
    """Each listed object whose mask extent is not its stored box (+-1 px)."""
    h, w = mask.shape
    k = len(boxes)
    label = np.minimum(mask.reshape(-1).astype(np.int64), k + 1)  # beyond k: masks.unlisted
    cols = np.zeros((k + 2, w), dtype=bool)
    rows = np.zeros((k + 2, h), dtype=bool)
    cols[label, np.tile(np.arange(w), h)] = True
    rows[label, np.repeat(np.arange(h), w)] = True
    out = []
    for n in range(1, k + 1):
        if not cols[n].any():
            out.append(f"object {n - 1} (mask value {n}) has no mask pixel")
            continue
        extent = (
            int(cols[n].argmax()),
            int(rows[n].argmax()),
            w - int(cols[n, ::-1].argmax()),
            h - int(rows[n, ::-1].argmax()),
        )
        box = tuple(int(b) for b in boxes[n - 1])
        if max(abs(a - b) for a, b in zip(extent, box, strict=True)) > EXTENT_TOLERANCE_PX:
            out.append(f"object {n - 1} (mask value {n}): mask spans {list(extent)}, box {box}")
    return out


def check_channels(root: Path, raw: dict[str, Any], files: list[str], out: Collector) -> None:
    """Decode the channels of the given observation shards and check them against the rows."""
    wanted = stored_channels(raw.get("config"), raw["format_version"])
    expected = observations_schema()
    diagonals: dict[str, float | None] = {}
    for rel in files:
        try:
            present = pq.read_schema(root / rel).names
            table = pq.read_table(
                root / rel,
                columns=[
                    c for c in (*CHANNELS, "objects", "camera", "domain", "scene") if c in present
                ],
            )
        except (pa.ArrowException, OSError, ValueError):
            continue  # reported by the table checks
        if not any(c in present for c in CHANNELS):
            for c in wanted:
                out.add("channels.present", rel, f"no {c} column; [outputs] {c} is on")
            continue
        if not table.schema.field("objects").type.equals(expected.field("objects").type):
            continue  # reported by the table checks
        cells = {}
        for c in CHANNELS:
            try:
                cells[c] = memory_column(table.column(c), f"{rel}: column {c}").to_pylist()
            except (KeyError, SgdataError):
                cells[c] = [None] * table.num_rows  # absent or mistyped: the table checks say
        camera = table.column("camera").to_pylist()
        objects = table.column("objects").to_pylist()
        domains = table.column("domain").to_pylist()
        scenes = table.column("scene").to_pylist()
        for row in range(table.num_rows):
            if domains[row] != "real":
                out.count("channels.present", len(wanted))
                for c in wanted:
                    if cells[c][row] is None:
                        out.add("channels.present", rel, f"[outputs] {c} is on", row=row, field=c)
            row_cells = {c: cells[c][row] for c in CHANNELS}
            if all(v is None for v in row_cells.values()):
                continue
            boxes = np.array([o["box2d"] for o in objects[row]], dtype=np.int64).reshape(-1, 4)
            for check in CHANNEL_CHECKS[1:]:
                out.count(check)
            problems = inspect_channels(
                row_cells,
                width=int(camera[row]["width"]),
                height=int(camera[row]["height"]),
                boxes=boxes,
                diagonal=_diagonal(root, scenes[row], diagonals),
            )
            for check, field, message in problems:
                out.add(check, rel, message, row=row, field=field)


def _diagonal(root: Path, scene: str | None, cache: dict[str, float | None]) -> float | None:
    """The diagonal (metres) of the room a row's scene layer holds; None when unreadable (the
    scene checks report it)."""
    if scene is None:
        return None
    key = str(Path(scene).parent)  # the layouts of a room share its size
    if key not in cache:
        from sgdata.usd.room_io import read_room  # pxr only when a dataset has channels

        path = root / scene
        try:
            room = read_room(path) if path.is_file() and ".." not in Path(scene).parts else None
        except SgdataError:
            room = None
        cache[key] = (
            None if room is None else math.sqrt(room.width**2 + room.depth**2 + room.height**2)
        )
    return cache[key]
