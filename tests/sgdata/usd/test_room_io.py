"""Tests of room and layout USD writing, reading, geometry and validation on real pxr stages."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from pxr import Gf, Sdf, Usd, UsdGeom, Vt

from sgdata.errors import UsdError
from sgdata.usd.geometry import read_geometry
from sgdata.usd.layout_layers import read_layout_provenance, write_layout
from sgdata.usd.room_io import catalog_geometry, read_room, write_room
from sgdata.usd.stage import check_stage, validate_stage
from sgdata.world.catalog import Catalog, ClassSpec
from sgdata.world.scene import Dynamics, Opening, Placement, Room, SceneObject
from sgdata.world.shapes import build_shape, merged_mesh


def block_geometry(obj: SceneObject) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every object as the ``block`` recipe: no catalog needed."""
    return merged_mesh(build_shape("block", obj.size, obj.variant, obj.color))


def tiny_room() -> Room:
    """A kitchen with a counter, a mug on it, a drawer attached to it, and a rotated chair."""
    counter = SceneObject(
        instance=1,
        class_name="CounterTop",
        dynamics=Dynamics.STATIC,
        size=(1.2, 0.6, 0.9),
        placement=Placement(1.0, 2.7, 0.0, math.pi),
        color=(0.5, 0.25, 0.125),
    )
    mug = SceneObject(
        instance=2,
        class_name="Mug",
        dynamics=Dynamics.HIGH,
        size=(0.08, 0.08, 0.1),
        placement=Placement(1.1, 2.65, 0.9, 0.3),
        variant=1,
        color=(0.9, 0.1, 0.2),
        support=1,
    )
    drawer = SceneObject(
        instance=3,
        class_name="Drawer",
        dynamics=Dynamics.STATIC,
        size=(0.5, 0.5, 0.2),
        placement=Placement(1.0, 2.7, 0.6, math.pi),
        attached_to=1,
    )
    chair = SceneObject(
        instance=14,
        class_name="Chair",
        dynamics=Dynamics.LOW,
        size=(0.45, 0.5, 0.9),
        placement=Placement(2.0, 1.0, 0.0, 1.234567890123),
    )
    return Room(
        room_id="kitchen_003",
        room_type="kitchen",
        width=3.5,
        depth=3.0,
        height=2.5,
        seed=2**62 + 17,
        door=Opening(wall="south", center=1.2, width=0.9, bottom=0.0, top=2.05),
        objects=(counter, mug, drawer, chair),
    )


def moved_layout(room: Room) -> Room:
    """The mug moved to the floor, the chair nudged; counter and drawer stay."""
    objs = room.by_instance()
    mug = replace(objs[2], placement=Placement(0.5, 0.5, 0.0, -1.0), support=None)
    chair = objs[14].moved_to(Placement(2.1, 1.05, 0.0, 1.5))
    return room.with_objects([objs[1], mug, objs[3], chair])


@pytest.fixture
def room_file(tmp_path: Path) -> Path:
    path = tmp_path / "room.usda"
    write_room(tiny_room(), path, geometry=block_geometry)
    return path


def test_round_trip(room_file: Path) -> None:
    room = tiny_room()
    back = read_room(room_file)
    assert back == room  # ids, seed, door, sizes, colours, supports, attached, order
    for a, b in zip(room.objects, back.objects, strict=True):
        pa, pb = a.placement, b.placement
        assert max(abs(pa.x - pb.x), abs(pa.y - pb.y), abs(pa.z - pb.z)) <= 1e-9
        assert abs(pa.yaw - pb.yaw) <= 1e-9


def test_writes_are_byte_identical(tmp_path: Path) -> None:
    a, b = tmp_path / "a" / "room.usda", tmp_path / "b" / "room.usda"
    write_room(tiny_room(), a, geometry=block_geometry)
    write_room(tiny_room(), b, geometry=block_geometry)
    first = a.read_bytes()
    write_room(tiny_room(), a, geometry=block_geometry)  # rewrite in place
    assert a.read_bytes() == first == b.read_bytes()
    assert not [p for p in a.parent.iterdir() if p.name != "room.usda"]  # no temp files left


