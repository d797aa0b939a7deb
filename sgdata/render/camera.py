"""The pinhole camera the agent carries: intrinsics, pose and projection (no backend imports;
the pinhole model itself is :mod:`sgdata.pinhole`'s, which the dataset states per view)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sgdata.errors import RenderError
from sgdata.pinhole import OPENGL_FROM_OPENCV, basis, camera_to_world, focal_px

__all__ = ["VIEW_SIZE", "CameraConfig"]

# Pixels a side of a rendered view: the image networks' input (seannet.weights.IMAGE_SIZE,
# which may not be imported down here; tests/seannet/test_weights.py holds the two equal)
VIEW_SIZE = 224


@dataclass(frozen=True)
class CameraConfig:
    """A pinhole camera carried by the agent, level in roll, pitched down by ``pitch_deg``.

    Pixel coordinates are continuous: pixel (u, v) (column u, row v, row 0 at the top) covers
    [u, u + 1) x [v, v + 1) and its centre is (u + 0.5, v + 0.5).
    """

    width: int = VIEW_SIZE  # pixels
    height: int = VIEW_SIZE  # pixels
    hfov_deg: float = 90.0  # horizontal field of view; AI2-THOR's default is 90
    eye_height: float = 1.5  # camera height above the floor (m), about AI2-THOR's agent eye
    # Positive looks down. 20 deg keeps the far wall's paintings and windows in view while
    # bringing table tops, counters and the near floor (where small objects lie) into the
    # lower half: at 0 deg a 224 px image spends its lower ~30% on bare floor.
    pitch_deg: float = 20.0
    znear: float = 0.05  # near clip plane (m)
    zfar: float = 30.0  # far clip plane (m)

    def __post_init__(self) -> None:
        if self.width < 1 or self.height < 1:
            raise RenderError(f"camera size {self.width}x{self.height}: expected >= 1 pixel each")
        if not 0.0 < self.hfov_deg < 180.0:
            raise RenderError(f"camera hfov_deg={self.hfov_deg}: expected in (0, 180)")
        if not -90.0 < self.pitch_deg < 90.0:
            raise RenderError(f"camera pitch_deg={self.pitch_deg}: expected in (-90, 90)")
        if not 0.0 < self.znear < self.zfar:
            raise RenderError(f"camera znear={self.znear}, zfar={self.zfar}: need 0 < znear < zfar")

    @property
    def focal(self) -> float:
        """Focal length in pixels (square pixels: fx = fy)."""
        return focal_px(self.width, self.hfov_deg)

    @property
    def yfov(self) -> float:
        """Vertical field of view in radians."""
        return 2.0 * math.atan((self.height / 2.0) / self.focal)

    def basis(self, theta: float) -> np.ndarray:
        """Rows right, up, forward (world unit vectors) for heading ``theta`` (rad about +Z)."""
        return basis(theta, self.pitch_deg)

    @property
    def intrinsics(self) -> tuple[float, float, float, float]:
        """fx, fy, cx, cy for continuous pixel coordinates: a view's ``intrinsics`` column."""
        return self.focal, self.focal, self.width / 2.0, self.height / 2.0

    def camera_to_world(self, x: float, y: float, theta: float) -> np.ndarray:
        """4x4 camera-to-world transform with OpenCV's axes: a view's ``camera_to_world``."""
        return camera_to_world(x, y, theta, self.eye_height, self.pitch_deg)

    def pose_matrix(self, x: float, y: float, theta: float) -> np.ndarray:
        """4x4 camera-to-world transform in OpenGL convention (camera looks along -Z, +Y up):
        the dataset's ``camera_to_world`` (OpenCV axes) turned to OpenGL's."""
        return self.camera_to_world(x, y, theta) @ OPENGL_FROM_OPENCV

    def project(self, points: np.ndarray, x: float, y: float, theta: float) -> np.ndarray:
        """World points (N, 3) -> (N, 3) of continuous pixel u, v and forward depth (m)."""
        rel = np.asarray(points, dtype=np.float64) - (x, y, self.eye_height)
        right, up, forward = self.basis(theta)
        xc, yc, zc = rel @ right, rel @ up, rel @ forward
        f = self.focal
        with np.errstate(divide="ignore", invalid="ignore"):
            u = self.width / 2.0 + f * xc / zc
            v = self.height / 2.0 - f * yc / zc
        return np.stack([u, v, zc], axis=1)
