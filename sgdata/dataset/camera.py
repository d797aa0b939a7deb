"""A view's camera as the dataset states it (format 2.2.0): its columns and their convention.

A view's camera is a level-in-roll pinhole at (x, y, eye_height) in the room frame (metres,
+Z up), heading ``theta`` radians about +Z (0 looks along +X), pitched down by ``pitch_deg``,
with square pixels and the principal point at the image centre. From format 2.2.0 every
synthetic view carries it explicitly (:func:`camera_columns`):

- ``intrinsics``: (fx, fy, cx, cy) in pixels, for continuous pixel coordinates: pixel (u, v)
  (column u, row v, row 0 at the top) covers [u, u + 1) x [v, v + 1), so cx = width / 2. In
  OpenCV's convention, where a pixel's centre is its integer index, cx and cy are 0.5 less.
- ``camera_to_world``: the 4 x 4 matrix (row-major, 16 numbers) taking camera coordinates to
  the room frame, with OpenCV's camera axes: +X right, +Y down, +Z forward (the axis K
  projects along). OpenGL's (and pyrender's) axes are +Y up, -Z forward: multiply on the
  right by diag(1, -1, -1, 1).

The renderer (:class:`sgdata.render.camera.CameraConfig`) draws with the same pinhole model
(:mod:`sgdata.pinhole`).
"""

from __future__ import annotations

from collections.abc import Mapping

import pyarrow as pa

from sgdata.dataset.schema import observations_schema
from sgdata.pinhole import camera_to_world, focal_px

__all__ = ["CAMERA_SINCE", "camera_columns"]

CAMERA_SINCE = "2.2.0"  # the format version that added the columns intrinsics, camera_to_world


def camera_columns(table: pa.Table | Mapping[str, pa.Array]) -> tuple[pa.Array, pa.Array]:
    """The ``intrinsics`` and ``camera_to_world`` columns of observation rows (a table, or
    its columns by name), from their ``x``, ``y``, ``theta`` and ``camera`` columns; null
    where those are (a real photo has no field of view, an unposed one no pose)."""
    cols = {n: table[n].to_pylist() for n in ("x", "y", "theta", "camera")}
    intrinsics: list[list[float] | None] = []
    poses: list[list[float] | None] = []
    for x, y, theta, cam in zip(*cols.values(), strict=True):
        hfov = cam["hfov_deg"]
        if hfov is None:
            intrinsics.append(None)
        else:
            f = focal_px(cam["width"], hfov)
            intrinsics.append([f, f, cam["width"] / 2.0, cam["height"] / 2.0])
        pose = (x, y, theta, cam["eye_height"], cam["pitch_deg"])
        poses.append(None if None in pose else camera_to_world(*pose).reshape(-1).tolist())
    schema = observations_schema()
    return (
        pa.array(intrinsics, type=schema.field("intrinsics").type),
        pa.array(poses, type=schema.field("camera_to_world").type),
    )
