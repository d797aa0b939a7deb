"""USD / USDZ files as mesh variants: points and faces with pxr, upAxis and metersPerUnit
honoured, textures (also inside a USDZ) carried, bad files refused in one line."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PIL import Image
from pxr import Gf, Sdf, Usd, UsdGeom, UsdShade, UsdUtils, Vt

from sgdata.errors import CatalogError
from sgdata.usd.mesh_files import register_usd_mesh_reader
from sgdata.world.catalog import load_catalog
from sgdata.world.mesh_assets import class_assets
from tests.asset_meshes import plate


@pytest.fixture(autouse=True)
def _reader() -> None:
    register_usd_mesh_reader()


def _write_plate(
    path: Path, *, up: str | None, meters: float | None, texture: str | None = None
) -> None:
    """A plate 0.24 m across as a USD mesh (in ``meters`` per unit, ``up`` axis), under a
    scaled Xform, optionally bound to a UsdPreviewSurface reading ``texture``."""
    mesh_data = plate()
    unit = meters or 1.0
    v = np.asarray(mesh_data.vertices) / unit / 2.0  # the Xform doubles it
    if up == "y":
        v = np.stack([v[:, 0], v[:, 2], -v[:, 1]], axis=1)
    stage = Usd.Stage.CreateNew(str(path))
    if up is not None:
        UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y if up == "y" else UsdGeom.Tokens.z)
    if meters is not None:
        UsdGeom.SetStageMetersPerUnit(stage, meters)
    root = UsdGeom.Xform.Define(stage, "/Plate")
    root.AddScaleOp().Set(Gf.Vec3f(2, 2, 2))
    stage.SetDefaultPrim(root.GetPrim())
    mesh = UsdGeom.Mesh.Define(stage, "/Plate/Geom")
    mesh.CreatePointsAttr(Vt.Vec3fArray.FromNumpy(v.astype(np.float32)))
    faces = np.asarray(mesh_data.faces, np.int32)
    mesh.CreateFaceVertexCountsAttr(Vt.IntArray.FromNumpy(np.full(len(faces), 3, np.int32)))
    mesh.CreateFaceVertexIndicesAttr(Vt.IntArray.FromNumpy(faces.ravel()))
    mesh.CreateDisplayColorPrimvar(UsdGeom.Tokens.constant).Set([Gf.Vec3f(0.2, 0.4, 0.6)])
    if texture is not None:
        st = UsdGeom.PrimvarsAPI(mesh).CreatePrimvar(
            "st", Sdf.ValueTypeNames.TexCoord2fArray, UsdGeom.Tokens.vertex
        )
        st.Set(Vt.Vec2fArray.FromNumpy((v[:, :2] * 0 + 0.25).astype(np.float32)))
        material = UsdShade.Material.Define(stage, "/Plate/Look")
        reader = UsdShade.Shader.Define(stage, "/Plate/Look/Reader")
        reader.CreateIdAttr("UsdPrimvarReader_float2")
        reader.CreateInput("varname", Sdf.ValueTypeNames.String).Set("st")
        image = UsdShade.Shader.Define(stage, "/Plate/Look/Texture")
        image.CreateIdAttr("UsdUVTexture")
        image.CreateInput("file", Sdf.ValueTypeNames.Asset).Set(texture)
        image.CreateInput("st", Sdf.ValueTypeNames.Float2).ConnectToSource(
            reader.CreateOutput("result", Sdf.ValueTypeNames.Float2)
        )
        surface = UsdShade.Shader.Define(stage, "/Plate/Look/Surface")
        surface.CreateIdAttr("UsdPreviewSurface")
        surface.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).ConnectToSource(
            image.CreateOutput("rgb", Sdf.ValueTypeNames.Float3)
        )
        material.CreateSurfaceOutput().ConnectToSource(
            surface.CreateOutput("surface", Sdf.ValueTypeNames.Token)
        )
        UsdShade.MaterialBindingAPI.Apply(mesh.GetPrim()).Bind(material)
    stage.GetRootLayer().Save()


def _plate_class(tmp_path: Path, name: str) -> object:
    path = tmp_path / "user.toml"
    path.write_text(f'[classes.Plate]\nmesh = "{name}"\n', encoding="utf-8")
    return load_catalog(extra=[path])["Plate"]


def test_authored_up_axis_and_units_are_honoured(tmp_path: Path) -> None:
    _write_plate(tmp_path / "plate.usda", up="y", meters=0.01)
    (asset,) = class_assets(_plate_class(tmp_path, "plate.usda"))
    assert (asset.up, asset.units) == ("y", "m")  # declared by the stage, not measured
    assert asset.size == pytest.approx((0.24, 0.24, 0.02), abs=1e-3)  # the Xform's scale too
    assert asset.face_colors == pytest.approx(np.tile([0.2, 0.4, 0.6], (asset.triangles, 1)))
    assert asset.footprint.shape == (48, 2)


def test_unauthored_units_are_measured(tmp_path: Path) -> None:
    _write_plate(tmp_path / "plate.usda", up="z", meters=None)  # metres, unsaid
    mm = tmp_path / "mm"
    mm.mkdir()
    _write_plate(mm / "plate.usda", up=None, meters=None)
    stage = Usd.Stage.Open(str(mm / "plate.usda"))
    xform = UsdGeom.Xformable(stage.GetPrimAtPath("/Plate"))
    xform.GetOrderedXformOps()[0].Set(Gf.Vec3f(2000, 2000, 2000))  # now in millimetres
    stage.GetRootLayer().Save()
    (metres,) = class_assets(_plate_class(tmp_path, "plate.usda"))
    (millimetres,) = class_assets(_plate_class(mm, "plate.usda"))
    assert metres.units == "m" and millimetres.units == "mm"
    assert millimetres.size == pytest.approx(metres.size, abs=1e-3)


def test_usdz_textures_are_read_from_the_package(tmp_path: Path) -> None:
    Image.fromarray(np.full((2, 2, 3), (10, 200, 30), np.uint8)).save(tmp_path / "green.png")
    _write_plate(tmp_path / "plate.usdc", up="z", meters=1.0, texture="green.png")
    assert UsdUtils.CreateNewUsdzPackage(
        Sdf.AssetPath(str(tmp_path / "plate.usdc")), str(tmp_path / "plate.usdz")
    )
    (tmp_path / "green.png").unlink()  # only the package's copy is left
    (asset,) = class_assets(_plate_class(tmp_path, "plate.usdz"))
    assert len(asset.images) == 1 and (asset.face_image == 0).all()
    assert asset.face_uvs == pytest.approx(np.full_like(asset.face_uvs, 0.25))
    assert np.round(asset.face_colors[0] * 255).tolist() == [10, 200, 30]


def test_a_texture_beside_the_stage_is_hashed(tmp_path: Path) -> None:
    Image.fromarray(np.full((2, 2, 3), 90, np.uint8)).save(tmp_path / "grey.png")
    _write_plate(tmp_path / "plate.usda", up="z", meters=1.0, texture="grey.png")
    (asset,) = class_assets(_plate_class(tmp_path, "plate.usda"))
    assert [Path(t).name for t in asset.textures] == ["grey.png"]
    assert len(asset.texture_sha256) == 1  # in the manifest, checked by validate --sources


def test_a_missing_texture_is_one_line(tmp_path: Path) -> None:
    _write_plate(tmp_path / "plate.usda", up="z", meters=1.0, texture="gone.png")
    with pytest.raises(CatalogError) as info:
        class_assets(_plate_class(tmp_path, "plate.usda"))
    message = str(info.value)
    assert "plate.usda" in message and "gone.png" in message and "\n" not in message


def test_an_empty_stage_is_one_line(tmp_path: Path) -> None:
    stage = Usd.Stage.CreateNew(str(tmp_path / "empty.usda"))
    UsdGeom.Xform.Define(stage, "/Nothing")
    stage.GetRootLayer().Save()
    with pytest.raises(CatalogError, match="holds no triangles"):
        class_assets(_plate_class(tmp_path, "empty.usda"))
