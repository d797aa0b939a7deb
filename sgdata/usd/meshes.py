"""Plain triangle-mesh records passed from USD reading to rendering (no backend imports)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from sgdata.world.scene import transform_points

__all__ = ["Lighting", "MeshData", "ObjectGeometry", "SceneGeometry", "merge_meshes"]


@dataclass(frozen=True)
class MeshData:
    """A triangle mesh with one colour per face, and optionally textures on some faces.

    A textured face is drawn as its texture image (sRGB, sampled at the corners' ``uvs`` with
    repeat wrapping) times its face colour; the other faces as the colour alone.
    """

    vertices: np.ndarray  # (V, 3) float64
    faces: np.ndarray  # (F, 3) int32
    face_colors: np.ndarray  # (F, 3) float32, linear RGB in [0, 1]
    name: str = ""  # where it came from (a prim path), for messages
    uvs: np.ndarray | None = None  # (F, 3, 2) float32 texture coordinates of each corner
    face_texture: np.ndarray | None = None  # (F,) int32 index into textures, -1 untextured
    textures: tuple[str, ...] = ()  # texture image files (absolute paths) the faces use

    @property
    def textured(self) -> bool:
        """Whether any face carries a texture."""
        return self.face_texture is not None and bool((self.face_texture >= 0).any())


@dataclass(frozen=True)
class ObjectGeometry:
    """One object instance: its mesh in the local frame and its local-to-world transform."""

    instance: int
    class_name: str
    mesh: MeshData
    matrix: np.ndarray  # (4, 4) column-vector convention: world = matrix @ [x, y, z, 1]

    def world_vertices(self) -> np.ndarray:
        """The vertices moved into world space, shape (V, 3)."""
        return transform_points(self.matrix, self.mesh.vertices)


@dataclass(frozen=True)
class Lighting:
    """A stage's light: a scale of the renderer's default lights and their colour."""

    intensity: float = 1.0  # scale of the default light intensities
    temperature: float | None = None  # Kelvin; None: the default white light
    color: tuple[float, float, float] = (1.0, 1.0, 1.0)  # RGB multiplier of the temperature


@dataclass(frozen=True)
class SceneGeometry:
    """Everything a renderer needs from a composed stage."""

    structure: tuple[MeshData, ...]  # floor, walls, ceiling in world coordinates
    objects: tuple[ObjectGeometry, ...]
    lighting: Lighting = Lighting()
    door: MeshData | None = None  # the door opening, for the id pass only (render.structure)


def merge_meshes(meshes: Sequence[MeshData], name: str = "") -> MeshData:
    """Meshes concatenated into one (face indices offset, colours and textures kept per face;
    texture files in order of first use)."""
    if not meshes:
        empty = np.zeros((0, 3))
        return MeshData(empty, np.zeros((0, 3), np.int32), np.zeros((0, 3), np.float32), name)
    offsets = np.cumsum([0] + [len(m.vertices) for m in meshes[:-1]])
    merged = MeshData(
        np.concatenate([m.vertices for m in meshes]),
        np.concatenate([m.faces + k for m, k in zip(meshes, offsets, strict=True)]).astype(
            np.int32
        ),
        np.concatenate([m.face_colors for m in meshes]).astype(np.float32),
        name,
    )
    if not any(m.textured for m in meshes):
        return merged
    files: dict[str, int] = {}
    uvs, which = [], []
    for m in meshes:
        n = len(m.faces)
        if not m.textured:
            uvs.append(np.zeros((n, 3, 2), np.float32))
            which.append(np.full(n, -1, np.int32))
            continue
        codes = np.array([files.setdefault(f, len(files)) for f in m.textures], np.int32)
        index = np.asarray(m.face_texture)
        which.append(np.where(index >= 0, codes[np.maximum(index, 0)], -1).astype(np.int32))
        uvs.append(np.asarray(m.uvs, np.float32))
    return replace(
        merged,
        uvs=np.concatenate(uvs),
        face_texture=np.concatenate(which),
        textures=tuple(files),
    )
