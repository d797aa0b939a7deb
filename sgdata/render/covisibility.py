"""How much of one view another view sees: the overlap score image-matching benchmarks use
(MegaDepth-style covisibility), from two depth maps and the camera's poses.

A pixel of view A with a depth is lifted to its 3D point (the pixel's centre, the depth along
the view axis), projected into view B, and counted as seen by B when it lands inside B's
image, in front of B, and B's depth there agrees with the point's distance within a relative
``tolerance`` (so a point behind something B sees is hidden). The one-sided share is the
count over A's pixels with a depth; :func:`covisibility` is the mean of both directions, so
it is symmetric: 1 for the same pose, near 0 for opposite headings.
"""

from __future__ import annotations

import numpy as np

from sgdata.render.camera import CameraConfig

__all__ = ["DEPTH_TOLERANCE", "covisibility", "seen_share"]

# Relative depth agreement for "the same surface": 5 % of the distance (3 cm at 60 cm, 15 cm
# at 3 m) absorbs the depth buffer's quantisation and a pixel's footprint on a slanted wall.
DEPTH_TOLERANCE = 0.05

Pose = tuple[float, float, float]  # x, y (m), heading theta (rad about +Z)


def _points(camera: CameraConfig, depth: np.ndarray, pose: Pose) -> np.ndarray:
    """(N, 3) world points of the pixels of ``depth`` that have one (depth > 0)."""
    v, u = np.nonzero(depth > 0)
    z = depth[v, u].astype(np.float64)
    f = camera.focal
    xc = (u + 0.5 - camera.width / 2.0) * z / f
    yc = (camera.height / 2.0 - (v + 0.5)) * z / f
    right, up, forward = camera.basis(pose[2])
    eye = np.array([pose[0], pose[1], camera.eye_height])
    return eye + xc[:, None] * right + yc[:, None] * up + z[:, None] * forward


def seen_share(
    camera: CameraConfig,
    depth_a: np.ndarray,
    pose_a: Pose,
    depth_b: np.ndarray,
    pose_b: Pose,
    *,
    tolerance: float = DEPTH_TOLERANCE,
) -> float:
    """The share of A's pixels (with a depth) whose 3D point view B sees; 0 when A has none."""
    points = _points(camera, depth_a, pose_a)
    if not len(points):
        return 0.0
    u, v, z = camera.project(points, *pose_b).T
    inside = (z > camera.znear) & (u >= 0) & (u < camera.width) & (v >= 0) & (v < camera.height)
    col = np.clip(np.floor(u[inside]).astype(np.int64), 0, camera.width - 1)
    row = np.clip(np.floor(v[inside]).astype(np.int64), 0, camera.height - 1)
    there = depth_b[row, col].astype(np.float64)
    agree = (there > 0) & (np.abs(there - z[inside]) <= tolerance * z[inside])
    return float(agree.sum() / len(points))


def covisibility(
    camera: CameraConfig,
    depth_a: np.ndarray,
    pose_a: Pose,
    depth_b: np.ndarray,
    pose_b: Pose,
    *,
    tolerance: float = DEPTH_TOLERANCE,
) -> float:
    """Symmetric covisibility of two views in [0, 1]: the mean of A's share seen by B and
    B's share seen by A."""
    ab = seen_share(camera, depth_a, pose_a, depth_b, pose_b, tolerance=tolerance)
    ba = seen_share(camera, depth_b, pose_b, depth_a, pose_a, tolerance=tolerance)
    return 0.5 * (ab + ba)
