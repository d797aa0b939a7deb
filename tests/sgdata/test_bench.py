"""sgdata.bench: what the speed measures share (random view poses, views per second)."""

from __future__ import annotations

import numpy as np

from sgdata.bench import sample_poses, views_per_second
from sgdata.world.poses import pose_grid


def test_sample_poses_are_reachable_and_follow_the_seed(tiny_room) -> None:  # noqa: ANN001
    poses = sample_poses(tiny_room.room, 25, np.random.default_rng(3))
    again = sample_poses(tiny_room.room, 25, np.random.default_rng(3))
    assert poses == again and len(poses) == 25
    cells = set(pose_grid(tiny_room.room).cells)
    assert all((p.grid_i, p.grid_j) in cells and 0 <= p.heading < 4 for p in poses)
    assert len({(p.grid_i, p.grid_j, p.heading) for p in poses}) > 1


def test_views_per_second_warms_up_once_then_times_every_pose(tiny_room) -> None:  # noqa: ANN001
    poses = sample_poses(tiny_room.room, 4, np.random.default_rng(0))
    seen = []
    rate = views_per_second(seen.append, poses)
    assert seen == [poses[0], *poses] and rate > 0
