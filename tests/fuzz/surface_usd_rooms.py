"""Surface: USD rooms people author by hand, as random mutations of a valid room.

Attributes removed or retyped; values NaN, inf, negative or huge; supports aimed at missing
prims or at each other; empty meshes and faces of fewer than three corners; Xforms with a zero
scale; a wrong up axis or units. Each room goes through what ``sgdata generate`` does with a
``[rooms] files`` entry: the check before anything is written, then (when accepted) the scene
step: the stage copied and tagged, layouts sampled, each layout's pose grid.
"""

from __future__ import annotations

import contextlib
import math
from pathlib import Path
from typing import Any

from hypothesis import strategies as st
from pxr import Gf, Sdf, Tf, Usd, UsdGeom

from sgdata.pipeline.config import GenerateConfig, LayoutsConfig, RoomFile, RoomsConfig
from sgdata.pipeline.room_tasks import RoomTask, write_room_scenes
from sgdata.pipeline.user_rooms import resolve_user_rooms

from ..sgdata.usd.user_stages import write_user_room
from .harness import Surface
from .mutations import NASTY_NUMBERS

BAD_NUMBERS = st.sampled_from(NASTY_NUMBERS) | st.floats(allow_nan=True, allow_infinity=True)
TYPES = ("String", "Int", "Float", "Double3", "Token", "Bool", "Float3[]", "Int[]")
KINDS = (
    "remove", "retype", "number", "point", "index", "counts", "dangling", "cycle", "empty",
    "scale", "up", "units", "no room",
)  # fmt: skip

mutation = st.tuples(
    st.sampled_from(KINDS), st.integers(0, 1000), st.integers(0, 1000), BAD_NUMBERS,
    st.sampled_from(TYPES),
)  # fmt: skip
rooms = st.fixed_dictionaries(
    {
        "up": st.sampled_from(["Z", "Y"]),
        "mpu": st.sampled_from([1.0, 0.01]),
        "gprims": st.booleans(),
        "nested": st.booleans(),
        "mutations": st.lists(mutation, min_size=0, max_size=3),
    }
)


def _pick(items: list, k: int) -> Any:
    return items[k % len(items)] if items else None


def _sample_value(type_name: str, number: float) -> Any:
    return {
        "String": str(number), "Int": 7, "Float": number, "Double3": Gf.Vec3d(number, 1, 1),
        "Token": "high", "Bool": True, "Float3[]": [Gf.Vec3f(number, 0, 0)], "Int[]": [0, 1, 99],
    }[type_name]  # fmt: skip