def test_room_layout_contract(room_file: Path) -> None:
    stage = Usd.Stage.Open(str(room_file))
    assert UsdGeom.GetStageUpAxis(stage) == UsdGeom.Tokens.z
    assert UsdGeom.GetStageMetersPerUnit(stage) == 1.0
    assert stage.GetDefaultPrim().GetPath() == Sdf.Path("/Room")
    assert Usd.ModelAPI(stage.GetDefaultPrim()).GetKind() == "assembly"
    for name in ("Floor", "Ceiling", "Walls"):
        assert stage.GetPrimAtPath(f"/Room/Structure/{name}").IsA(UsdGeom.Mesh)
    names = [p.GetName() for p in stage.GetPrimAtPath("/Room/Objects").GetChildren()]
    assert names == ["CounterTop_0001", "Mug_0002", "Drawer_0003", "Chair_0014"]
    chair = UsdGeom.Xform(stage.GetPrimAtPath("/Room/Objects/Chair_0014"))
    ops = chair.GetOrderedXformOps()
    assert [op.GetOpName() for op in ops] == ["xformOp:translate", "xformOp:rotateZ"]
    assert all(op.GetPrecision() == UsdGeom.XformOp.PrecisionDouble for op in ops)
    mesh = UsdGeom.Mesh(stage.GetPrimAtPath("/Room/Objects/Chair_0014/Geom"))
    assert set(mesh.GetFaceVertexCountsAttr().Get()) == {3}
    assert mesh.GetDisplayColorPrimvar().GetInterpolation() == UsdGeom.Tokens.uniform
    walls = UsdGeom.Mesh(stage.GetPrimAtPath("/Room/Structure/Walls"))
    points = np.array(walls.GetPointsAttr().Get())
    # the door gap: nothing of the south wall between x = 0.75 and 1.65 below z = 2.05
    south = points[(points[:, 1] <= 0.0)]
    tris = np.array(walls.GetFaceVertexIndicesAttr().Get()).reshape(-1, 3)
    centers = points[tris].mean(axis=1)
    in_gap = (centers[:, 0] > 0.75) & (centers[:, 0] < 1.65) & (centers[:, 1] < 0)
    assert len(south) and not (in_gap & (centers[:, 2] < 2.05)).any()


def test_layout_overrides_only_moved_objects(room_file: Path) -> None:
    room = tiny_room()
    layout = moved_layout(room)
    path = room_file.parent / "layout_1.usda"
    write_layout(room, layout, path, index=1, seed=99, moves=[])
    layer = Sdf.Layer.FindOrOpen(str(path))
    assert list(layer.subLayerPaths) == ["./room.usda"]
    objects = layer.GetPrimAtPath("/Room/Objects")
    assert [c.name for c in objects.nameChildren] == ["Mug_0002", "Chair_0014"]
    for spec in [layer.GetPrimAtPath("/Room"), objects, *objects.nameChildren]:
        assert spec.specifier == Sdf.SpecifierOver
    assert set(objects.nameChildren["Chair_0014"].properties.keys()) == {
        "xformOp:translate",
        "xformOp:rotateZ",
    }
    assert "sgdata:support" in objects.nameChildren["Mug_0002"].properties
    back = read_room(path)
    assert back == layout
    assert back.by_instance()[2].support is None
    assert read_room(room_file) == room  # the base is untouched


def test_layout_support_changes_to_another_object(room_file: Path) -> None:
    room = tiny_room()
    objs = room.by_instance()
    on_chair = objs[2].moved_to(Placement(2.0, 1.0, 0.45, 0.0), support=14)
    layout = room.with_objects([objs[1], on_chair, objs[3], objs[14]])
    path = room_file.parent / "layout_2.usda"
    write_layout(room, layout, path, index=2, seed=5, moves=[])
    assert read_room(path).by_instance()[2].support == 14


def test_provenance_round_trips(room_file: Path) -> None:
    moves = [
        {
            "instance": 2,
            "class": "Mug",
            "rule": "high",
            "from": [1.1, 2.65, 0.9, 0.3],
            "to": [0.5, 0.5, 0.0, -1.0],
            "fromSupport": 1,
            "toSupport": None,
            "moved": True,
        },
        {"instance": 14, "class": "Chair", "rule": "low", "moved": np.bool_(True)},
    ]
    path = room_file.parent / "layout_1.usda"
    seed = 2**63 - 1
    write_layout(tiny_room(), moved_layout(tiny_room()), path, index=1, seed=seed, moves=moves)
    got = read_layout_provenance(path)
    assert got == {"layout": 1, "seed": seed, "moves": [moves[0], {**moves[1], "moved": True}]}


