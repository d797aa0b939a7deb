"""Mesh files made with trimesh for the mesh-class tests, the demo and the fuzz surface.

One file per format, each in another unit and up axis, as users' files come:
``table.glb`` (glTF PBR materials, metres, Y up), ``mug.obj`` (+ MTL + PNG texture, centimetres,
Y up), ``bowl.ply`` (vertex colours, millimetres, Z up), ``plate.stl`` (no colour, metres, Z up).
Deterministic: the same call writes the same bytes.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import trimesh
from PIL import Image

__all__ = ["DEMO_CATALOG", "bowl", "mug", "plate", "table", "write_demo_assets"]

# The user catalog that turns four built-in classes into these files (paths relative to it).
DEMO_CATALOG = """\
# Demo: four kitchen classes made of mesh files instead of recipes (docs/rooms.md).
[classes.DiningTable]
mesh = "meshes/table*.glb"

[classes.Mug]
mesh = "meshes/mug*.obj"

[classes.Bowl]
mesh = "meshes/bowl*.ply"

[classes.Plate]
mesh = "meshes/plate*.stl"
"""

Y_UP = np.array([[1, 0, 0, 0], [0, 0, 1, 0], [0, -1, 0, 0], [0, 0, 0, 1]], float)  # z -> y


def _at(mesh: trimesh.Trimesh, x: float, y: float, z: float) -> trimesh.Trimesh:
    mesh.apply_translation((x, y, z))
    return mesh


def table(width: float = 1.2, depth: float = 0.8, height: float = 0.75) -> list[trimesh.Trimesh]:
    """A table (top and four legs), Z up, metres, bottom on z = 0."""
    top = _at(trimesh.creation.box((width, depth, 0.04)), 0, 0, height - 0.02)
    legs = [
        _at(
            trimesh.creation.box((0.05, 0.05, height - 0.04)),
            sx * (width / 2 - 0.06),
            sy * (depth / 2 - 0.06),
            (height - 0.04) / 2,
        )
        for sx in (-1, 1)
        for sy in (-1, 1)
    ]
    return [top, trimesh.util.concatenate(legs)]


def mug(radius: float = 0.04, height: float = 0.1, sections: int = 32) -> trimesh.Trimesh:
    """A mug: a wall, a bottom and a handle, Z up, metres."""
    wall = trimesh.creation.annulus(radius - 0.004, radius, height, sections=sections)
    wall.apply_translation((0, 0, height / 2))
    bottom = _at(trimesh.creation.cylinder(radius - 0.004, 0.008, sections=sections), 0, 0, 0.004)
    handle = _at(trimesh.creation.box((0.024, 0.012, 0.06)), radius + 0.012, 0, height / 2)
    return trimesh.util.concatenate([wall, bottom, handle])


def bowl(radius: float = 0.08, height: float = 0.06, sections: int = 48) -> trimesh.Trimesh:
    """An open bowl (a flat inner bottom, walls flaring out), Z up, metres."""
    t = 0.004
    profile = np.array(
        [
            [0.0, 0.0],
            [radius * 0.5, 0.0],
            [radius, height],
            [radius - t, height],
            [radius * 0.5 - t, t],
            [0.0, t],
        ]
    )
    return trimesh.creation.revolve(profile, sections=sections)


def plate(radius: float = 0.12, height: float = 0.02, sections: int = 48) -> trimesh.Trimesh:
    """A flat plate, Z up, metres."""
    return _at(trimesh.creation.cylinder(radius, height, sections=sections), 0, 0, height / 2)


def _checker(colors: tuple[tuple[int, int, int], tuple[int, int, int]]) -> Image.Image:
    pixels = np.zeros((8, 8, 3), np.uint8)
    for i in range(8):
        for j in range(8):
            pixels[i, j] = colors[(i + j) % 2]
    return Image.fromarray(pixels)


def write_demo_assets(folder: Path, *, catalog: bool = True) -> list[Path]:
    """Write the four demo meshes under ``folder/meshes`` (and ``folder/catalog.toml``)."""
    meshes = Path(folder) / "meshes"
    meshes.mkdir(parents=True, exist_ok=True)
    written = []
    # table.glb: glTF, Y up, metres, PBR base colours (wood top, dark legs)
    scene = trimesh.Scene()
    for name, part, rgba in zip(
        ("top", "legs"), table(), ([150, 100, 60, 255], [40, 40, 44, 255]), strict=True
    ):
        part = part.copy()
        part.apply_transform(Y_UP)
        material = trimesh.visual.material.PBRMaterial(baseColorFactor=rgba)
        part.visual = trimesh.visual.TextureVisuals(material=material)
        scene.add_geometry(part, geom_name=name)
    path = meshes / "table.glb"
    path.write_bytes(scene.export(file_type="glb"))
    written.append(path)
    # mug.obj: OBJ + MTL + a PNG texture, Y up, centimetres (UVs from the angle and height)
    part = mug()
    angle = (np.arctan2(part.vertices[:, 1], part.vertices[:, 0]) / (2 * np.pi)) % 1.0
    uv = np.stack([angle, part.vertices[:, 2] / 0.1], axis=1)
    image = _checker(((200, 40, 40), (240, 230, 220)))
    part.visual = trimesh.visual.TextureVisuals(uv=uv, image=image)
    part.apply_transform(Y_UP)
    part.apply_scale(100.0)
    files = trimesh.exchange.obj.export_obj(
        part, include_texture=True, return_texture=True, mtl_name="mug.mtl"
    )
    text, textures = files
    (meshes / "mug.obj").write_text(text, encoding="utf-8")
    for name, data in sorted(textures.items()):
        (meshes / name).write_bytes(data)
        written.append(meshes / name)
    written.append(meshes / "mug.obj")
    # bowl.ply: vertex colours, Z up, millimetres
    part = bowl()
    part.visual = trimesh.visual.ColorVisuals(part, vertex_colors=[60, 110, 170, 255])
    part.apply_scale(1000.0)
    path = meshes / "bowl.ply"
    path.write_bytes(part.export(file_type="ply"))
    written.append(path)
    # plate.stl: no colour, Z up, metres
    path = meshes / "plate.stl"
    path.write_bytes(plate().export(file_type="stl"))
    written.append(path)
    if catalog:
        path = Path(folder) / "catalog.toml"
        path.write_text(DEMO_CATALOG, encoding="utf-8")
        written.append(path)
    return sorted(written)
