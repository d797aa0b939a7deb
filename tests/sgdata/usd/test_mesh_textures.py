"""Mesh files' own image textures: copied beside the room, bound in UsdShade on the file's UVs,
read back for the renderer, left alone by layout looks."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import trimesh
from PIL import Image
from pxr import Usd, UsdGeom, UsdShade

from sgdata.errors import UsdError
from sgdata.usd.geometry import read_geometry
from sgdata.usd.looks import read_room_parts
from sgdata.usd.room_io import catalog_geometry, write_room
from sgdata.world.appearance import AppearanceConfig
from sgdata.world.catalog import load_catalog
from sgdata.world.mesh_assets import class_assets
from sgdata.world.rooms import generate_room
from tests.asset_meshes import Y_UP, plate, write_demo_assets


@pytest.fixture(scope="module")
def demo(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("demo_assets")
    write_demo_assets(folder)
    # a textured GLB plate too: glTF baseColorTexture with a base colour factor
    mesh = plate()
    angle = np.arctan2(mesh.vertices[:, 1], mesh.vertices[:, 0]) / (2 * np.pi) % 1.0
    uv = np.stack([angle, mesh.vertices[:, 2] / 0.02], axis=1)
    pixels = np.zeros((4, 4, 3), np.uint8)
    pixels[:, :2] = (30, 160, 60)
    pixels[:, 2:] = (250, 250, 250)
    material = trimesh.visual.material.PBRMaterial(
        baseColorTexture=Image.fromarray(pixels), baseColorFactor=[255, 128, 255, 255]
    )
    mesh.visual = trimesh.visual.TextureVisuals(uv=uv, material=material)
    mesh.apply_transform(Y_UP)  # glTF is Y up by its specification
    (folder / "meshes" / "plate.stl").unlink()
    (folder / "meshes" / "plate.glb").write_bytes(mesh.export(file_type="glb"))
    text = (folder / "catalog.toml").read_text(encoding="utf-8")
    (folder / "catalog.toml").write_text(text.replace("plate*.stl", "plate*.glb"), "utf-8")
    return folder / "catalog.toml"


@pytest.fixture(scope="module")
def written(demo: Path, tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, object]:
    catalog = load_catalog(extra=[demo])
    room = generate_room("kitchen", 0, 0, catalog)
    path = tmp_path_factory.mktemp("scenes") / room.room_id / "room.usda"
    write_room(room, path, geometry=catalog_geometry(catalog), appearance=AppearanceConfig())
    return path, catalog


def _image_materials(stage: Usd.Stage) -> list[UsdShade.Material]:
    looks = stage.GetPrimAtPath("/Room/Looks")
    return [UsdShade.Material(p) for p in looks.GetChildren() if p.GetName().startswith("image_")]


def test_images_are_usdshade_textures_on_the_files_uvs(written: tuple) -> None:
    path, catalog = written
    stage = Usd.Stage.Open(str(path))
    materials = _image_materials(stage)
    assert len(materials) == 2  # the mug's checker (MTL map_Kd) and the plate's (glTF)
    for material in materials:
        texture = UsdShade.Shader(material.GetPrim().GetChild("Texture"))
        assert texture.GetShaderId() == "UsdUVTexture"
        asset = texture.GetInput("file").Get()
        assert asset.path.startswith("../textures/mesh_") and Path(asset.resolvedPath).is_file()
    plate_prim = next(
        p
        for p in stage.GetPrimAtPath("/Room/Objects").GetChildren()
        if p.GetName().startswith("Plate")
    )
    mesh = UsdGeom.Mesh(plate_prim.GetChild("Geom"))
    st = np.array(UsdGeom.PrimvarsAPI(mesh).GetPrimvar("st").ComputeFlattened())
    uvs = class_assets(catalog["Plate"])[0].face_uvs

    # every face is textured with the file's coordinates (faces grouped by part: sort them)
    def rows(a: np.ndarray) -> np.ndarray:
        flat = np.round(np.asarray(a, np.float64).reshape(-1, 6), 5)
        return flat[np.lexsort(flat.T[::-1])]

    assert rows(st) == pytest.approx(rows(uvs), abs=1e-5)


def test_the_renderer_reads_the_image_times_the_base_colour(written: tuple) -> None:
    path, _ = written
    geometry = read_geometry(path)
    plates = [o for o in geometry.objects if o.class_name == "Plate"]
    mugs = [o for o in geometry.objects if o.class_name == "Mug"]
    assert plates and mugs
    for obj in plates + mugs:
        mesh = obj.mesh
        assert mesh.textured and (mesh.face_texture >= 0).all()
        assert all(Path(f).name.startswith("mesh_") for f in mesh.textures)
    # the plate's faces: its texture times the glTF base colour factor
    assert plates[0].mesh.face_colors[0] == pytest.approx((1.0, 128 / 255, 1.0), abs=1e-3)


def test_layout_looks_leave_image_parts_alone(written: tuple) -> None:
    path, catalog = written
    parts = read_room_parts(path)
    plate = next(p for i, p in parts.objects.items() if str(p.prim.name).startswith("Plate"))
    assert set(plate.kinds) == {"image"} and not any(plate.body)


def test_flat_rooms_keep_the_sampled_colours(written: tuple, tmp_path: Path) -> None:
    _, catalog = written
    room = generate_room("kitchen", 0, 0, catalog)
    flat = tmp_path / "flat" / "room.usda"
    write_room(room, flat, geometry=catalog_geometry(catalog), appearance=None)
    stage = Usd.Stage.Open(str(flat))
    assert not stage.GetPrimAtPath("/Room/Looks")
    mug = next(
        p
        for p in stage.GetPrimAtPath("/Room/Objects").GetChildren()
        if p.GetName().startswith("Mug")
    )
    colors = UsdGeom.PrimvarsAPI(UsdGeom.Mesh(mug.GetChild("Geom"))).GetPrimvar("displayColor")
    values = np.round(np.array(colors.Get()) * 255).astype(int).tolist()
    assert sorted(values) == [[200, 40, 40], [240, 230, 220]]  # the checker's two colours


def test_a_missing_copied_texture_is_one_line(written: tuple, tmp_path: Path) -> None:
    import shutil

    path, _ = written
    copy = tmp_path / "scenes"
    shutil.copytree(path.parent.parent, copy)
    for image in (copy / "textures").glob("mesh_*.png"):
        image.unlink()
    with pytest.raises(UsdError) as info:
        read_geometry(copy / path.parent.name / "room.usda")
    assert "not found" in str(info.value) and "\n" not in str(info.value)
