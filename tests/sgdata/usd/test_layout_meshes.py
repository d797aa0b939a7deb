"""A room's meshes kept across its layouts (sgdata.usd.layout_meshes): reading a room's layouts
with one cache gives exactly the fresh reads, on generated layouts that move, re-colour and
re-bind objects, and on layouts edited by hand to override what a mesh reads from elsewhere."""

from __future__ import annotations

import dataclasses
import shutil
from pathlib import Path

import numpy as np
import pytest
from pxr import Gf, Sdf

from sgdata.scene_files import layout_file
from sgdata.usd.geometry import read_geometry
from sgdata.usd.layout_meshes import LayoutMeshes
from sgdata.usd.room_io import read_room, read_scene
from sgdata.usd.stage import open_layer, write_usd_file


def assert_same(a: object, b: object, where: str = "geometry") -> None:
    """Dataclasses, tuples and arrays equal to the last bit (and of the same dtype)."""
    if dataclasses.is_dataclass(a):
        assert type(a) is type(b), where
        for field in dataclasses.fields(a):
            assert_same(getattr(a, field.name), getattr(b, field.name), f"{where}.{field.name}")
    elif isinstance(a, tuple | list):
        assert isinstance(b, tuple | list) and len(a) == len(b), where
        for k, (x, y) in enumerate(zip(a, b, strict=True)):
            assert_same(x, y, f"{where}[{k}]")
    elif isinstance(a, np.ndarray):
        assert isinstance(b, np.ndarray) and a.dtype == b.dtype, where
        assert np.array_equal(a, b), where
    else:
        assert a == b, where


def room_dirs(root: Path) -> list[Path]:
    return sorted(p for p in (root / "scenes").iterdir() if p.is_dir() and p.name != "textures")


def test_one_cache_over_a_datasets_layouts_reads_what_fresh_reads_do(mini_dataset: Path) -> None:
    meshes = LayoutMeshes()  # one cache for every room: a new room starts it afresh
    layouts = 0
    for room_dir in room_dirs(mini_dataset):
        for path in sorted(room_dir.glob("layout_*.usda")):
            room, geometry = read_scene(path, meshes)
            assert_same(room, read_room(path), f"{path} room")
            assert_same(geometry, read_geometry(path), str(path))
            layouts += 1
    assert layouts >= 4
    # the layouts re-dress objects (textured, per-layout looks), and most prims are still kept
    assert meshes.reused > 0.5 * meshes.read


@pytest.fixture
def room_copy(mini_dataset: Path, tmp_path: Path) -> Path:
    """One room's scene folder (and the textures beside it), copied so a test may edit its
    layouts."""
    scenes = mini_dataset / "scenes"
    shutil.copytree(scenes / "textures", tmp_path / "textures")
    return Path(shutil.copytree(room_dirs(mini_dataset)[0], tmp_path / "room"))


def _first_binding(room_dir: Path) -> tuple[Sdf.Path, Sdf.Path]:
    """(a mesh prim bound to a room material, that material), from ``room.usda``."""
    layer = open_layer(room_dir / "room.usda")
    found: list[tuple[Sdf.Path, Sdf.Path]] = []

    def visit(path: Sdf.Path) -> None:
        if found or not path.IsPropertyPath() or path.name != "material:binding":
            return
        targets = layer.GetRelationshipAtPath(path).targetPathList.explicitItems
        if targets:
            found.append((path.GetPrimPath(), targets[0]))

    layer.Traverse(Sdf.Path.absoluteRootPath, visit)
    assert found, "room.usda binds no material"
    return found[0]


def _edit(path: Path, edit) -> None:  # noqa: ANN001
    """Apply ``edit(layer)`` to the layout layer at ``path`` and write it back."""
    layer = Sdf.Layer.CreateAnonymous(".usda")
    layer.TransferContent(open_layer(path))
    edit(layer)
    write_usd_file(path, layer.ExportToString())


def _read_all(room_dir: Path) -> None:
    """Each layout of the room read with one cache, checked against its fresh read."""
    meshes = LayoutMeshes()
    for k in range(len(list(room_dir.glob("layout_*.usda")))):
        path = layout_file(room_dir, k)
        _, geometry = read_scene(path, meshes)
        assert_same(geometry, read_geometry(path), str(path))


