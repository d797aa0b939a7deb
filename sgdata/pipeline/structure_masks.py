"""The structure mask of views already stored, drawn again from each view's scene layer.

``sgdata migrate`` fills the ``structure`` column (format 2.3.0) of an older dataset that stores
instance masks with it: the same renderer, camera and id pass as ``generate``, so the bytes
are those ``generate`` writes now.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa

from sgdata.dataset.channels import encode_mask
from sgdata.render.camera import CameraConfig
from sgdata.render.renderer import Renderer
from sgdata.usd.room_io import door_quad, read_scene

__all__ = ["structure_column"]


def structure_column(root: Path, table: pa.Table, config: dict[str, Any]) -> pa.Array:
    """The encoded structure mask of each row of an observation ``table`` that has an
    instance mask (null for the others), from its ``scene`` layer and pose; ``config`` is the
    manifest's resolved generation config (its camera and textures)."""
    camera = CameraConfig(**config["camera"])
    textures = bool(config.get("appearance", {}).get("textures", True))
    rows = table.select(["scene", "x", "y", "theta"]).to_pylist()
    masked = table.column("instances").is_valid().to_pylist()
    cells: list[bytes | None] = []
    with Renderer(camera, textures=textures) as renderer:
        loaded = None
        for row, has_mask in zip(rows, masked, strict=True):
            if not has_mask:
                cells.append(None)
                continue
            if row["scene"] != loaded:
                stage = root / row["scene"]
                room, geometry = read_scene(stage)
                geometry = dataclasses.replace(geometry, door=door_quad(room))
                renderer.load(geometry)
                loaded = row["scene"]
            parts = renderer.render_structure(row["x"], row["y"], row["theta"])
            cells.append(encode_mask(parts.astype(np.uint16)))
    return pa.array(cells, pa.binary())
