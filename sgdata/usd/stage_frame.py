"""The room frame of a stage: its up axis, ``metersPerUnit`` and room origin mapped to Z-up metres.

sgdata works in one frame (docs/architecture.md): Z up, metres, the room's interior spanning
``[0, width] x [0, depth]`` with the floor at ``z = 0``. A stage written by another tool may be
Y-up, in centimetres, and centred anywhere; :func:`stage_frame` is the 4x4 transform taking its
coordinates into the room frame (a stage without ``metersPerUnit`` counts as metres).
``sgdata:roomOrigin`` (double3 on the room prim, metres, in the
up-corrected axes) is the point that becomes the room frame's origin; ``sgdata tag`` writes it.
"""

from __future__ import annotations

import math

import numpy as np
from pxr import Usd, UsdGeom

from sgdata.errors import UsdError
from sgdata.usd.prims import ROOM_ORIGIN, ROOT

__all__ = ["meters_per_unit", "room_prim", "stage_frame", "up_and_units"]


# stage axes -> Z-up axes: a Y-up stage's +Y becomes +Z, its +Z becomes -Y (a +90 degree turn
# about X), so right-handed frames stay right-handed
_Y_UP = np.array([[1.0, 0, 0, 0], [0, 0, -1.0, 0], [0, 1.0, 0, 0], [0, 0, 0, 1.0]])


def room_prim(stage: Usd.Stage) -> Usd.Prim:
    """The room prim: ``/Room`` when present, else the stage's default prim (maybe invalid)."""
    prim = stage.GetPrimAtPath(ROOT)
    if prim.IsValid():
        return prim
    return stage.GetDefaultPrim()


def meters_per_unit(stage: Usd.Stage) -> float:
    """The stage's ``metersPerUnit`` as sgdata reads it: 1 when the stage does not author one.

    Raises:
        UsdError: an authored value that is not a positive finite number.
    """
    # USD's fallback is centimetres; sgdata has always read stages without the field as metres
    if not UsdGeom.StageHasAuthoredMetersPerUnit(stage):
        return 1.0
    value = float(UsdGeom.GetStageMetersPerUnit(stage))
    if not (math.isfinite(value) and value > 0):
        raise UsdError(
            f"{stage.GetRootLayer().identifier}: metersPerUnit is {value:g}; expected a positive "
            "number (1 for metres, 0.01 for centimetres)"
        )
    return value


def up_and_units(stage: Usd.Stage) -> np.ndarray:
    """The 4x4 transform (column convention) turning stage axes and units into Z-up metres."""
    scale = meters_per_unit(stage)
    m = np.diag([scale, scale, scale, 1.0])
    if UsdGeom.GetStageUpAxis(stage) == UsdGeom.Tokens.y:
        m = _Y_UP @ m
    return m


def stage_frame(stage: Usd.Stage) -> np.ndarray | None:
    """The stage-to-room-frame transform, or ``None`` when the stage is in the room frame already.

    ``None`` (rather than an identity matrix) lets readers leave sgdata's own stages untouched,
    bit for bit.
    """
    m = up_and_units(stage)
    root = room_prim(stage)
    attr = root.GetAttribute(ROOM_ORIGIN) if root.IsValid() else None
    origin = attr.Get() if attr else None
    if origin is not None:
        shift = np.eye(4)
        shift[:3, 3] = -np.array(origin, dtype=np.float64)
        m = shift @ m
    return None if np.array_equal(m, np.eye(4)) else m