def test_a_layout_that_re_tints_a_room_material_is_read_afresh(room_copy: Path) -> None:
    _, material = _first_binding(room_copy)
    before = read_geometry(layout_file(room_copy, 1))

    def retint(layer: Sdf.Layer) -> None:
        spec = Sdf.CreatePrimInLayer(layer, material)
        tint = Sdf.AttributeSpec(spec, "inputs:tint", Sdf.ValueTypeNames.Float4)
        tint.default = Gf.Vec4f(0.1, 0.9, 0.2, 1.0)

    _edit(layout_file(room_copy, 1), retint)
    after = read_geometry(layout_file(room_copy, 1))
    changed = [
        a.name
        for a, b in zip(before.structure, after.structure, strict=True)
        if not np.array_equal(a.face_colors, b.face_colors)
    ] + [
        a.mesh.name
        for a, b in zip(before.objects, after.objects, strict=True)
        if not np.array_equal(a.mesh.face_colors, b.mesh.face_colors)
    ]
    assert changed, "the edit changed no colour: it tests nothing"
    _read_all(room_copy)


def test_a_layout_that_re_binds_an_ancestor_or_hides_a_mesh_is_read_afresh(
    room_copy: Path,
) -> None:
    mesh, material = _first_binding(room_copy)

    def rebind(layer: Sdf.Layer) -> None:
        # a binding on the mesh's parent, and the mesh's own colour replaced
        parent = Sdf.CreatePrimInLayer(layer, mesh.GetParentPath())
        rel = Sdf.RelationshipSpec(parent, "material:binding", False)
        rel.targetPathList.explicitItems = [material]
        spec = Sdf.CreatePrimInLayer(layer, mesh)
        color = Sdf.AttributeSpec(spec, "primvars:displayColor", Sdf.ValueTypeNames.Color3fArray)
        color.default = [Gf.Vec3f(0.0, 1.0, 0.0)]

    _edit(layout_file(room_copy, 1), rebind)

    def hide(layer: Sdf.Layer) -> None:
        spec = Sdf.CreatePrimInLayer(layer, mesh)
        visibility = Sdf.AttributeSpec(spec, "visibility", Sdf.ValueTypeNames.Token)
        visibility.default = "invisible"

    _edit(layout_file(room_copy, 0), hide)
    _read_all(room_copy)
    # the edits took: the first bound mesh of a room is its floor, hidden in layout 0 only
    shown = {m.name for m in read_geometry(layout_file(room_copy, 1)).structure}
    hidden = {m.name for m in read_geometry(layout_file(room_copy, 0)).structure}
    assert str(mesh) in shown - hidden


ROOM_WITH_A_REFERENCE = """#usda 1.0
(
    defaultPrim = "Room"
    metersPerUnit = 1
    upAxis = "Z"
)

def Xform "Room"
{
    def Mesh "Floor"
    {
        int[] faceVertexCounts = [4]
        int[] faceVertexIndices = [0, 1, 2, 3]
        point3f[] points = [(0, 0, 0), (4, 0, 0), (4, 4, 0), (0, 4, 0)]
    }

    def Scope "Protos"
    {
        def Xform "Box"
        {
            def Mesh "Geom"
            {
                int[] faceVertexCounts = [3, 3]
                int[] faceVertexIndices = [0, 1, 2, 0, 2, 3]
                point3f[] points = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)]
                color3f[] primvars:displayColor = [(0.8, 0.2, 0.2)] (
                    interpolation = "constant"
                )
            }
        }
    }

    def Xform "Objects"
    {
        def Xform "Box_1" (
            prepend references = </Room/Protos/Box>
        )
        {
            custom string sgdata:class = "Box"
            custom int sgdata:instance = 1
            double3 xformOp:translate = (2, 0, 0)
            uniform token[] xformOpOrder = ["xformOp:translate"]
        }
    }
}
"""


def _layout(path: Path, body: str = "") -> None:
    path.write_text(f"#usda 1.0\n(\n    subLayers = [@./room.usda@]\n)\n\n{body}")


def test_a_layout_that_overrides_what_an_object_references_is_read_afresh(tmp_path: Path) -> None:
    (tmp_path / "room.usda").write_text(ROOM_WITH_A_REFERENCE)
    _layout(tmp_path / "layout_0.usda")
    # the prototype the object references turns green: no spec at the object's own paths
    _layout(tmp_path / "layout_1.usda", """over "Room"
{
    over "Protos"
    {
        over "Box"
        {
            over "Geom"
            {
                color3f[] primvars:displayColor = [(0.1, 0.9, 0.1)]
            }
        }
    }
}
""")  # fmt: skip
    meshes = LayoutMeshes()
    first = read_geometry(tmp_path / "layout_0.usda", meshes)
    second = read_geometry(tmp_path / "layout_1.usda", meshes)
    assert_same(second, read_geometry(tmp_path / "layout_1.usda"))
    assert np.allclose(second.objects[0].mesh.face_colors, (0.1, 0.9, 0.1))
    assert np.allclose(first.objects[0].mesh.face_colors, (0.8, 0.2, 0.2))
    assert meshes.reused == 1  # the floor, taken from layout 0
