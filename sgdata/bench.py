"""What the speed measures under bench/ share: random view poses of a room, and views per
second of a rendering function (a warm-up call first, then the wall clock over the poses)."""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from sgdata.annotate.records import ViewPose
    from sgdata.world.scene import Room

__all__ = ["sample_poses", "views_per_second"]


def sample_poses(room: Room, count: int, rng: np.random.Generator) -> list[ViewPose]:
    """``count`` poses drawn uniformly from the room's reachable cells and four headings
    (with repetition); none when the room has no reachable cell."""
    from sgdata.annotate.records import ViewPose
    from sgdata.world.poses import pose_grid

    grid = pose_grid(room)
    if not grid.cells:
        return []
    poses = []
    for pick in rng.integers(0, len(grid.cells), count):
        i, j = grid.cells[int(pick)]
        heading = int(rng.integers(0, 4))
        x, y, theta = grid.pose_world(i, j, heading)
        poses.append(ViewPose(x, y, theta, i, j, heading))
    return poses


def views_per_second(fn: Callable[[ViewPose], object], poses: list[ViewPose]) -> float:
    """Views per second of ``fn`` over ``poses``, after one untimed call (shader compilation,
    buffer upload)."""
    fn(poses[0])
    start = time.perf_counter()
    for pose in poses:
        fn(pose)
    return len(poses) / (time.perf_counter() - start)
