"""Textured rooms on real USD stages: materials bound (ComputeBoundMaterial) with texture
files that resolve, st primvars, USD's validators clean, layouts that give moving objects new
looks and light while the structure and static objects keep theirs, and the geometry reader
handing all of it to the renderer."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from pxr import Sdf, Usd, UsdGeom, UsdShade

from sgdata.scene_files import layout_file, room_file
from sgdata.usd.geometry import read_geometry
from sgdata.usd.materials import PART_FAMILY
from sgdata.usd.prims import (
    LIGHT_INTENSITY,
    LIGHT_TEMPERATURE,
    LOOK_TINT,
    LOOK_VARIANT,
    LOOKS,
    OBJECTS,
    STRUCTURE,
)
from sgdata.usd.scene_dirs import write_layouts, write_rooms
from sgdata.usd.stage import open_stage, validate_stage
from sgdata.world.appearance import AppearanceConfig
from sgdata.world.catalog import Catalog

APPEARANCE = AppearanceConfig(texture_size=64, light_intensity=(0.7, 0.9))


@pytest.fixture(scope="module")
def textured_dir(tmp_path_factory: pytest.TempPathFactory, catalog: Catalog) -> Path:
    """A textured bathroom with three layouts that draw their appearance."""
    out = tmp_path_factory.mktemp("textured") / "scenes"
    write_rooms(out, "bathroom", count=1, seed=2, catalog=catalog, appearance=APPEARANCE)
    write_layouts(out / "bathroom_000", count=3, seed=0, catalog=catalog, appearance=APPEARANCE)
    return out / "bathroom_000"


def _texture_file(material: UsdShade.Material) -> Sdf.AssetPath:
    surface = material.ComputeSurfaceSource()[0]
    (source,), _ = surface.GetInput("diffuseColor").GetConnectedSources()
    texture = UsdShade.Shader(source.source.GetPrim())
    assert texture.GetShaderId() == "UsdUVTexture"
    return texture.GetInput("file").Get()


def _bound_meshes(stage: Usd.Stage) -> list[Usd.Prim]:
    """Every prim a material is bound to: structure meshes and object part subsets."""
    prims = [p for p in stage.GetPrimAtPath(STRUCTURE).GetChildren()]
    for obj in stage.GetPrimAtPath(OBJECTS).GetChildren():
        mesh = UsdGeom.Mesh(obj.GetChild("Geom"))
        prims += [s.GetPrim() for s in UsdGeom.Subset.GetGeomSubsets(mesh, familyName=PART_FAMILY)]
    return prims


def test_materials_are_bound_and_their_textures_resolve(textured_dir: Path) -> None:
    stage = open_stage(room_file(textured_dir))
    prims = _bound_meshes(stage)
    assert len(prims) > 20
    files = set()
    for prim in prims:
        material, _ = UsdShade.MaterialBindingAPI(prim).ComputeBoundMaterial()
        assert material, prim.GetPath()
        assert material.GetPath().HasPrefix(LOOKS)
        asset = _texture_file(material)
        assert asset.resolvedPath and Path(asset.resolvedPath).is_file(), asset
        files.add(Path(asset.resolvedPath).name)
    assert {"tiles", "plaster"} <= {name.split("_")[0] for name in files}
    assert (textured_dir.parent / "textures").is_dir()  # shared beside the room directories


def test_every_mesh_has_st_and_subsets_partition_its_faces(textured_dir: Path) -> None:
    stage = open_stage(room_file(textured_dir))
    for prim in stage.Traverse():
        if not prim.IsA(UsdGeom.Mesh):
            continue
        mesh = UsdGeom.Mesh(prim)
        st = UsdGeom.PrimvarsAPI(mesh).GetPrimvar("st")
        assert st and st.GetInterpolation() == UsdGeom.Tokens.faceVarying, prim.GetPath()
        n_faces = len(mesh.GetFaceVertexCountsAttr().Get())
        assert len(st.ComputeFlattened()) == 3 * n_faces
        subsets = UsdGeom.Subset.GetGeomSubsets(mesh, familyName=PART_FAMILY)
        if prim.GetPath().HasPrefix(OBJECTS):
            assert (
                subsets and UsdGeom.Subset.ValidateFamily(mesh, UsdGeom.Tokens.face, PART_FAMILY)[0]
            )
            colors = UsdGeom.PrimvarsAPI(mesh).GetPrimvar("displayColor")
            assert colors.IsIndexed() and len(colors.Get()) == len(subsets)


def test_room_and_layouts_pass_usd_validation(textured_dir: Path) -> None:
    for path in [room_file(textured_dir), *(layout_file(textured_dir, k) for k in range(3))]:
        assert validate_stage(path) == [], path


def test_layouts_relook_moving_objects_only_and_draw_their_light(textured_dir: Path) -> None:
    base = open_stage(room_file(textured_dir))
    layouts = [open_stage(layout_file(textured_dir, k)) for k in range(3)]
    lights = []
    for stage in layouts:
        root = stage.GetPrimAtPath("/Room")
        intensity = root.GetAttribute(LIGHT_INTENSITY).Get()
        kelvin = root.GetAttribute(LIGHT_TEMPERATURE).Get()
        assert 0.7 <= intensity <= 0.9 + 1e-6
        assert 4000 <= kelvin <= 6500
        lights.append((intensity, kelvin))
    assert len(set(lights)) == 3
    moved_look = 0
    for obj in base.GetPrimAtPath(OBJECTS).GetChildren():
        static = obj.GetAttribute("sgdata:dynamics").Get() == "static"
        bindings = []
        for stage in (base, *layouts):
            other = stage.GetPrimAtPath(obj.GetPath())
            subsets = UsdGeom.Subset.GetGeomSubsets(
                UsdGeom.Mesh(other.GetChild("Geom")), familyName=PART_FAMILY
            )
            bindings.append(
                tuple(
                    UsdShade.MaterialBindingAPI(s.GetPrim()).ComputeBoundMaterial()[0].GetPath()
                    for s in subsets
                )
            )
            if static:
                assert other.GetAttribute(LOOK_TINT).Get() == obj.GetAttribute(LOOK_TINT).Get()
        if static:
            assert len(set(bindings)) == 1, obj.GetPath()
        else:
            moved_look += len(set(bindings)) > 1
            assert layouts[1].GetPrimAtPath(obj.GetPath()).GetAttribute(LOOK_VARIANT).Get() >= 0
    assert moved_look > 0
    for name in ("Floor", "Walls", "Ceiling"):
        paths = {
            UsdShade.MaterialBindingAPI(s.GetPrimAtPath(STRUCTURE.AppendChild(name)))
            .ComputeBoundMaterial()[0]
            .GetPath()
            for s in (base, *layouts)
        }
        assert len(paths) == 1  # the structure keeps its look


def test_geometry_reader_hands_textures_uvs_and_light_to_the_renderer(textured_dir: Path) -> None:
    geometry = read_geometry(layout_file(textured_dir, 1))
    floor = next(m for m in geometry.structure if m.name.endswith("Floor"))
    assert floor.textured and floor.uvs is not None
    assert all(Path(f).is_file() for f in floor.textures)
    assert floor.uvs.shape == (len(floor.faces), 3, 2)
    # tiles repeat every 0.6 m: the floor's st spans its size divided by that
    span = np.ptp(floor.uvs[floor.face_texture >= 0].reshape(-1, 2), axis=0)
    assert span.max() > 2.0
    assert all(o.mesh.textured for o in geometry.objects)
    assert 0.7 <= geometry.lighting.intensity <= 0.9 + 1e-6
    assert geometry.lighting.temperature is not None
    assert geometry.lighting.color[0] == pytest.approx(1.0)


def test_a_room_without_appearance_stays_flat(tmp_path: Path, catalog: Catalog) -> None:
    write_rooms(tmp_path, "kitchen", count=1, seed=0, catalog=catalog)
    stage = open_stage(room_file(tmp_path / "kitchen_000"))
    assert not stage.GetPrimAtPath(LOOKS)
    assert not (tmp_path / "textures").exists()
    geometry = read_geometry(room_file(tmp_path / "kitchen_000"))
    assert not any(o.mesh.textured for o in geometry.objects)
    assert geometry.lighting.temperature is None and geometry.lighting.intensity == 1.0


def test_layouts_of_a_flat_room_change_only_the_light(tmp_path: Path, catalog: Catalog) -> None:
    """A room written without an appearance keeps its objects' looks; layouts light it."""
    write_rooms(tmp_path, "bathroom", count=1, seed=2, catalog=catalog)
    room_dir = tmp_path / "bathroom_000"
    write_layouts(room_dir, count=2, seed=0, catalog=catalog, appearance=APPEARANCE)
    base = read_geometry(room_file(room_dir))
    for k in range(2):
        assert validate_stage(layout_file(room_dir, k)) == []
        text = layout_file(room_dir, k).read_text()
        assert LOOK_TINT not in text and "displayColor" not in text
        geometry = read_geometry(layout_file(room_dir, k))
        assert 0.7 <= geometry.lighting.intensity <= 0.9 + 1e-6
        for a, b in zip(base.objects, geometry.objects, strict=True):
            assert np.array_equal(a.mesh.face_colors, b.mesh.face_colors)


def test_texture_files_are_written_once_and_shared(tmp_path: Path) -> None:
    from sgdata.usd.materials import write_texture_files

    first = write_texture_files(tmp_path, 32)
    stamps = [p.stat().st_mtime_ns for p in first]
    again = write_texture_files(tmp_path, 32)  # identical files are left alone
    assert again == first and [p.stat().st_mtime_ns for p in again] == stamps
    assert len({p.read_bytes() for p in first}) == len(first)
