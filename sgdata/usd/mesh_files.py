"""USD / USDZ files as catalog mesh variants: every drawn mesh of the stage, read with pxr.

:func:`read_usd_mesh` returns the file's meshes as one :class:`~sgdata.world.mesh_files.RawMesh`
in the stage's own axes and units (transforms applied), its display colours, and the image
textures its bound ``UsdPreviewSurface`` materials name (read from inside a USDZ package too).
An authored ``upAxis`` and ``metersPerUnit`` are declared with it, so they are honoured rather
than measured; what a stage leaves unauthored is measured like any mesh file. The scene model
imports no USD: :func:`register_usd_mesh_reader` hands the reader to
:mod:`sgdata.world.mesh_files` (the pipeline's catalog and the CLI call it).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from pxr import Ar, Usd, UsdGeom

from sgdata.errors import CatalogError, UsdError
from sgdata.usd.bound_materials import MaterialReader
from sgdata.usd.geometry import prim_triangles
from sgdata.usd.object_prims import drawn_prims
from sgdata.usd.stage import open_stage
from sgdata.world.mesh_files import MeshImage, RawMesh, image_png, register_mesh_reader, sample
from sgdata.world.scene import transform_points

__all__ = ["USD_SUFFIXES", "read_usd_mesh", "register_usd_mesh_reader"]

USD_SUFFIXES = (".usd", ".usda", ".usdc", ".usdz")


def register_usd_mesh_reader() -> None:
    """Let catalog classes name USD / USDZ files (idempotent)."""
    register_mesh_reader(USD_SUFFIXES, read_usd_mesh)


def read_usd_mesh(file: Path) -> RawMesh:
    """The drawn meshes (and tessellated gprims) of a USD file in stage coordinates.

    Raises:
        CatalogError: the file does not open or compose, a mesh is malformed, a bound texture
            is missing, or the stage holds no triangles (one line naming the file).
    """
    try:
        stage = open_stage(file)
        return _read(stage, file)
    except UsdError as exc:
        reason = str(exc).removeprefix(f"{file}: ")
        raise CatalogError(f"{file}: cannot read the mesh ({reason})") from None


def _read(stage: Usd.Stage, file: Path) -> RawMesh:
    cache = UsdGeom.XformCache(Usd.TimeCode.Default())
    materials = MaterialReader()
    images: dict[str, MeshImage] = {}
    pixels: dict[str, np.ndarray] = {}
    vertices, faces, colors, base, uvs, which = [], [], [], [], [], []
    offset = 0
    for prim in drawn_prims(stage):
        found = prim_triangles(prim, materials)
        if found is None or not len(found.faces):
            continue
        matrix = np.array(cache.GetLocalToWorldTransform(prim), np.float64).T
        vertices.append(transform_points(matrix, found.vertices))
        faces.append(np.asarray(found.faces, np.int64) + offset)
        offset += len(found.vertices)
        n = len(found.faces)
        flat = np.asarray(found.face_colors, np.float32).copy()
        base.append(flat.copy())
        face_uv = np.zeros((n, 3, 2), np.float32)
        face_image = np.full(n, -1, np.int32)
        if found.textured:
            index = np.asarray(found.face_texture)
            for k, path in enumerate(found.textures):
                if path not in pixels:
                    pixels[path] = _image(file, path)
                    images.setdefault(path, image_png(pixels[path]))
                pick = index == k
                face_uv[pick] = np.asarray(found.uvs, np.float32)[pick]
                face_image[pick] = list(images).index(path)
                flat[pick] *= sample(pixels[path].astype(np.float32) / 255.0, face_uv[pick])
        colors.append(flat)
        uvs.append(face_uv)
        which.append(face_image)
    if not faces:
        raise CatalogError(f"{file}: the file holds no triangles (an empty mesh); re-export it")
    up = None
    if stage.HasAuthoredMetadata("upAxis"):
        up = "y" if UsdGeom.GetStageUpAxis(stage) == UsdGeom.Tokens.y else "z"
    meters = None
    if UsdGeom.StageHasAuthoredMetersPerUnit(stage):
        meters = float(UsdGeom.GetStageMetersPerUnit(stage))
        if not (np.isfinite(meters) and meters > 0):
            raise CatalogError(f"{file}: metersPerUnit is {meters:g}; expected a positive number")
    return RawMesh(
        vertices=np.concatenate(vertices),
        faces=np.concatenate(faces),
        colors=np.concatenate(colors),
        base=np.concatenate(base),
        uvs=np.concatenate(uvs),
        face_image=np.concatenate(which),
        images=tuple(images.values()),
        up=up,
        meters_per_unit=meters,
        # files on disk (not inside a USDZ package, whose sha256 covers them)
        texture_paths=tuple(sorted(str(Path(p).resolve()) for p in pixels if "[" not in p)),
    )


def _image(file: Path, resolved: str) -> np.ndarray:
    """The RGB pixels of a texture (a file, or an entry of a USDZ package)."""
    import io

    from PIL import Image, UnidentifiedImageError

    asset = Ar.GetResolver().OpenAsset(Ar.ResolvedPath(resolved))
    if asset is None:
        raise CatalogError(f"{file}: texture {resolved!r} cannot be read; restore it")
    try:
        data = bytes(memoryview(asset.GetBuffer()))
        return np.asarray(Image.open(io.BytesIO(data)).convert("RGB"), np.uint8)
    except (OSError, UnidentifiedImageError, ValueError) as exc:
        raise CatalogError(f"{file}: texture {resolved!r} does not decode ({exc})") from None
