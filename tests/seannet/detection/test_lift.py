"""Boxes lifted with depth, and support inferred from the lifted boxes."""

from __future__ import annotations

import numpy as np

from sgdata.pinhole import camera_to_world, focal_px


def _scene() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A 64 x 64 camera looking straight down +X from 1 m up (no pitch); a wall 3 m ahead,
    and a 0.4 m wide, 0.3 m high box face 1.5 m ahead rendered into the depth."""
    width = 64
    f = focal_px(width, 90.0)
    intrinsics = np.array([f, f, width / 2, width / 2])
    pose = camera_to_world(0.0, 0.0, 0.0, 1.0, 0.0)
    depth = np.full((width, width), 3.0, dtype=np.float32)
    # the face spans y in [-0.2, 0.2], z in [0.85, 1.15] at x = 1.5: columns / rows by pinhole
    u = lambda y: width / 2 - y * f / 1.5  # noqa: E731 - +Y (left) is -u
    v = lambda z: width / 2 - (z - 1.0) * f / 1.5  # noqa: E731
    depth[int(round(v(1.15))) : int(round(v(0.85))), int(round(u(0.2))) : int(round(u(-0.2)))] = 1.5
    return depth, intrinsics, pose


def test_a_box_around_a_face_lifts_to_that_face_not_the_wall_behind_it() -> None:
    from seannet.detection.lift import lift_boxes

    depth, intrinsics, pose = _scene()
    rows, cols = np.nonzero(depth < 2)
    # a detector's box a few pixels larger than the face: the wall shows in its corners
    box = np.array([[cols.min() - 3, rows.min() - 3, cols.max() + 4, rows.max() + 4]], float)
    lo, hi, ok = lift_boxes(depth, box, intrinsics, pose)
    assert ok.tolist() == [True]
    np.testing.assert_allclose(lo[0, 0], 1.5, atol=0.01)  # the face, not the wall at 3 m
    np.testing.assert_allclose(hi[0, 0], 1.5, atol=0.01)
    np.testing.assert_allclose([lo[0, 1], hi[0, 1]], [-0.2, 0.2], atol=0.05)
    np.testing.assert_allclose([lo[0, 2], hi[0, 2]], [0.85, 1.15], atol=0.05)


def test_a_box_that_sees_no_depth_is_not_lifted() -> None:
    from seannet.detection.lift import lift_boxes

    depth, intrinsics, pose = _scene()
    depth[:, :10] = 0  # nothing hit there
    lo, hi, ok = lift_boxes(depth, np.array([[0, 0, 8, 8], [0, 0, 0, 5]], float), intrinsics, pose)
    assert ok.tolist() == [False, False]
    assert not lo.any() and not hi.any()


def test_two_surfaces_in_one_box_give_one_of_them_not_the_gap_between() -> None:
    from seannet.detection.lift import lift_boxes

    depth, intrinsics, pose = _scene()
    depth[:, :] = 3.0
    depth[:, 30:32] = 1.0  # a box two columns wide: one near, one far, as many pixels each
    lo, hi, ok = lift_boxes(depth, np.array([[30, 20, 34, 30]], float), intrinsics, pose)
    assert ok[0] and (np.isclose(lo[0, 0], 1.0, atol=0.01) or np.isclose(lo[0, 0], 3.0, atol=0.01))
    assert np.isclose(lo[0, 0], hi[0, 0], atol=0.01)


def test_a_mug_rests_on_the_table_under_it_and_the_table_on_nothing() -> None:
    from seannet.detection.lift import infer_support

    lo = np.array([[0, 0, 0], [0.4, 0.4, 0.76], [2, 2, 0.76], [0.5, 0.5, 1.5]], float)
    hi = np.array([[1, 1, 0.75], [0.5, 0.5, 0.86], [2.1, 2.1, 0.9], [0.55, 0.55, 1.6]], float)
    # table; mug on it; a box at the table's height elsewhere; a lamp floating above the table
    support = infer_support(lo, hi, np.ones(4, bool))
    assert support.tolist() == [-1, 0, -1, -1]
    # an object whose depth was not seen takes no part
    assert infer_support(lo, hi, np.array([False, True, True, True])).tolist() == [-1, -1, -1, -1]
