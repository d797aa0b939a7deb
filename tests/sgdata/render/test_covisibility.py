"""Covisibility of two views from their depth maps: constructed scenes whose answer is known
(depth by ray casting against planes), and views the real renderer draws."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sgdata.render.camera import CameraConfig
from sgdata.render.covisibility import covisibility, seen_share

SMALL = CameraConfig(width=64, height=64)


def box_room_depth(camera: CameraConfig, pose: tuple[float, float, float],
                   size: tuple[float, float, float] = (4.0, 4.0, 2.6)) -> np.ndarray:  # fmt: skip
    """Forward depth of every pixel inside an empty box room (walls, floor, ceiling)."""
    right, up, forward = camera.basis(pose[2])
    eye = np.array([pose[0], pose[1], camera.eye_height])
    v, u = np.mgrid[0 : camera.height, 0 : camera.width]
    xc = (u + 0.5 - camera.width / 2.0) / camera.focal
    yc = (camera.height / 2.0 - (v + 0.5)) / camera.focal
    rays = xc[..., None] * right + yc[..., None] * up + forward  # forward component 1
    depth = np.full(u.shape, np.inf)
    for axis, bound in ((0, 0.0), (0, size[0]), (1, 0.0), (1, size[1]), (2, 0.0), (2, size[2])):
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (bound - eye[axis]) / rays[..., axis]
        t[~np.isfinite(t) | (t <= 0)] = np.inf
        depth = np.minimum(depth, t)
    return depth.astype(np.float32)


def wall_depth(camera: CameraConfig, distance: float) -> np.ndarray:
    """A level camera facing a wall ``distance`` m ahead: every pixel at that depth."""
    return np.full((camera.height, camera.width), distance, dtype=np.float32)


def test_the_same_pose_sees_all_of_itself() -> None:
    pose = (2.0, 2.0, 0.3)
    depth = box_room_depth(SMALL, pose)
    assert covisibility(SMALL, depth, pose, depth, pose) == pytest.approx(1.0, abs=1e-6)


def test_turning_round_sees_almost_nothing_of_the_first_view() -> None:
    ahead, behind = (2.0, 2.0, 0.0), (2.0, 2.0, math.pi)
    score = covisibility(
        SMALL, box_room_depth(SMALL, ahead), ahead, box_room_depth(SMALL, behind), behind
    )
    assert score < 0.02


def test_a_step_sideways_loses_the_band_of_columns_it_shifts_by() -> None:
    """Facing a wall D m ahead, a step s to the side shifts the image by f s / D pixels: the
    share that stays in view is 1 - s / (2 D) at a 90 degree field of view."""
    level = CameraConfig(width=96, height=96, pitch_deg=0.0)
    distance, step = 2.0, 0.5
    depth = wall_depth(level, distance)
    here, beside = (0.0, 0.0, 0.0), (0.0, -step, 0.0)  # heading +x: right is -y
    expected = 1.0 - step / (2.0 * distance)
    assert seen_share(level, depth, here, depth, beside) == pytest.approx(expected, abs=0.011)
    assert covisibility(level, depth, here, depth, beside) == pytest.approx(expected, abs=0.011)


def test_a_point_behind_a_nearer_surface_is_not_seen() -> None:
    """B sees a nearer surface where A's points lie: depth disagrees, so they are hidden."""
    level = CameraConfig(width=32, height=32, pitch_deg=0.0)
    far, near = wall_depth(level, 3.0), wall_depth(level, 1.0)
    pose = (0.0, 0.0, 0.0)
    assert seen_share(level, far, pose, near, pose) == 0.0
    assert seen_share(level, far, pose, far, pose) == pytest.approx(1.0)


def test_pixels_without_depth_are_not_counted() -> None:
    level = CameraConfig(width=32, height=32, pitch_deg=0.0)
    empty = np.zeros((32, 32), dtype=np.float32)
    assert seen_share(level, empty, (0.0, 0.0, 0.0), wall_depth(level, 2.0), (0.0, 0.0, 0.0)) == 0


def test_rendered_views_of_a_room_agree_with_their_geometry(tiny_room) -> None:  # noqa: ANN001
    """The real renderer's depth: the same pose gives 1, a quarter turn keeps less than the
    same pose, and a half turn keeps less still."""
    from sgdata.render.renderer import Renderer

    camera = CameraConfig(width=64, height=64)
    with Renderer(camera) as renderer:
        renderer.load(tiny_room.geometry)
        poses = [(2.5, 2.0, 0.0), (2.5, 2.0, math.pi / 2), (2.5, 2.0, math.pi)]
        depths = [renderer.render_rgb(*p, depth=True)[1] for p in poses]
    same = covisibility(camera, depths[0], poses[0], depths[0], poses[0])
    quarter = covisibility(camera, depths[0], poses[0], depths[1], poses[1])
    half = covisibility(camera, depths[0], poses[0], depths[2], poses[2])
    assert same == pytest.approx(1.0, abs=1e-3)
    assert same > quarter > half and half < 0.05