def test_layout_writes_are_byte_identical(room_file: Path) -> None:
    a, b = room_file.parent / "layout_1.usda", room_file.parent / "layout_2.usda"
    for path in (a, b):
        write_layout(tiny_room(), moved_layout(tiny_room()), path, index=1, seed=3, moves=[])
    assert a.read_bytes() == b.read_bytes()


def test_validators_pass(room_file: Path) -> None:
    path = room_file.parent / "layout_0.usda"
    write_layout(tiny_room(), moved_layout(tiny_room()), path, index=0, seed=1, moves=[])
    assert validate_stage(room_file) == []
    assert validate_stage(path) == []
    check_stage(path)


def test_validators_report_problems(tmp_path: Path) -> None:
    path = tmp_path / "bare.usda"
    path.write_text('#usda 1.0\n\ndef Xform "A"\n{\n}\n')
    problems = validate_stage(path)
    assert any("upAxis" in p for p in problems)
    with pytest.raises(UsdError, match="bare.usda: fails USD validation"):
        check_stage(path)


def test_geometry_matches_placement(room_file: Path) -> None:
    geometry = read_geometry(room_file)
    assert {m.name.rsplit("/", 1)[-1] for m in geometry.structure} == {"Floor", "Ceiling", "Walls"}
    assert [o.instance for o in geometry.objects] == [1, 2, 3, 14]
    chair = tiny_room().by_instance()[14]
    got = next(o for o in geometry.objects if o.instance == 14)
    assert got.class_name == "Chair"
    local, faces, colors = block_geometry(chair)
    np.testing.assert_allclose(got.mesh.vertices, local, atol=1e-6)
    np.testing.assert_array_equal(got.mesh.faces, faces)
    np.testing.assert_allclose(got.mesh.face_colors, colors, atol=1e-7)
    np.testing.assert_allclose(got.matrix, chair.placement.matrix(), atol=1e-12)
    expected = (np.c_[local, np.ones(len(local))] @ chair.placement.matrix().T)[:, :3]
    np.testing.assert_allclose(got.world_vertices(), expected, atol=1e-6)


def test_layout_geometry_uses_layout_placement(room_file: Path) -> None:
    path = room_file.parent / "layout_1.usda"
    layout = moved_layout(tiny_room())
    write_layout(tiny_room(), layout, path, index=1, seed=3, moves=[])
    got = {o.instance: o for o in read_geometry(path).objects}
    np.testing.assert_allclose(
        got[2].matrix, layout.by_instance()[2].placement.matrix(), atol=1e-12
    )


def test_catalog_geometry(tmp_path: Path) -> None:
    spec = ClassSpec(
        name="Chair",
        dynamics=Dynamics.LOW,
        shape="block",
        size_min=(0.4, 0.4, 0.8),
        size_max=(0.5, 0.5, 0.9),
        placement="floor",
        wall_height=(0.0, 0.0),
        receptacles=(),
        containers=(),
        max_instances=4,
        palette=((0.5, 0.5, 0.5),),
        variants=1,
    )
    catalog = Catalog(classes={"Chair": spec}, source="test")
    chair = tiny_room().by_instance()[14]
    room = tiny_room().with_objects([chair])
    write_room(room, tmp_path / "room.usda", geometry=catalog_geometry(catalog))
    (got,) = read_geometry(tmp_path / "room.usda").objects
    np.testing.assert_allclose(got.mesh.vertices, block_geometry(chair)[0], atol=1e-6)


def test_missing_sublayer_raises(room_file: Path) -> None:
    path = room_file.parent / "layout_1.usda"
    write_layout(tiny_room(), moved_layout(tiny_room()), path, index=1, seed=3, moves=[])
    room_file.unlink()
    with pytest.raises(UsdError, match=r"layout_1\.usda: sublayer './room.usda' not found"):
        read_room(path)
    with pytest.raises(UsdError, match="sublayer"):
        read_geometry(path)
    assert read_layout_provenance(path)["layout"] == 1  # the layer alone still reads


