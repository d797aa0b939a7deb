"""Scene checks: every USD layer a row's ``scene`` names exists and composes; with ``usd``,
USD's own validators run on it too (:func:`sgdata.usd.stage.validate_stage`)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from sgdata.errors import UsdError
from sgdata.validate.loading import SplitTables, column_numpy
from sgdata.validate.problems import Collector

__all__ = ["check_scenes"]


def check_scenes(root: Path, splits: list[SplitTables], out: Collector, *, usd: bool) -> None:
    """Open each distinct referenced scene once; report problems at its first row."""
    from sgdata.usd.stage import open_stage, validate_stage  # pxr only when scenes are checked

    first: dict[str, tuple[str, int]] = {}
    for tables in splits:
        if tables.observations is None:
            continue
        scene = column_numpy(tables.observations, "scene")
        for k in np.flatnonzero(scene != None):  # noqa: E711  (object array of str | None)
            if scene[k] not in first:
                f, row = tables.where(k)
                first[scene[k]] = (tables.files[f], int(row))
    for rel, (file, row) in sorted(first.items()):
        out.count("scenes.exist")
        path = root / rel
        bad_path = rel.startswith("/") or ".." in Path(rel).parts
        if bad_path or not path.is_file():
            out.add("scenes.exist", file, f"scene {rel!r} does not exist", row=row, field="scene")
            continue
        out.count("scenes.open")
        try:
            open_stage(path)
        except UsdError as exc:
            out.add("scenes.open", file, f"scene {rel!r}: {exc}", row=row, field="scene")
            continue
        if usd:
            out.count("scenes.usd")
            try:
                problems = validate_stage(path)
            except UsdError as exc:
                problems = [str(exc)]
            for message in problems:
                out.add("scenes.usd", rel, message)
