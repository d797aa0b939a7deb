"""Pyrender primitives from mesh records: flat per-face colours, optionally textured.

Vertices are unshared per face (flat shading: each triangle its own normal and colour); a
textured primitive adds the faces' texture coordinates and samples one image, multiplied by
the face colours (pyrender multiplies ``COLOR_0`` into the lit colour, in linear RGB).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from typing import Any

import numpy as np

from sgdata.errors import RenderError
from sgdata.usd.meshes import MeshData, ObjectGeometry, merge_meshes

__all__ = [
    "face_order",
    "merged_world",
    "mesh_primitives",
    "primitive",
    "same_mesh",
    "same_shape",
    "subset",
    "texture",
]


def merged_world(objects: tuple[ObjectGeometry, ...]) -> MeshData:
    """All objects' meshes moved into world space and concatenated into one mesh (colours
    and textures kept per face)."""
    return merge_meshes([replace(o.mesh, vertices=o.world_vertices()) for o in objects])


def same_shape(a: MeshData, b: MeshData) -> bool:
    """Equal geometry (layouts read from USD carry fresh but equal arrays)."""
    if a is b:
        return True
    return np.array_equal(a.vertices, b.vertices) and np.array_equal(a.faces, b.faces)


def same_mesh(a: MeshData, b: MeshData) -> bool:
    """Equal geometry, colours and textures."""
    if a is b:
        return True
    return (
        same_shape(a, b)
        and np.array_equal(a.face_colors, b.face_colors)
        and a.textures == b.textures
        and _equal_or_none(a.face_texture, b.face_texture)
        and _equal_or_none(a.uvs, b.uvs)
    )


def _equal_or_none(a: np.ndarray | None, b: np.ndarray | None) -> bool:
    return (a is None and b is None) or (a is not None and b is not None and np.array_equal(a, b))


def subset(mesh: MeshData, pick: np.ndarray) -> MeshData:
    """The faces ``pick`` of a mesh (vertices kept, faces, colours and uvs selected)."""
    return replace(
        mesh,
        faces=np.asarray(mesh.faces)[pick],
        face_colors=np.asarray(mesh.face_colors)[pick],
        uvs=None if mesh.uvs is None else np.asarray(mesh.uvs)[pick],
        face_texture=None if mesh.face_texture is None else np.asarray(mesh.face_texture)[pick],
    )


def primitive(pr: Any, mesh: MeshData, *, double_sided: bool = False, texture: Any = None) -> Any:
    """A flat-shaded pyrender primitive with per-face colours (vertices unshared per face),
    sampling ``texture`` at the mesh's uvs when given."""
    v = np.asarray(mesh.vertices, dtype=np.float64)
    f = np.asarray(mesh.faces, dtype=np.int64)
    tri = v[f]  # (F, 3, 3)
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-12)
    colors = np.ones((len(f), 4), dtype=np.float32)
    colors[:, :3] = np.asarray(mesh.face_colors, dtype=np.float32)
    material = pr.MetallicRoughnessMaterial(
        baseColorFactor=[1.0, 1.0, 1.0, 1.0],
        baseColorTexture=texture,
        metallicFactor=0.0,
        roughnessFactor=0.9,
        doubleSided=double_sided,
    )
    uvs = None
    if texture is not None:
        uvs = np.asarray(mesh.uvs, dtype=np.float32).reshape(-1, 2)
    return pr.Primitive(
        positions=tri.reshape(-1, 3).astype(np.float32),
        normals=np.repeat(n, 3, axis=0).astype(np.float32),
        texcoord_0=uvs,
        color_0=np.repeat(colors, 3, axis=0),
        material=material,
    )


def face_order(mesh: MeshData, textured: bool) -> np.ndarray:
    """The order the RGB pass draws a mesh's faces in: untextured faces first, then those of
    each texture file in file order (one primitive each), each group in mesh order; all in
    mesh order when not ``textured``."""
    if not (textured and mesh.textured):
        return np.arange(len(mesh.faces))
    which = np.asarray(mesh.face_texture)
    return np.concatenate(
        [np.flatnonzero(which < 0)]
        + [np.flatnonzero(which == k) for k in range(len(mesh.textures))]
    )


def mesh_primitives(
    pr: Any,
    mesh: MeshData,
    texture_of: Callable[[str], Any] | None,
    *,
    double_sided: bool = False,
) -> list[Any]:
    """The RGB primitives of a mesh in :func:`face_order`: one for its untextured faces, one
    per texture file. ``texture_of`` maps a texture file to its pyrender texture; None draws
    every face in its flat colour."""
    if texture_of is None or not mesh.textured:
        return [primitive(pr, mesh, double_sided=double_sided)]
    which = np.asarray(mesh.face_texture)
    out = []
    for k in (-1, *range(len(mesh.textures))):
        pick = which < 0 if k < 0 else which == k
        if pick.any():
            texture = None if k < 0 else texture_of(mesh.textures[k])
            out.append(
                primitive(pr, subset(mesh, pick), double_sided=double_sided, texture=texture)
            )
    return out


def texture(pr: Any, path: str) -> Any:
    """The pyrender texture of an image file (decoded here; callers keep one per file)."""
    from PIL import Image

    try:
        with Image.open(path) as image:
            pixels = np.asarray(image.convert("RGB"), dtype=np.uint8)
    except OSError as exc:
        raise RenderError(f"{path}: cannot read texture image ({exc})") from None
    return pr.Texture(source=pixels, source_channels="RGB")
