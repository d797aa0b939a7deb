"""Pyrender primitives from mesh records: flat per-face colours, optionally textured.

Vertices are unshared per face (flat shading: each triangle its own normal and colour); a
textured primitive adds the faces' texture coordinates and samples one image, multiplied by
the face colours (pyrender multiplies ``COLOR_0`` into the lit colour, in linear RGB).
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np

from sgdata.usd.meshes import MeshData, ObjectGeometry, merge_meshes

__all__ = ["merged_world", "primitive", "same_mesh", "same_shape", "subset", "untextured"]


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


def untextured(mesh: MeshData) -> MeshData:
    """The mesh without its textures (the id pass needs shapes only)."""
    return replace(mesh, uvs=None, face_texture=None, textures=())


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
