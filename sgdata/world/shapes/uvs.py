"""Texture coordinates for any triangle mesh: box projection in metres.

Each triangle is projected onto the plane of the axis its normal points along most (a box
projection), so ``st`` is in metres of the mesh's own frame: a material scales it by its
texture's tile size, and a texture is as large on a small object as on a large one. Faces
that look along a negative axis are mirrored so that a texture reads the same way round on
opposite sides of a box. Curved surfaces show a seam where the dominant axis changes, the
usual price of a box projection.
"""

from __future__ import annotations

import numpy as np

__all__ = ["box_uvs"]

# For a face whose normal points along (axis, sign): which coordinates give (s, t), and the
# sign of s (t always runs up the surface, or along +y on horizontal faces).
_PROJECTIONS = {
    (0, 1): (1, 2, 1.0),  # +x: s = y, t = z
    (0, -1): (1, 2, -1.0),  # -x: s = -y
    (1, 1): (0, 2, -1.0),  # +y: s = -x
    (1, -1): (0, 2, 1.0),  # -y (an object's front): s = x
    (2, 1): (0, 1, 1.0),  # +z (tops, floors): s = x, t = y
    (2, -1): (0, 1, -1.0),  # -z (undersides, ceilings): s = -x
}


def box_uvs(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Box-projected texture coordinates of every face corner, in metres.

    Args:
        vertices: (V, 3) positions in metres (an object's local frame, or world space).
        faces: (F, 3) vertex indices.

    Returns:
        (F, 3, 2) float32: (s, t) of each face's three corners, in face order.

    Shapes:
        vertices (V, 3), faces (F, 3) -> (F, 3, 2).
    """
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    tri = v[f]  # (F, 3, 3)
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    axis = np.argmax(np.abs(normal), axis=1)
    sign = np.where(normal[np.arange(len(f)), axis] >= 0, 1, -1)
    out = np.zeros((len(f), 3, 2), dtype=np.float64)
    for (a, sg), (s_axis, t_axis, flip) in _PROJECTIONS.items():
        pick = (axis == a) & (sign == sg)
        if pick.any():
            out[pick, :, 0] = flip * tri[pick][:, :, s_axis]
            out[pick, :, 1] = tri[pick][:, :, t_axis]
    return out.astype(np.float32)
