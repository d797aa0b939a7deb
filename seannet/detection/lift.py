"""Detected 2D boxes lifted to 3D with the depth channel, and which object rests on which:
the inputs the generator's relation rules (:func:`sgdata.annotate.relations.compute_relations`)
take, measured from pixels instead of read from the scene.

A box holds its object and whatever is seen around or behind it. The object is taken to be
the depth surface at the median depth of the box's central half (an object fills its box's
centre more than its corners), and the box's pixels within a band of that depth are lifted
through the pinhole (the dataset's ``intrinsics`` and ``camera_to_world``). The 3D box is the
2nd to 98th percentile of those points per axis: only the visible surface, so it is thinner
than the object in depth.
"""

from __future__ import annotations

import numpy as np

__all__ = ["DEPTH_BAND", "lift_boxes", "infer_support"]

# metres around the object's median depth that still count as the object: a fixed part for
# thin objects, a part growing with distance for the depth of large ones seen at a slant
DEPTH_BAND = (0.15, 0.08)
SUPPORT_GAP = 0.06  # metres between a bottom and a top that still count as resting on it


def lift_boxes(
    depth: np.ndarray,
    boxes: np.ndarray,
    intrinsics: np.ndarray,
    camera_to_world: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """World axis-aligned boxes of the objects in ``boxes``.

    Args:
        depth: (H, W) metres along the camera axis, 0 where nothing was hit.
        boxes: (n, 4) [u1, v1, u2, v2] pixels (u2, v2 exclusive).
        intrinsics: fx, fy, cx, cy for continuous pixel coordinates.
        camera_to_world: 4 x 4, OpenCV camera axes.

    Returns:
        ``(box_min, box_max, ok)``: (n, 3) each, and (n,) bool, False where the box saw no
        depth (its rows are then zero).
    """
    height, width = depth.shape
    fx, fy, cx, cy = (float(v) for v in intrinsics)
    pose = np.asarray(camera_to_world, dtype=np.float64).reshape(4, 4)
    n = len(boxes)
    lo, hi, ok = np.zeros((n, 3)), np.zeros((n, 3)), np.zeros(n, dtype=bool)
    for k, (u1, v1, u2, v2) in enumerate(np.asarray(boxes, dtype=np.float64)):
        a, b = int(np.clip(np.floor(u1), 0, width)), int(np.clip(np.ceil(u2), 0, width))
        c, d = int(np.clip(np.floor(v1), 0, height)), int(np.clip(np.ceil(v2), 0, height))
        patch = depth[c:d, a:b]
        if patch.size == 0:
            continue
        h, w = patch.shape
        centre = patch[h // 4 : h - h // 4 or h, w // 4 : w - w // 4 or w]
        seen = centre[centre > 0]
        if seen.size == 0:
            seen = patch[patch > 0]
            if seen.size == 0:
                continue
        # a depth the box holds: the mean of two middle values can fall between two surfaces
        middle = float(np.percentile(seen, 50, method="lower"))
        band = DEPTH_BAND[0] + DEPTH_BAND[1] * middle
        rows, cols = np.nonzero((patch > 0) & (np.abs(patch - middle) <= band))
        z = patch[rows, cols].astype(np.float64)
        x = (cols + a + 0.5 - cx) * z / fx
        y = (rows + c + 0.5 - cy) * z / fy
        points = np.stack((x, y, z, np.ones_like(z)), axis=1) @ pose.T
        lo[k] = np.percentile(points[:, :3], 2, axis=0)
        hi[k] = np.percentile(points[:, :3], 98, axis=0)
        ok[k] = True
    return lo, hi, ok


def infer_support(box_min: np.ndarray, box_max: np.ndarray, ok: np.ndarray) -> np.ndarray:
    """Per object, the index of the object it rests on, or -1 (the floor, or none seen).

    An object rests on another when its bottom is within :data:`SUPPORT_GAP` of the other's
    top and the centre
    of its footprint lies over the other's footprint; of several, the highest top wins.
    """
    n = len(box_min)
    support = np.full(n, -1, dtype=np.int64)
    for i in range(n):
        if not ok[i]:
            continue
        centre = (box_min[i, :2] + box_max[i, :2]) / 2
        best, best_top = -1, -np.inf
        for j in range(n):
            if j == i or not ok[j]:
                continue
            top = box_max[j, 2]
            reaches = top - SUPPORT_GAP <= box_min[i, 2] <= top + SUPPORT_GAP
            over = np.all(centre >= box_min[j, :2]) and np.all(centre <= box_max[j, :2])
            # the other must be the larger footprint: a mug does not carry its table
            larger = np.prod(box_max[j, :2] - box_min[j, :2]) > np.prod(
                box_max[i, :2] - box_min[i, :2]
            )
            if reaches and over and larger and top > best_top:
                best, best_top = j, top
        support[i] = best
    return support
