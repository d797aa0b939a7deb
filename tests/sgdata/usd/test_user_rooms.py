"""User rooms: hand-written USD stages (any up axis and unit) tagged, read, laid out, rendered."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from pxr import Usd

from sgdata.errors import UsdError
from sgdata.usd.geometry import read_geometry
from sgdata.usd.room_io import read_room
from sgdata.usd.scene_dirs import load_layout, write_layouts
from sgdata.usd.stage import validate_stage
from sgdata.usd.tagging import tag_stage

from .user_stages import write_user_room

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


def test_class_file_alias_reads_as_the_catalog_class(tmp_path: Path) -> None:
    path = write_user_room(tmp_path / "room.usda")
    stage = Usd.Stage.Open(str(path))
    stage.GetPrimAtPath("/Room/Mug").GetAttribute("sgdata:class").Set("Teacup")
    stage.GetRootLayer().Save()
    before = path.read_bytes()
    classes = tmp_path / "classes.toml"
    classes.write_text('Teacup = "Mug"\nTeapot = "high"\n')
    report = tag_stage(path, classes=classes)
    assert path.read_bytes() == before
    mug = by_class(report.room)["Mug"]  # every Teacup prim is the catalog's Mug
    assert mug.dynamics == "high" and mug.support == by_class(report.room)["DiningTable"].instance
    assert report.problems == ()
    classes.write_text('Teacup = "Cupp"\n')
    with pytest.raises(Exception, match="class 'Teacup' is 'Cupp'; expected"):
        tag_stage(path, classes=classes)
