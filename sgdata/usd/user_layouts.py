"""Layout overrides for rooms authored elsewhere: moves written as each prim's own local matrix.

An object of a measured room (:mod:`sgdata.usd.user_rooms`) may sit anywhere in the hierarchy,
under transformed parents, in another up axis and unit. A layout moves it by the rigid motion
``D = new placement @ old placement^-1`` (room frame); its layer overrides the prim with one
``xformOp:transform`` whose value keeps the prim's geometry where ``D`` puts it, allowing for
an ancestor object that moved too.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from pxr import Gf, Sdf, Usd, UsdGeom

from sgdata.usd.stage import open_stage
from sgdata.usd.stage_frame import room_prim, stage_frame, up_and_units
from sgdata.usd.user_rooms import is_measured, measure_stage
from sgdata.world.scene import SceneObject

__all__ = ["UserFrame", "user_frame", "override_user"]


@dataclass(frozen=True)
class UserFrame:
    """What a layout of a measured room needs to know about its base stage."""

    paths: dict[int, str]  # instance -> object prim path
    frame: np.ndarray  # stage -> room frame (4x4, column convention)
    worlds: dict[int, np.ndarray]  # instance -> the prim's stage-space local-to-world matrix
    parents: dict[int, np.ndarray]  # instance -> its parent prim's local-to-world matrix
    owners: dict[int, int | None]  # instance -> the nearest ancestor object, if any
    up_axis: str
    meters_per_unit: float
    default_prim: str


def user_frame(room_path: Path) -> UserFrame | None:
    """The :class:`UserFrame` of a measured room stage (``room.usda`` written by ``sgdata tag``).

    ``None`` for a room written by ``sgdata rooms`` (its layouts override by placement).
    """
    stage = open_stage(room_path)
    if not is_measured(stage):
        return None
    measured = measure_stage(stage, Path(room_path))
    frame = stage_frame(stage)
    frame = np.eye(4) if frame is None else frame
    cache = UsdGeom.XformCache(Usd.TimeCode.Default())
    by_path = {p: i for i, p in measured.paths.items()}
    worlds, parents, owners = {}, {}, {}
    for instance, key in measured.paths.items():
        prim = stage.GetPrimAtPath(key)
        worlds[instance] = np.array(cache.GetLocalToWorldTransform(prim)).T
        parents[instance] = np.array(cache.GetLocalToWorldTransform(prim.GetParent())).T
        owner = None
        for prefix in reversed(prim.GetPath().GetParentPath().GetPrefixes()):
            if str(prefix) in by_path:
                owner = by_path[str(prefix)]
                break
        owners[instance] = owner
    scale = float(np.linalg.norm(up_and_units(stage)[:3, 0]))
    return UserFrame(
        measured.paths,
        frame,
        worlds,
        parents,
        owners,
        str(UsdGeom.GetStageUpAxis(stage)),
        scale,
        room_prim(stage).GetName(),
    )


def override_user(
    layer: Sdf.Layer,
    user: UserFrame,
    before: dict[int, SceneObject],
    after: dict[int, SceneObject],
    instance: int,
) -> None:
    """Override one moved object of ``layer`` with its new local matrix."""
    motion = _motion(before[instance], after[instance])
    owner = user.owners[instance]
    parent_motion = np.eye(4) if owner is None else _motion(before[owner], after[owner])
    parent = parent_motion @ user.frame @ user.parents[instance]
    local = np.linalg.inv(parent) @ motion @ user.frame @ user.worlds[instance]
    spec = Sdf.CreatePrimInLayer(layer, Sdf.Path(user.paths[instance]))
    matrix = Sdf.AttributeSpec(
        spec, "xformOp:transform", Sdf.ValueTypeNames.Matrix4d, Sdf.VariabilityVarying, False
    )
    matrix.default = Gf.Matrix4d(local.T.tolist())
    order = Sdf.AttributeSpec(
        spec, "xformOpOrder", Sdf.ValueTypeNames.TokenArray, Sdf.VariabilityUniform, False
    )
    order.default = ["xformOp:transform"]


def _motion(old: SceneObject, new: SceneObject) -> np.ndarray:
    return new.placement.matrix() @ np.linalg.inv(old.placement.matrix())
