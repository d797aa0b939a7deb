"""Malformed meshes, gprims and transforms in a stage: one-line UsdErrors naming the prim."""

from __future__ import annotations

from pathlib import Path

import pytest
from pxr import Gf, Sdf, Usd, UsdGeom

from sgdata.errors import UsdError
from sgdata.usd.geometry import read_geometry
from sgdata.usd.room_sizes import check_sizes
from sgdata.usd.stage import open_stage
from sgdata.usd.user_rooms import measure_stage

from .user_stages import write_user_room

TOP = "/Room/Things/Table/Top"


def mutated(tmp_path: Path, change: str) -> Path:
    path = write_user_room(tmp_path / "room.usda")
    stage = Usd.Stage.Open(str(path))
    mesh = UsdGeom.Mesh(stage.GetPrimAtPath(TOP))
    if change == "inf point":
        points = list(mesh.GetPointsAttr().Get())
        points[0] = Gf.Vec3f(float("inf"), 0, 0)
        mesh.GetPointsAttr().Set(points)
    elif change == "negative index":
        indices = list(mesh.GetFaceVertexIndicesAttr().Get())
        indices[2] = -1
        mesh.GetFaceVertexIndicesAttr().Set(indices)
    elif change == "counts disagree":
        mesh.GetFaceVertexCountsAttr().Set([4] * 7)
    elif change == "zero scale":
        UsdGeom.Xformable(stage.GetPrimAtPath("/Room/Things/Table")).AddScaleOp().Set(
            Gf.Vec3f(1, 0, 1)
        )
    elif change == "negative radius":
        UsdGeom.Cylinder.Define(stage, "/Room/Mug/Body").GetRadiusAttr().Set(-0.04)
    elif change == "nan translate":
        UsdGeom.Xformable(stage.GetPrimAtPath("/Room/Mug")).GetOrderedXformOps()[0].Set(
            Gf.Vec3d(float("nan"), 0, 0)
        )
    elif change == "retyped points":  # string points = "-1" in the .usda text
        spec = stage.GetRootLayer().GetPrimAtPath(TOP)
        spec.RemoveProperty(spec.attributes["points"])
        Sdf.AttributeSpec(spec, "points", Sdf.ValueTypeNames.String).default = "-1"
    elif change == "retyped translate":
        spec = stage.GetRootLayer().GetPrimAtPath("/Room/Mug")
        spec.RemoveProperty(spec.attributes["xformOp:translate"])
        Sdf.AttributeSpec(spec, "xformOp:translate", Sdf.ValueTypeNames.Int).default = -1
    elif change == "negative units":
        stage.SetMetadata("metersPerUnit", -1.0)
    elif change == "overflowing units":
        stage.SetMetadata("metersPerUnit", 1e308)
    stage.GetRootLayer().Save()
    return path


# found by tests/fuzz: each raised a traceback (ValueError, pxr's ErrorException) or measured a
# room of NaN before its fix
CASES = {
    "retyped points": f"{TOP}.points holds '-1', authored with another value type; expected",
    "retyped translate": "/Room/Mug/Body: USD cannot compute its transform (Invalid combination",
    "negative units": "metersPerUnit is -1; expected a positive number (1 for metres, 0.01 for",
    "overflowing units": "/Room/Shell/Floor has coordinates that overflow to inf or NaN in metres",
    "inf point": f"{TOP} points[0] is (inf, ",
    "negative index": f"{TOP} faceVertexIndices[2] is -1, past the mesh's 8 points",
    "counts disagree": f"{TOP} faceVertexCounts sum to 28 but faceVertexIndices holds 24",
    "zero scale": "/Room/Things/Table has a singular transform",
    "negative radius": "/Room/Mug/Body.radius is -0.04; expected a positive finite number",
    "nan translate": "/Room/Mug/Body has a transform with NaN or infinite values",
}


@pytest.mark.parametrize("change", sorted(CASES))
def test_a_malformed_prim_is_named_in_one_line(tmp_path: Path, change: str) -> None:
    path = mutated(tmp_path, change)
    with pytest.raises(UsdError) as raised:
        read_geometry(path)
    message = str(raised.value)
    assert message.startswith(str(path)) and "\n" not in message
    assert CASES[change] in message


def test_supports_in_a_circle_are_refused(tmp_path: Path) -> None:
    # accepted before, then sampling layouts hung, growing memory (found by tests/fuzz)
    path = write_user_room(tmp_path / "room.usda")
    stage = Usd.Stage.Open(str(path))
    table, mug = stage.GetPrimAtPath("/Room/Things/Table"), stage.GetPrimAtPath("/Room/Mug")
    table.CreateRelationship("sgdata:support").SetTargets([mug.GetPath()])
    mug.CreateRelationship("sgdata:support").SetTargets([table.GetPath()])
    stage.GetRootLayer().Save()
    with pytest.raises(UsdError) as raised:
        measure_stage(open_stage(path), path)
    assert str(raised.value) == (
        f"{path}: /Room/Things/Table -> /Room/Mug -> /Room/Things/Table: sgdata:support goes "
        "round in a circle; expected every chain to end at an object on the floor or a wall: "
        "remove sgdata:support from one of them"
    )


def test_an_object_outside_the_room_is_refused(tmp_path: Path) -> None:
    # a mug 1e300 m away was accepted, then layout sampling overflowed (found by tests/fuzz)
    path = write_user_room(tmp_path / "room.usda")
    stage = Usd.Stage.Open(str(path))
    UsdGeom.Xformable(stage.GetPrimAtPath("/Room/Mug")).GetOrderedXformOps()[0].Set(
        Gf.Vec3d(1e300, 0, 0)
    )
    stage.GetRootLayer().Save()
    stage = open_stage(path)
    with pytest.raises(UsdError, match=r"/Room/Mug \(Mug\) stands at \(1e\+300, "):
        check_sizes(stage, path, measure_stage(stage, path), max_room=30, max_object=5)


def test_a_corrupted_byte_in_a_usda_is_one_line(tmp_path: Path) -> None:
    # pxr's message quotes the bad byte, and str() of it raised UnicodeDecodeError (tests/fuzz)
    path = write_user_room(tmp_path / "room.usda")
    data = path.read_bytes()
    path.write_bytes(data[:7] + bytes([data[7] ^ 0xFF]) + data[8:])
    with pytest.raises(UsdError, match="unreadable USD layer .its text is not valid UTF-8"):
        open_stage(path)
