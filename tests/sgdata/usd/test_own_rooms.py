"""Own rooms: hand-written USD stages (any up axis and unit) tagged, read, laid out and rendered."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from pxr import Gf, Sdf, Usd, UsdGeom, Vt

from sgdata.errors import UsdError
from sgdata.usd.geometry import read_geometry
from sgdata.usd.room_io import read_room
from sgdata.usd.scene_dirs import load_layout, write_layouts
from sgdata.usd.stage import validate_stage
from sgdata.usd.tagging import tag_stage

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


VARIANTS = {
    "z_up_metres_meshes": {},
    "y_up_centimetres_gprims_nested": {"up": "Y", "mpu": 0.01, "gprims": True, "nested": True},
    "z_up_optional_attrs_no_door": {"optional": True, "door": False, "nested": True},
}


@pytest.fixture(params=sorted(VARIANTS))
def user_room(request: pytest.FixtureRequest, tmp_path: Path) -> tuple[str, Path]:
    return request.param, write_user_room(tmp_path / "my room.usda", **VARIANTS[request.param])


def by_class(room) -> dict:  # noqa: ANN001
    return {o.class_name: o for o in room.objects}


def test_user_room_reads_before_tagging(user_room: tuple[str, Path]) -> None:
    name, path = user_room
    room = read_room(path)
    assert (room.width, room.depth, room.height) == pytest.approx((4.0, 3.0, 2.5), abs=1e-6)
    objects = by_class(room)
    assert objects["Mug"].support == objects["DiningTable"].instance
    assert objects["DiningTable"].support is None
    assert objects["DiningTable"].size == pytest.approx((1.2, 0.8, 0.75), abs=1e-5)
    fridge = objects["Fridge"]
    assert fridge.size == pytest.approx((0.7, 0.8, 1.8), abs=1e-5)
    assert math.degrees(fridge.placement.yaw) == pytest.approx(90.0)
    # room frame: the interior's south-west floor corner is the origin
    assert (fridge.placement.x, fridge.placement.y) == pytest.approx((3.6, 2.55), abs=1e-6)
    if name.startswith("z_up_optional"):
        assert objects["DiningTable"].instance == 5
        assert room.door.wall in ("south", "east", "north", "west")
        assert room.door.width == pytest.approx(0.9)
    else:
        assert room.door.wall == "south"
        assert room.door.center == pytest.approx(0.95, abs=1e-6)
        assert room.door.width == pytest.approx(0.9, abs=1e-6)
        assert room.door.top == pytest.approx(2.1, abs=1e-6)


def test_tag_writes_a_layer_and_leaves_the_user_file_alone(user_room: tuple[str, Path]) -> None:
    _, path = user_room
    before = path.read_bytes()
    report = tag_stage(path)
    assert path.read_bytes() == before
    assert report.output == path.parent / "my room_sgdata" / "room.usda"
    assert report.problems == ()
    assert report.usd_problems == ()
    assert validate_stage(path) == []
    assert any("rests on" in line for line in report.inferred)
    tagged = read_room(report.output)
    objects = by_class(tagged)
    assert objects["Mug"].support == objects["DiningTable"].instance
    assert [o.instance for o in tagged.objects] == [o.instance for o in report.room.objects]
    again = tag_stage(path, output=path.parent / "again.usda")
    assert read_room(again.output) == tagged
    with pytest.raises(Exception, match="never written"):
        tag_stage(path, output=path)


def test_geometry_is_in_the_room_frame(user_room: tuple[str, Path]) -> None:
    _, path = user_room
    report = tag_stage(path)
    room = read_room(report.output)
    geometry = read_geometry(report.output)
    for og in geometry.objects:
        obj = room.by_instance()[og.instance]
        w = og.world_vertices()
        lo, hi = obj.world_aabb()
        np.testing.assert_allclose(w.min(axis=0), lo, atol=1e-5)
        np.testing.assert_allclose(w.max(axis=0), hi, atol=1e-5)
    floor = np.concatenate([m.vertices for m in geometry.structure])
    assert floor[:, 2].min() == pytest.approx(-0.05, abs=1e-6)


def test_layouts_and_render_of_a_tagged_room(user_room: tuple[str, Path]) -> None:
    from sgdata.annotate.annotator import ViewAnnotator
    from sgdata.annotate.records import ViewPose
    from sgdata.annotate.slots import SlotTable
    from sgdata.render.renderer import Renderer
    from sgdata.world.catalog import load_catalog

    _, path = user_room
    report = tag_stage(path)
    room_dir = report.output.parent
    base = load_layout(room_dir, 0)  # no layout files yet: layout 0 is room.usda
    layouts = write_layouts(room_dir, count=3, seed=1)
    for layout in layouts:
        composed = load_layout(room_dir, layout.index)
        for obj in layout.room.objects:
            got = composed.by_instance()[obj.instance]
            assert got.support == obj.support
            np.testing.assert_allclose(
                got.corners(), obj.corners(), atol=1e-5, err_msg=f"layout {layout.index}"
            )
        assert validate_stage(room_dir / f"layout_{layout.index}.usda") == []
    catalog = load_catalog()
    table = by_class(base)["DiningTable"].placement
    with Renderer() as renderer:
        annotator = ViewAnnotator(renderer, SlotTable.from_catalog(catalog), min_visible_pixels=5)
        annotator.set_layout(base, read_geometry(report.output), 0)
        x, y = table.x, table.y - 1.2  # south of the table, looking north at it
        record = annotator.view(ViewPose(x, y, math.pi / 2, 0, 0, 1))
    names = {int(i): c for i, c in zip(record.obj_instance, record.obj_class, strict=True)}
    objects = by_class(base)
    assert objects["Mug"].instance in names and objects["DiningTable"].instance in names
    on = [
        (names[int(s)], names[int(o)])
        for s, o, r in zip(record.rel_src, record.rel_dst, record.rel_type, strict=True)
        if r == 0
    ]
    assert ("Mug", "DiningTable") in on


def test_unknown_class_needs_a_class_file(tmp_path: Path) -> None:
    path = write_user_room(tmp_path / "room.usda")
    stage = Usd.Stage.Open(str(path))
    stage.GetPrimAtPath("/Room/Mug").GetAttribute("sgdata:class").Set("Teacup")
    stage.GetRootLayer().Save()
    with pytest.raises(UsdError, match=r"/Room/Mug sgdata:class 'Teacup' is not a catalog"):
        tag_stage(path)
    classes = tmp_path / "classes.toml"
    classes.write_text('[classes]\nTeacup = "high"\n')
    report = tag_stage(path, classes=classes)
    assert by_class(report.room)["Teacup"].dynamics == "high"
    assert "not in the catalog" in report.problems[0]


def test_tag_command(tmp_path: Path) -> None:
    from sgdata_cli.sgdata_app import app
    from typer.testing import CliRunner

    path = write_user_room(tmp_path / "room.usda", up="Y", mpu=0.01)
    before = path.read_bytes()
    out = tmp_path / "tagged" / "room.usda"
    result = CliRunner().invoke(app, ["tag", str(path), "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert "rests on" in result.output and "warning" not in result.output
    assert path.read_bytes() == before
    result = CliRunner().invoke(app, ["preview", str(out), "-o", str(tmp_path / "top.png")])
    assert result.exit_code == 0, result.output
    result = CliRunner().invoke(app, ["render", str(out.parent), "-o", str(tmp_path / "v.png")])
    assert result.exit_code == 0, result.output
    assert (tmp_path / "v.overlay.png").is_file()
