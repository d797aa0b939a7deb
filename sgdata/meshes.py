"""Plain triangle-mesh records passed from USD reading to rendering (no backend imports)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["MeshData", "ObjectGeometry", "SceneGeometry"]


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
        return self.mesh.vertices @ self.matrix[:3, :3].T + self.matrix[:3, 3]


@dataclass(frozen=True)
class SceneGeometry:
    """Everything a renderer needs from a composed stage."""

    structure: tuple[MeshData, ...]  # floor, walls, ceiling in world coordinates
    objects: tuple[ObjectGeometry, ...]
