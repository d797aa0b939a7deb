"""Plain triangle-mesh records passed from USD reading to rendering (no backend imports)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from sgdata.world.scene import transform_points

__all__ = ["MeshData", "ObjectGeometry", "SceneGeometry", "merge_meshes"]


@dataclass(frozen=True)
class MeshData:
    """A triangle mesh with one colour per face."""

    vertices: np.ndarray  # (V, 3) float64
    faces: np.ndarray  # (F, 3) int32
    face_colors: np.ndarray  # (F, 3) float32, linear RGB in [0, 1]
    name: str = ""  # where it came from (a prim path), for messages


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
class SceneGeometry:
    """Everything a renderer needs from a composed stage."""

    structure: tuple[MeshData, ...]  # floor, walls, ceiling in world coordinates
    objects: tuple[ObjectGeometry, ...]


def merge_meshes(meshes: Sequence[MeshData], name: str = "") -> MeshData:
    """Meshes concatenated into one (face indices offset, colours kept per face)."""
    if not meshes:
        empty = np.zeros((0, 3))
        return MeshData(empty, np.zeros((0, 3), np.int32), np.zeros((0, 3), np.float32), name)
    offsets = np.cumsum([0] + [len(m.vertices) for m in meshes[:-1]])
    return MeshData(
        np.concatenate([m.vertices for m in meshes]),
        np.concatenate([m.faces + k for m, k in zip(meshes, offsets, strict=True)]).astype(
            np.int32
        ),
        np.concatenate([m.face_colors for m in meshes]).astype(np.float32),
        name,
    )