def test_missing_and_unreadable_files(tmp_path: Path) -> None:
    with pytest.raises(UsdError, match="nope.usda: USD file not found"):
        read_room(tmp_path / "nope.usda")
    bad = tmp_path / "bad.usda"
    bad.write_text('#usda 1.0\ndef Xform "Room" {{{\n')
    with pytest.raises(UsdError, match="bad.usda: unreadable USD layer"):
        read_room(bad)


def test_object_without_class_raises(room_file: Path) -> None:
    layer = Sdf.Layer.FindOrOpen(str(room_file))
    del layer.GetPrimAtPath("/Room/Objects/Mug_0002").properties["sgdata:class"]
    layer.Save()
    with pytest.raises(UsdError, match="Mug_0002 lacks attribute sgdata:class"):
        read_room(room_file)


def test_rewrite_is_seen_by_reader(room_file: Path) -> None:
    held = Sdf.Layer.FindOrOpen(str(room_file))  # a copy kept open in this process
    room = tiny_room()
    changed = room.with_objects(room.objects[:2])
    write_room(changed, room_file, geometry=block_geometry)
    assert read_room(room_file) == changed
    assert held.GetPrimAtPath("/Room/Objects/Chair_0014") is None


def test_foreign_stage_geometry(tmp_path: Path) -> None:
    """A stage authored by hand: other names, a quad mesh, constant colour, nested transform."""
    path = tmp_path / "foreign.usda"
    stage = Usd.Stage.CreateNew(str(path))
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.z)
    UsdGeom.Xform.Define(stage, "/World")
    table = UsdGeom.Xform.Define(stage, "/World/MyTable")
    table.AddTranslateOp().Set(Gf.Vec3d(1.0, 2.0, 0.0))
    table.AddRotateZOp().Set(90.0)
    prim = table.GetPrim()
    prim.CreateAttribute("sgdata:instance", Sdf.ValueTypeNames.Int).Set(7)
    prim.CreateAttribute("sgdata:class", Sdf.ValueTypeNames.String).Set("Table")
    top = UsdGeom.Xform.Define(stage, "/World/MyTable/Top")
    top.AddTranslateOp().Set(Gf.Vec3d(0.0, 0.0, 0.5))
    quad = UsdGeom.Mesh.Define(stage, "/World/MyTable/Top/Board")
    quad.CreatePointsAttr([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0.5, 1.5, 0)])
    quad.CreateFaceVertexCountsAttr([5])
    quad.CreateFaceVertexIndicesAttr([0, 1, 2, 4, 3])
    quad.CreateDisplayColorPrimvar(UsdGeom.Tokens.constant).Set(Vt.Vec3fArray([(1, 0, 0)]))
    floor = UsdGeom.Mesh.Define(stage, "/World/Ground")
    floor.CreatePointsAttr([(0, 0, 0), (4, 0, 0), (4, 4, 0), (0, 4, 0)])
    floor.CreateFaceVertexCountsAttr([4])
    floor.CreateFaceVertexIndicesAttr([0, 1, 2, 3])
    floor.CreateDisplayColorPrimvar(UsdGeom.Tokens.vertex).Set(
        Vt.Vec3fArray([(0, 0, 0), (1, 1, 1), (1, 1, 1), (0, 0, 0)])
    )
    stage.GetRootLayer().Save()

    geometry = read_geometry(path)
    assert len(geometry.structure) == 1
    ground = geometry.structure[0]
    assert ground.faces.shape == (2, 3)
    np.testing.assert_allclose(ground.face_colors, [[2 / 3] * 3, [1 / 3] * 3], atol=1e-6)
    (obj,) = geometry.objects
    assert (obj.instance, obj.class_name) == (7, "Table")
    assert obj.mesh.faces.shape == (3, 3)  # pentagon -> 3-triangle fan
    np.testing.assert_allclose(obj.mesh.face_colors, np.tile([1.0, 0.0, 0.0], (3, 1)))
    np.testing.assert_allclose(obj.mesh.vertices[:, 2], 0.5)  # Top's offset is in the local frame
    expected = np.array([[0, -1, 0, 1], [1, 0, 0, 2], [0, 0, 1, 0], [0, 0, 0, 1]], float)
    np.testing.assert_allclose(obj.matrix, expected, atol=1e-12)
    np.testing.assert_allclose(obj.world_vertices()[1], [1.0, 3.0, 0.5], atol=1e-12)
