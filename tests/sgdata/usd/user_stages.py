"""Hand-written user rooms (any up axis and unit, meshes or gprims, nested or flat), shared by
the own-room tests and the ``[rooms] files`` generation tests."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from pxr import Gf, Sdf, Usd, UsdGeom, Vt

# the room in room-frame metres: interior x in [-2, 2], y in [-1.5, 1.5], 2.5 m high, a door
# gap in the south wall from x = -1.5 to -0.6, 2.1 m high
HALF_W, HALF_D, HEIGHT, WALL = 2.0, 1.5, 2.5, 0.1
DOOR = (-1.5, -0.6, 2.1)
TABLE_AT, MUG_AT, FRIDGE_AT = (0.5, 0.2), (0.6, 0.1), (1.6, 1.05)


class Author:
    """Writes boxes and cylinders given in room-frame metres into a stage of any axis and unit."""

    def __init__(self, stage: Usd.Stage, up: str, mpu: float, gprims: bool) -> None:
        self.stage, self.up, self.mpu, self.gprims = stage, up, mpu, gprims

    def vec(self, p: tuple[float, float, float]) -> Gf.Vec3d:
        x, y, z = (v / self.mpu for v in p)
        return Gf.Vec3d(x, z, -y) if self.up == "Y" else Gf.Vec3d(x, y, z)

    def xform(self, path: str, at: tuple[float, float, float], yaw_deg: float = 0.0) -> Usd.Prim:
        xf = UsdGeom.Xform.Define(self.stage, path)
        xf.AddTranslateOp().Set(self.vec(at))
        if yaw_deg:
            (xf.AddRotateYOp() if self.up == "Y" else xf.AddRotateZOp()).Set(yaw_deg)
        return xf.GetPrim()

    def box(self, path: str, lo: tuple, hi: tuple, color: tuple) -> None:
        """An axis-aligned box [lo, hi] in its parent's frame (room axes, metres)."""
        lo, hi = np.array(lo, float), np.array(hi, float)
        if self.gprims:
            cube = UsdGeom.Cube.Define(self.stage, path)
            cube.CreateSizeAttr(1.0)
            cube.AddTranslateOp().Set(self.vec(tuple((lo + hi) / 2)))
            ext = np.abs(np.array(self.vec(tuple(hi - lo))))
            cube.AddScaleOp().Set(Gf.Vec3f(*ext))
            cube.CreateDisplayColorPrimvar().Set(Vt.Vec3fArray([color]))
            return
        corners = [self.vec(tuple(np.where([i & 1, i & 2, i & 4], hi, lo))) for i in range(8)]
        quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]]
        mesh = UsdGeom.Mesh.Define(self.stage, path)
        mesh.CreatePointsAttr(corners)
        mesh.CreateFaceVertexCountsAttr([4] * 6)
        mesh.CreateFaceVertexIndicesAttr([i for q in quads for i in q])
        mesh.CreateExtentAttr(UsdGeom.Mesh.ComputeExtent(mesh.GetPointsAttr().Get()))
        mesh.CreateDisplayColorPrimvar().Set(Vt.Vec3fArray([color]))

    def cylinder(self, path: str, centre: tuple, radius: float, height: float) -> None:
        cyl = UsdGeom.Cylinder.Define(self.stage, path)
        cyl.CreateAxisAttr(self.up)
        cyl.CreateRadiusAttr(radius / self.mpu)
        cyl.CreateHeightAttr(height / self.mpu)
        cyl.CreateExtentAttr([(-radius / self.mpu,) * 3, (radius / self.mpu,) * 3])
        cyl.AddTranslateOp().Set(self.vec(centre))
        cyl.CreateDisplayColorPrimvar().Set(Vt.Vec3fArray([(0.9, 0.9, 0.95)]))


def tag(prim: Usd.Prim, cls: str, **extra: object) -> None:
    prim.CreateAttribute("sgdata:class", Sdf.ValueTypeNames.String).Set(cls)
    types = {"dynamics": Sdf.ValueTypeNames.Token, "instance": Sdf.ValueTypeNames.Int}
    for name, value in extra.items():
        prim.CreateAttribute(f"sgdata:{name}", types[name]).Set(value)


