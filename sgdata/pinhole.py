"""The pinhole model of a view's camera, in one place: the renderer draws with it and the
dataset states it per view (:mod:`sgdata.dataset.camera` says the convention).

A level-in-roll pinhole at (x, y, eye_height) in the room frame (metres, +Z up), heading
``theta`` radians about +Z (0 looks along +X), pitched down by ``pitch_deg``, square pixels.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["OPENGL_FROM_OPENCV", "basis", "camera_to_world", "focal_px"]

# camera_to_world @ OPENGL_FROM_OPENCV: the same pose with OpenGL's camera axes
OPENGL_FROM_OPENCV = np.diag([1.0, -1.0, -1.0, 1.0])


def focal_px(width: int, hfov_deg: float) -> float:
    """Focal length in pixels of a ``width``-pixel image spanning ``hfov_deg`` (fx = fy)."""
    return (width / 2.0) / math.tan(math.radians(hfov_deg) / 2.0)


def basis(theta: float, pitch_deg: float) -> np.ndarray:
    """Rows right, up, forward (room-frame unit vectors) of a camera heading ``theta``
    (radians about +Z), pitched down by ``pitch_deg``, level in roll."""
    p = math.radians(pitch_deg)
    ct, st, cp, sp = math.cos(theta), math.sin(theta), math.cos(p), math.sin(p)
    forward = np.array([ct * cp, st * cp, -sp])
    right = np.array([st, -ct, 0.0])
    up = np.cross(right, forward)
    return np.stack([right, up, forward])


def camera_to_world(
    x: float, y: float, theta: float, eye_height: float, pitch_deg: float
) -> np.ndarray:
    """4 x 4 camera-to-room transform with OpenCV's camera axes (+X right, +Y down, +Z
    forward)."""
    right, up, forward = basis(theta, pitch_deg)
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2] = right, -up, forward
    m[:3, 3] = (x, y, eye_height)
    return m
