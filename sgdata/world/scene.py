"""The scene data model: rooms, object instances and their placements, free of any backend.

Conventions (DESIGN §3): Z up, metres, yaw in radians about +Z. An object's local frame has
its origin at the centre of the bottom face of its bounding box, +X along its width, +Y along
its depth pointing *backwards* (so the front faces local -Y), +Z up. A room spans
[0, width] x [0, depth] on the floor, with the floor at z = 0.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from enum import StrEnum
from functools import cached_property

import numpy as np

__all__ = [
    "Dynamics",
    "Placement",
    "SceneObject",
    "Opening",
    "Room",
    "WALLS",
    "box_corners",
    "transform_points",
]

# Walls by the side of the room they close; each names the axis-aligned line it lies on.
WALLS = ("south", "east", "north", "west")  # y = 0, x = width, y = depth, x = 0


class Dynamics(StrEnum):
    """How an object class may move between layouts (paper §V-A.3)."""

    STATIC = "static"  # structure and fixtures: never moves
    LOW = "low"  # moves locally, within r(B) of its spot, small yaw noise
    HIGH = "high"  # relocates anywhere it fits


@dataclass(frozen=True)
class Placement:
    """Where an object stands: world position of its local origin and its yaw."""

    x: float
    y: float
    z: float
    yaw: float = 0.0  # radians about +Z

    def matrix(self) -> np.ndarray:
        """The 4x4 local-to-world transform."""
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        m = np.eye(4)
        m[:2, :2] = [[c, -s], [s, c]]
        m[:3, 3] = [self.x, self.y, self.z]
        return m


@dataclass(frozen=True)
class SceneObject:
    """One object instance of a room.

    ``instance`` is a stable id, unique within the room and never reused across layouts.
    ``support`` is the instance the object rests on (AI2-THOR's parentReceptacle); ``None``
    means the floor or a wall. ``attached_to`` names the object a fixed part belongs to (a
    shelf board of a shelving unit, a sink basin of a sink): it moves with its parent but
    does not rest on it, so the relation heuristic may call it ``in`` rather than ``on``.
    """

    instance: int
    class_name: str
    dynamics: Dynamics
    size: tuple[float, float, float]  # width (x), depth (y), height (z) of the local box
    placement: Placement
    variant: int = 0  # which shape variant of the class recipe
    color: tuple[float, float, float] = (0.7, 0.7, 0.7)  # main colour, linear RGB in [0, 1]
    support: int | None = None
    attached_to: int | None = None

    @property
    def prim_name(self) -> str:
        """The USD prim name: class and zero-padded instance id, e.g. ``Mug_0042``."""
        return f"{self.class_name}_{self.instance:04d}"

    def moved_to(self, placement: Placement, support: int | None = None) -> SceneObject:
        """A copy at another placement (and support, when given)."""
        new_support = self.support if support is None else support
        return replace(self, placement=placement, support=new_support)

    def local_box(self) -> tuple[np.ndarray, np.ndarray]:
        """Min and max corners of the local bounding box."""
        w, d, h = self.size
        return np.array([-w / 2, -d / 2, 0.0]), np.array([w / 2, d / 2, h])

    def corners(self) -> np.ndarray:
        """The 8 world corners of the object's oriented bounding box, shape (8, 3), read-only."""
        return self._corners

    @cached_property
    def _corners(self) -> np.ndarray:
        # cached: placement checks ask for the corners of every object many times
        lo, hi = self.local_box()
        corners = box_corners(lo, hi, self.placement.matrix())
        corners.flags.writeable = False
        return corners

    def world_aabb(self) -> tuple[np.ndarray, np.ndarray]:
        """World axis-aligned box (min, max) around the oriented box."""
        c = self.corners()
        return c.min(axis=0), c.max(axis=0)


@dataclass(frozen=True)
class Opening:
    """A window or door gap in a wall: ``center`` is measured along the wall from its start."""

    wall: str  # one of WALLS
    center: float
    width: float
    bottom: float  # height of the sill (0 for a door)
    top: float


@dataclass(frozen=True)
class Room:
    """A room: its shell, its openings and the objects in it."""

    room_id: str  # e.g. "kitchen_003"
    room_type: str  # kitchen | living_room | bedroom | bathroom
    width: float  # x extent, metres
    depth: float  # y extent, metres
    height: float  # wall height, metres
    seed: int  # the seed this room was generated from
    door: Opening
    objects: tuple[SceneObject, ...] = field(default_factory=tuple)

    def by_instance(self) -> dict[int, SceneObject]:
        """Objects keyed by instance id."""
        return {o.instance: o for o in self.objects}

    def with_objects(self, objects: list[SceneObject] | tuple[SceneObject, ...]) -> Room:
        """A copy holding other objects (a layout of the same room)."""
        return replace(self, objects=tuple(objects))

    def wall_length(self, wall: str) -> float:
        """Length of a wall: rooms are rectangles."""
        return self.width if wall in ("south", "north") else self.depth


def transform_points(matrix: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Points (N, 3) moved by a 4x4 local-to-world transform (column-vector convention).

    The one home of this formula: meshes, boxes and footprints all move through it.
    """
    return np.asarray(points, dtype=np.float64) @ matrix[:3, :3].T + matrix[:3, 3]


def box_corners(lo: np.ndarray, hi: np.ndarray, matrix: np.ndarray) -> np.ndarray:
    """The 8 corners of the box [lo, hi] moved by a 4x4 transform, shape (8, 3)."""
    xs, ys, zs = (lo[0], hi[0]), (lo[1], hi[1]), (lo[2], hi[2])
    return transform_points(matrix, np.array([[x, y, z] for x in xs for y in ys for z in zs]))