def mutate(stage: Usd.Stage, kind: str, a: int, b: int, number: float, type_name: str) -> None:
    """Apply one mistake to the stage (``a``, ``b`` pick the prim and the attribute)."""
    prims = [p for p in stage.Traverse()]
    objects = [p for p in prims if p.HasAttribute("sgdata:class")]
    meshes = [UsdGeom.Mesh(p) for p in prims if p.IsA(UsdGeom.Mesh)]
    prim = _pick(prims, a)
    attrs = [x for x in prim.GetAttributes() if x.IsAuthored()] if prim else []
    if kind == "remove" and attrs:
        prim.RemoveProperty(_pick(attrs, b).GetName())
    elif kind == "retype" and attrs:  # a wrong typeName in the .usda text
        name = _pick(attrs, b).GetName()
        spec = stage.GetRootLayer().GetPrimAtPath(prim.GetPath())
        if spec is None or name not in spec.attributes:
            return
        spec.RemoveProperty(spec.attributes[name])
        value_type = getattr(Sdf.ValueTypeNames, type_name.replace("[]", "Array"))
        Sdf.AttributeSpec(spec, name, value_type).default = _sample_value(type_name, number)
    elif kind == "number":
        numeric = [x for x in attrs if x.GetTypeName().scalarType.type.pythonClass in (float, int)]
        numeric += [x for x in attrs if x.GetTypeName() in ("double3", "float3", "point3f[]")]
        attr = _pick(numeric, b)
        if attr is None:
            return
        value = attr.Get()
        if hasattr(value, "__len__") and len(value):
            items = list(value)
            if hasattr(items[0], "__len__"):
                items[b % len(items)] = type(items[0])(*(number,) * len(items[0]))
                attr.Set(items)
            else:
                attr.Set(type(value)(*(number,) * len(items)))
        elif isinstance(value, int) and not math.isfinite(number):
            attr.Set(-1)
        elif isinstance(value, int):
            attr.Set(int(max(min(number, 2**31 - 1), -(2**31))))
        else:
            attr.Set(number)
    elif kind == "point" and meshes:
        mesh = _pick(meshes, a)
        points = list(mesh.GetPointsAttr().Get() or [])
        if points:
            points[b % len(points)] = Gf.Vec3f(number, number, number)
            mesh.GetPointsAttr().Set(points)
    elif kind == "index" and meshes:
        mesh = _pick(meshes, a)
        indices = list(mesh.GetFaceVertexIndicesAttr().Get() or [])
        if indices:
            indices[b % len(indices)] = (
                int(max(min(number, 2**31 - 1), -(2**31))) if math.isfinite(number) else 9999
            )
            mesh.GetFaceVertexIndicesAttr().Set(indices)
    elif kind == "counts" and meshes:  # faces of 0, 1 or 2 corners (not triangulable)
        mesh = _pick(meshes, a)
        counts = list(mesh.GetFaceVertexCountsAttr().Get() or [])
        if counts:
            k = b % len(counts)
            spare = counts[k] - b % 3
            counts[k : k + 1] = [b % 3] + ([spare] if spare > 0 else [])
            mesh.GetFaceVertexCountsAttr().Set(counts)
    elif kind == "dangling" and objects:
        _pick(objects, a).CreateRelationship("sgdata:support").SetTargets(["/Room/Nope"])
    elif kind == "cycle" and len(objects) > 1:
        one, two = _pick(objects, a), _pick(objects, a + 1)
        one.CreateRelationship("sgdata:support").SetTargets([two.GetPath()])
        two.CreateRelationship("sgdata:support").SetTargets([one.GetPath()])
    elif kind == "empty" and meshes:
        mesh = _pick(meshes, a)
        for attr in (
            mesh.GetPointsAttr(),
            mesh.GetFaceVertexCountsAttr(),
            mesh.GetFaceVertexIndicesAttr(),
        ):
            attr.Set([])
    elif kind == "scale" and prims:
        xformables = [p for p in prims if p.IsA(UsdGeom.Xformable)]
        target = UsdGeom.Xformable(_pick(xformables, a))
        scale = [1.0, 1.0, 1.0]
        scale[b % 3] = 0.0 if b % 2 else number
        target.AddScaleOp(opSuffix=f"fuzz{len(target.GetOrderedXformOps())}").Set(Gf.Vec3f(*scale))
    elif kind == "up":
        stage.SetMetadata("upAxis", _pick(["X", "Y", "Z", "up", ""], b))
    elif kind == "units":
        stage.SetMetadata("metersPerUnit", number)
    elif kind == "no room":
        stage.GetRootLayer().defaultPrim = ""
        room = stage.GetPrimAtPath("/Room")
        if room.IsValid():
            stage.RemovePrim("/Room") if b % 2 else room.SetActive(False)


def feed(example: dict, work: Path, session: None) -> None:
    path = work / "room.usda"
    write_user_room(
        path,
        up=example["up"],
        mpu=example["mpu"],
        gprims=example["gprims"],
        nested=example["nested"],
    )
    stage = Usd.Stage.Open(str(path))
    for kind, a, b, number, type_name in example["mutations"]:
        with contextlib.suppress(Tf.ErrorException):  # a mistake USD itself will not author
            mutate(stage, kind, a, b, number, type_name)
    stage.GetRootLayer().Save()
    rooms = RoomsConfig(files=(RoomFile("room.usda", id="r"),), base_dir=str(work))
    config = GenerateConfig(rooms=rooms, layouts=LayoutsConfig(count=2))
    config = resolve_user_rooms(config)  # the check before anything is written
    try:
        write_room_scenes(RoomTask("custom", 0, "train", name="r"), config, work / "out")
    except Exception as exc:  # noqa: BLE001 - past the check, any refusal is a defect
        raise AssertionError(
            f"accepted by the check, then failed: {type(exc).__name__}: {exc}"
        ) from None


SURFACE = Surface(name="USD rooms", inputs=rooms, feed=feed, outputs=("out",))
