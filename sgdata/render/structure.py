"""The room's structure as parts: which of wall, floor, ceiling or door a structure pixel shows.

The id pass draws each structure face with the code of its part
(:class:`~sgdata.render.renderer.Renderer`), so a view's structure mask comes from the same
draw as its instance mask. A face's part is read from its geometry, so it holds for rooms
authored elsewhere too:

- **floor**: up-facing faces in the up-facing plane of largest area (the lowest, on a tie:
  a slab's top and the ceiling slab's top have the same area);
- **ceiling**: down-facing faces in the down-facing plane of largest area above the floor
  (the underside of a door's lintel is not the ceiling);
- **wall**: every other structure face.

The **door** is what is seen through the room's door opening where nothing else is: the
scene's :attr:`~sgdata.usd.meshes.SceneGeometry.door` rectangle
(:func:`sgdata.usd.room_io.door_quad`), drawn by the id pass only. Windows are objects of the
catalog (class ``Window``) and keep their instance.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from sgdata.room_parts import CEILING, FLOOR, WALL
from sgdata.usd.meshes import MeshData

__all__ = ["face_parts"]

_FACING = 0.9  # |cos| of a face normal to +Z above which a face is horizontal
_PLANE = 0.01  # metres: faces whose heights differ by less lie in one plane


def face_parts(structure: Sequence[MeshData]) -> list[np.ndarray]:
    """The part (:data:`WALL`, :data:`FLOOR` or :data:`CEILING`) of every face of each
    structure mesh, as uint8 arrays in the meshes' order."""
    tris = [np.asarray(m.vertices, np.float64)[np.asarray(m.faces, np.int64)] for m in structure]
    every = np.concatenate(tris) if tris else np.zeros((0, 3, 3))
    cross = np.cross(every[:, 1] - every[:, 0], every[:, 2] - every[:, 0])
    area = np.linalg.norm(cross, axis=1)
    cos_z = np.divide(cross[:, 2], area, out=np.zeros(len(area)), where=area > 0)
    height = every[:, :, 2].mean(axis=1)
    up, down = cos_z > _FACING, cos_z < -_FACING
    floor_z = _largest_plane(height[up], area[up])
    floor = up & (np.abs(height - floor_z) < _PLANE)
    above = down & (height > floor_z + _PLANE)
    ceiling_z = _largest_plane(height[above], area[above])
    ceiling = above & (np.abs(height - ceiling_z) < _PLANE)
    parts = np.full(len(every), WALL, np.uint8)
    parts[floor], parts[ceiling] = FLOOR, CEILING
    return np.split(parts, np.cumsum([len(t) for t in tris])[:-1]) if tris else []


def _largest_plane(heights: np.ndarray, areas: np.ndarray) -> float:
    """The height of the plane (faces within :data:`_PLANE`) of largest total area, the
    lowest of those within 0.1 % of it; -inf when there are no faces."""
    if not len(heights):
        return -np.inf
    levels = np.round(heights / _PLANE).astype(np.int64)
    keys, index = np.unique(levels, return_inverse=True)
    totals = np.bincount(index, weights=areas)
    best = np.flatnonzero(totals >= totals.max() * 0.999)[0]  # keys are sorted: the lowest
    return float(heights[index == best].mean())