def write_user_room(
    path: Path,
    *,
    up: str = "Z",
    mpu: float = 1.0,
    gprims: bool = False,
    nested: bool = False,
    door: bool = True,
    optional: bool = False,
) -> Path:
    """A hand-written room: floor, four walls, a dining table, a mug on it, a fridge."""
    stage = Usd.Stage.CreateNew(str(path))
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y if up == "Y" else UsdGeom.Tokens.z)
    UsdGeom.SetStageMetersPerUnit(stage, mpu)
    a = Author(stage, up, mpu, gprims)
    root = UsdGeom.Xform.Define(stage, "/Room").GetPrim()
    stage.SetDefaultPrim(root)
    UsdGeom.Xform.Define(stage, "/Room/Shell")
    grey, wall = (0.5, 0.5, 0.5), (0.85, 0.83, 0.8)
    a.box("/Room/Shell/Floor", (-HALF_W, -HALF_D, -0.05), (HALF_W, HALF_D, 0.0), grey)
    w, d, t, h = HALF_W, HALF_D, WALL, HEIGHT
    if door:
        x0, x1, top = DOOR
        a.box("/Room/Shell/SouthA", (-w - t, -d - t, 0), (x0, -d, h), wall)
        a.box("/Room/Shell/SouthB", (x1, -d - t, 0), (w + t, -d, h), wall)
        a.box("/Room/Shell/SouthTop", (x0, -d - t, top), (x1, -d, h), wall)
    else:
        a.box("/Room/Shell/South", (-w - t, -d - t, 0), (w + t, -d, h), wall)
    a.box("/Room/Shell/North", (-w - t, d, 0), (w + t, d + t, h), wall)
    a.box("/Room/Shell/West", (-w - t, -d, 0), (-w, d, h), wall)
    a.box("/Room/Shell/East", (w, -d, 0), (w + t, d, h), wall)

    group = "/Room/Furniture/Dining" if nested else "/Room/Things"
    if nested:
        a.xform("/Room/Furniture", (0.0, 0.0, 0.0))
        a.xform(group, (0.1, 0.0, 0.0))  # a transformed group between room and table
    else:
        UsdGeom.Xform.Define(stage, group)
    tx, ty = TABLE_AT
    gx = 0.1 if nested else 0.0
    table = a.xform(f"{group}/Table", (tx - gx, ty, 0.0))
    tag(table, "DiningTable", **({"dynamics": "low", "instance": 5} if optional else {}))
    wood = (0.55, 0.35, 0.2)
    a.box(f"{group}/Table/Top", (-0.6, -0.4, 0.71), (0.6, 0.4, 0.75), wood)
    legs = f"{group}/Table/Legs" if nested else f"{group}/Table"
    if nested:
        UsdGeom.Xform.Define(stage, legs)
    for k, (sx, sy) in enumerate([(-1, -1), (1, -1), (1, 1), (-1, 1)]):
        cx, cy = sx * 0.55, sy * 0.35
        a.box(f"{legs}/Leg{k}", (cx - 0.025, cy - 0.025, 0), (cx + 0.025, cy + 0.025, 0.71), wood)
    if nested:  # the mug is a child of the table: it moves with it in USD too
        mug_path, mug_at = f"{group}/Table/Mug", (MUG_AT[0] - tx, MUG_AT[1] - ty, 0.75)
    else:
        mug_path, mug_at = "/Room/Mug", (*MUG_AT, 0.75)
    tag(a.xform(mug_path, mug_at), "Mug")
    a.cylinder(f"{mug_path}/Body", (0.0, 0.0, 0.05), 0.04, 0.1)
    fridge = a.xform("/Room/Fridge", (*FRIDGE_AT, 0.0), yaw_deg=90.0)
    tag(fridge, "Fridge", **({"dynamics": "static"} if optional else {}))
    a.box("/Room/Fridge/Body", (-0.35, -0.4, 0.0), (0.35, 0.4, 1.8), (0.95, 0.95, 0.95))
    stage.GetRootLayer().Save()
    return path
