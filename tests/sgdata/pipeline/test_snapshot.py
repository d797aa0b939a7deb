"""``sgdata render``: a run's [poses] and [annotation] decide the grid and what is visible."""

from __future__ import annotations

from pathlib import Path

import pytest

from sgdata.pipeline.config import AnnotationConfig
from sgdata.pipeline.snapshot import render_snapshot
from sgdata.render.camera import CameraConfig
from sgdata.usd.scene_dirs import load_layout, write_layouts, write_rooms
from sgdata.world.poses import PosesConfig


@pytest.fixture(scope="module")
def room_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("scenes")
    (room,) = write_rooms(out, "bedroom", count=1, seed=4)
    write_layouts(out / room.room_id, count=2, seed=1)
    return out / room.room_id


def test_the_view_follows_the_runs_poses_and_annotation(room_dir: Path) -> None:
    camera = CameraConfig(width=64, height=48)
    poses = PosesConfig(cell=0.5, robot_radius=0.1)
    record = render_snapshot(room_dir, layout=1, cell=None, heading=2, camera=camera, poses=poses)
    grid = poses.grid(load_layout(room_dir, 1))
    middle = grid.cells[len(grid.cells) // 2]
    assert (record.grid_i, record.grid_j) == middle
    x, y, _ = grid.pose_world(*middle, 2)
    assert (record.x, record.y) == pytest.approx((x, y))
    assert record.num_objects > 0
    none = render_snapshot(
        room_dir,
        layout=1,
        cell=None,
        heading=2,
        camera=camera,
        poses=poses,
        annotation=AnnotationConfig(min_visible_pixels=64 * 48 + 1),
    )
    assert none.num_objects == 0
