"""The reachable pose grid of one layout: free floor cells an agent of radius r can reach.

Grid convention: cells of size d tile the room's floor, ``nx = floor(width / d)`` along x
(index i) and ``ny = floor(depth / d)`` along y (index j), centred in the room: the leftover
strip (< d) is split evenly between opposite walls, so ``origin = ((width - nx d) / 2,
(depth - ny d) / 2)`` and cell (i, j) has its centre at ``origin + ((i + 0.5) d, (j + 0.5) d)``,
always inside the room. Masks are indexed ``[i, j]`` (shape (nx, ny)).

A cell is free when a disk of radius r around its centre lies inside the walls and clear of
the floor footprint (oriented rectangle) of every floor-standing object: an object whose
bottom is at the floor (``placement.z < 0.05``) and that neither rests on (``support``) nor is
fixed to (``attached_to``) another object. Windows and paintings hang higher; small objects
rest on furniture whose footprint already blocks.

Reachable cells are the 4-connected component of free cells an agent entering by the door
reaches: the component holding the free cell nearest the door's centre, when that cell is
within ``door_reach`` of it; otherwise (the door is blocked) the largest component.

Headings are indices 0..3 for 0, 90, 180, 270 degrees; heading 0 looks along +X, 90 along +Y.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from sgdata.errors import ConfigError
from sgdata.world.scene import Room

__all__ = ["HEADINGS_DEG", "PoseGrid", "PosesConfig", "pose_grid"]

HEADINGS_DEG = (0, 90, 180, 270)
_FLOOR_Z = 0.05  # bottoms below this stand on the floor


@dataclass(frozen=True)
class PosesConfig:
    """The reachable pose grid of a run: one home for the cell size and the robot radius."""

    cell: float = 0.25  # grid cell d (m), paper §V-A
    robot_radius: float = 0.2  # robot footprint radius (m)
    noise: bool = False  # the authors' pose noise (x, y ~ N(0, d/12), theta ~ N(0, 3 deg))

    def __post_init__(self) -> None:
        if not 0.05 <= self.cell <= 2.0:
            raise ConfigError(f"poses.cell must be within [0.05, 2] m, got {self.cell}")
        if not 0.0 <= self.robot_radius < 1.0:
            raise ConfigError(
                f"poses.robot_radius must be within [0, 1) m, got {self.robot_radius}"
            )

    def grid(self, room: Room) -> PoseGrid:
        """The reachable pose grid of ``room`` on this run's cells."""
        return pose_grid(room, cell=self.cell, radius=self.robot_radius)


@dataclass(frozen=True)
class PoseGrid:
    """Free and reachable cells of one layout."""

    cell: float  # d, metres
    radius: float  # robot radius r, metres
    origin: tuple[float, float]  # world (x, y) of the grid's lower-left corner
    free: np.ndarray  # (nx, ny) bool
    reachable: np.ndarray  # (nx, ny) bool, a subset of free
    cells: tuple[tuple[int, int], ...]  # reachable (i, j), sorted

    @property
    def shape(self) -> tuple[int, int]:
        """(nx, ny)."""
        return (int(self.free.shape[0]), int(self.free.shape[1]))

    def center(self, i: int, j: int) -> tuple[float, float]:
        """World (x, y) of the centre of cell (i, j)."""
        return (self.origin[0] + (i + 0.5) * self.cell, self.origin[1] + (j + 0.5) * self.cell)

    def pose_world(
        self, i: int, j: int, heading: int, *, rng: np.random.Generator | None = None
    ) -> tuple[float, float, float]:
        """(x, y, theta) of the pose at cell (i, j) and heading index 0..3 (theta in rad).

        With ``rng``, adds the authors' pose noise: x, y ~ N(0, d/12), theta ~ N(0, 3 deg),
        each clipped at 3 sigma (so a noisy pose stays inside its cell).
        """
        if not 0 <= heading < len(HEADINGS_DEG):
            raise ConfigError(f"heading index {heading}: expected 0..3 (0/90/180/270 degrees)")
        x, y = self.center(i, j)
        theta = math.radians(HEADINGS_DEG[heading])
        if rng is not None:
            sxy, sth = self.cell / 12.0, math.radians(3.0)
            dx, dy = np.clip(rng.normal(0.0, sxy, 2), -3 * sxy, 3 * sxy)
            dth = float(np.clip(rng.normal(0.0, sth), -3 * sth, 3 * sth))
            x, y, theta = x + float(dx), y + float(dy), theta + dth
        return (x, y, theta)


def pose_grid(
    room: Room,
    *,
    cell: float = PosesConfig.cell,
    radius: float = PosesConfig.robot_radius,
    door_reach: float = 1.0,
) -> PoseGrid:
    """The reachable pose grid of a layout (see the module docstring for conventions).

    Args:
        room: the layout (room shell, door and objects).
        cell: grid cell size d (m).
        radius: robot radius r (m).
        door_reach: how far from the door's centre the entry cell may be (m).
    """
    if cell <= 0 or radius < 0:
        raise ConfigError(f"pose grid cell={cell}, radius={radius}: need cell > 0, radius >= 0")
    nx, ny = int(room.width // cell), int(room.depth // cell)
    origin = ((room.width - nx * cell) / 2.0, (room.depth - ny * cell) / 2.0)
    xs = origin[0] + (np.arange(nx) + 0.5) * cell
    ys = origin[1] + (np.arange(ny) + 0.5) * cell
    px, py = np.meshgrid(xs, ys, indexing="ij")
    free = (px >= radius) & (px <= room.width - radius)
    free &= (py >= radius) & (py <= room.depth - radius)
    for obj in room.objects:
        if obj.placement.z >= _FLOOR_Z or obj.support is not None or obj.attached_to is not None:
            continue
        p = obj.placement
        c, s = math.cos(p.yaw), math.sin(p.yaw)
        lx = c * (px - p.x) + s * (py - p.y)  # cell centres in the object's frame
        ly = -s * (px - p.x) + c * (py - p.y)
        ox = np.maximum(np.abs(lx) - obj.size[0] / 2, 0.0)
        oy = np.maximum(np.abs(ly) - obj.size[1] / 2, 0.0)
        free &= ox * ox + oy * oy > radius * radius
    reachable = _entry_component(room, free, px, py, door_reach)
    cells = tuple((int(i), int(j)) for i, j in zip(*np.nonzero(reachable), strict=True))
    return PoseGrid(cell, radius, origin, free, reachable, cells)


def _door_point(room: Room) -> tuple[float, float]:
    d = room.door
    return {
        "south": (d.center, 0.0),
        "east": (room.width, d.center),
        "north": (d.center, room.depth),
        "west": (0.0, d.center),
    }[d.wall]


def _entry_component(
    room: Room, free: np.ndarray, px: np.ndarray, py: np.ndarray, door_reach: float
) -> np.ndarray:
    if not free.any():
        return free.copy()
    labels, count = ndimage.label(free)  # default structure: 4-connectivity
    dx, dy = _door_point(room)
    dist = np.where(free, np.hypot(px - dx, py - dy), np.inf)
    nearest = np.unravel_index(int(np.argmin(dist)), free.shape)
    if dist[nearest] <= door_reach:
        return labels == labels[nearest]
    sizes = np.bincount(labels.ravel(), minlength=count + 1)
    sizes[0] = 0
    return labels == int(np.argmax(sizes))
