"""Surface: mesh files a user catalog names (``[catalog] files``), valid and broken, through
the catalog loader and the shape every stage draws (:mod:`sgdata.world.mesh_assets`).

Broken as users' files are: an empty mesh, NaN vertices, faces without area, a mesh in other
units (up to a kilometre), a missing texture, an unknown format, random bytes, a glob that
matches nothing, and wrong ``units`` / ``up`` / ``scale`` declarations; USD files (``.usda``,
read with pxr) broken the same ways.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import trimesh
from hypothesis import strategies as st

from sgdata.world.catalog import load_catalog
from sgdata.world.mesh_assets import class_assets, class_shape
from sgdata.world.shapes import merged_mesh

from ..asset_meshes import plate
from .harness import Surface

assets = st.fixed_dictionaries(
    {
        "format": st.sampled_from(["obj", "stl", "ply", "glb", "fbx", "obj", "usda"]),
        "scale": st.sampled_from([1.0, 100.0, 1000.0, 1e6, 1e-4, 0.5, 4.0]),
        "nan": st.sampled_from([0, 0, 0, 0, 1, 3]),
        "flat": st.sampled_from([0, 0, 0, 1, 2, 40]),  # faces collapsed to a point
        "empty": st.integers(0, 5).map(lambda k: k == 0),
        "texture": st.sampled_from(["none", "present", "missing"]),
        "garbage": st.one_of(st.none(), st.none(), st.none(), st.binary(max_size=48)),
        "glob_nothing": st.integers(0, 9).map(lambda k: k == 0),
        "units": st.sampled_from([None, None, None, "m", "cm", "mm", "km"]),
        "up": st.sampled_from([None, "y", "z"]),
        "policy": st.sampled_from([None, "keep", "fit"]),
        "sections": st.integers(3, 24),
    }
)


def _write(example: dict[str, Any], folder: Path) -> str:
    """The mesh file of ``example`` under ``folder``; returns its name."""
    folder.mkdir(parents=True, exist_ok=True)
    name = f"thing.{example['format']}"
    if example["garbage"] is not None:
        (folder / name).write_bytes(example["garbage"])
        return name
    mesh = plate(sections=example["sections"])
    vertices = np.array(mesh.vertices) * example["scale"]
    faces = np.array(mesh.faces)
    for k in range(min(example["nan"], len(vertices))):
        vertices[k * 7 % len(vertices)] = math.nan
    for k in range(min(example["flat"], len(faces))):
        faces[k] = faces[k, 0]
    if example["empty"]:
        faces = faces[:0]
    mesh = trimesh.Trimesh(vertices, faces, process=False)
    if example["format"] == "obj" and example["texture"] != "none":
        text = "mtllib thing.mtl\nusemtl a\n" + trimesh.exchange.obj.export_obj(
            mesh, include_texture=False
        )
        (folder / name).write_text(text, encoding="utf-8")
        (folder / "thing.mtl").write_text("newmtl a\nmap_Kd wood.png\n", encoding="utf-8")
        if example["texture"] == "present":
            from PIL import Image

            Image.new("RGB", (2, 2), (90, 60, 30)).save(folder / "wood.png")
        return name
    if example["format"] == "usda":
        _write_usd(folder / name, vertices, faces, example["up"])
        return name
    if example["format"] == "fbx":
        (folder / name).write_bytes(b"Kaydara FBX Binary  \x00")
        return name
    data = mesh.export(file_type=example["format"])
    (folder / name).write_bytes(data.encode() if isinstance(data, str) else data)
    return name


def _write_usd(path: Path, vertices: np.ndarray, faces: np.ndarray, up: str | None) -> None:
    """A USD stage holding one mesh (NaN points and empty faces as given)."""
    from pxr import Usd, UsdGeom, Vt

    stage = Usd.Stage.CreateInMemory()
    if up is not None:
        UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y if up == "y" else UsdGeom.Tokens.z)
    mesh = UsdGeom.Mesh.Define(stage, "/Thing")
    mesh.CreatePointsAttr(Vt.Vec3fArray.FromNumpy(np.asarray(vertices, np.float32)))
    mesh.CreateFaceVertexCountsAttr(Vt.IntArray.FromNumpy(np.full(len(faces), 3, np.int32)))
    mesh.CreateFaceVertexIndicesAttr(Vt.IntArray.FromNumpy(np.asarray(faces, np.int32).ravel()))
    path.write_text(stage.GetRootLayer().ExportToString(), encoding="utf-8")


def feed(example: dict[str, Any], work: Path, session: None) -> None:
    from sgdata.usd.mesh_files import register_usd_mesh_reader

    register_usd_mesh_reader()  # as the run's catalog does
    name = _write(example, work / "meshes")
    pattern = "meshes/none-*.obj" if example["glob_nothing"] else f"meshes/{name}"
    lines = ["[classes.Plate]", f'mesh = "{pattern}"']
    for key, value in (("units", example["units"]), ("up", example["up"])):
        if value is not None:
            lines.append(f'{key} = "{value}"')
    if example["policy"] is not None:
        lines.append(f'scale = "{example["policy"]}"')
    catalog = work / "catalog.toml"
    catalog.write_text("\n".join(lines) + "\n", encoding="utf-8")
    spec = load_catalog(extra=[catalog])["Plate"]
    (asset,) = class_assets(spec)
    size = np.array(asset.size)
    assert np.isfinite(asset.vertices).all(), "wrong result: non-finite vertices kept"
    low, high = np.array(spec.size_min), np.array(spec.size_max)
    assert (size >= low / 1.3 - 1e-6).all() and (size <= high * 1.3 + 1e-6).all(), (
        f"wrong result: size {size} outside the class's bounds {low} to {high}"
    )
    vertices, faces, colors = merged_mesh(class_shape(spec, asset.size, 0, (1.0, 0.0, 0.0)))
    assert len(faces) == len(colors) == asset.triangles, "wrong result: faces lost in the build"
    assert np.allclose(np.ptp(vertices, axis=0), size, atol=1e-3), (
        "wrong result: the built shape is not the measured size"
    )


SURFACE = Surface(name="mesh assets", inputs=assets, feed=feed, outputs=())
