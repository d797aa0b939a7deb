"""Render detail of mesh files: a part's triangles decimated to a budget (quadric error metric).

A user's mesh may hold far more triangles than a 224-pixel view can show (a 20k-triangle mug
covers a few hundred pixels), and a CPU rasteriser pays for every one. A mesh class draws at
most ``max_triangles`` per variant (catalog field, default
:data:`~sgdata.world.catalog.DEFAULT_MAX_TRIANGLES`; 0 keeps every triangle): each part gets
its share of the budget by its triangle count and is simplified by open3d's quadric decimation
(deterministic: the same part gives the same triangles). Placement never sees this: footprints
and support surfaces come from the full mesh. Texture coordinates of a simplified part are
those of each new vertex's nearest original vertex (a texture seam may smear a little).
"""

from __future__ import annotations

import numpy as np

__all__ = ["MIN_PART_TRIANGLES", "budgets", "decimate"]

MIN_PART_TRIANGLES = 64  # parts this small (a box, a handle) are never simplified


def budgets(counts: list[int], limit: int) -> list[int]:
    """Each part's triangle budget: its share of ``limit`` by its count (never below
    :data:`MIN_PART_TRIANGLES`, never above its own count); ``limit`` 0 or a total within it
    keeps every count."""
    total = sum(counts)
    if limit <= 0 or total <= limit:
        return list(counts)
    return [min(n, max(MIN_PART_TRIANGLES, int(limit * n / total))) for n in counts]


def decimate(
    vertices: np.ndarray, faces: np.ndarray, target: int, uvs: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """``faces`` simplified to about ``target`` triangles: (vertices, faces, corner UVs or
    None). Nothing changes when the part has ``target`` triangles or fewer.

    Args:
        vertices: (V, 3) float64.
        faces: (F, 3) int.
        target: the triangles to keep.
        uvs: (F, 3, 2) corner texture coordinates, or None.
    """
    if len(faces) <= target:
        return vertices, faces, uvs
    import open3d as o3d  # late: only meshes over their budget need it

    mesh = o3d.geometry.TriangleMesh(
        o3d.utility.Vector3dVector(np.asarray(vertices, np.float64)),
        o3d.utility.Vector3iVector(np.asarray(faces, np.int32)),
    )
    simple = mesh.simplify_quadric_decimation(int(target))
    new_vertices = np.asarray(simple.vertices, np.float64)
    new_faces = np.asarray(simple.triangles, np.int64)
    area = np.linalg.norm(
        np.cross(
            new_vertices[new_faces[:, 1]] - new_vertices[new_faces[:, 0]],
            new_vertices[new_faces[:, 2]] - new_vertices[new_faces[:, 0]],
        ),
        axis=1,
    )
    new_faces = new_faces[area > 0]
    if uvs is None:
        return new_vertices, new_faces, None
    from scipy.spatial import cKDTree  # late: with open3d

    per_vertex = np.zeros((len(vertices), 2), np.float32)
    per_vertex[np.asarray(faces).reshape(-1)] = np.asarray(uvs, np.float32).reshape(-1, 2)
    _, nearest = cKDTree(np.asarray(vertices, np.float64)).query(new_vertices)
    return new_vertices, new_faces, per_vertex[nearest][new_faces]
