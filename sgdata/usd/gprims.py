"""Tessellating USD gprims (Cube, Sphere, Cylinder, Cone, Capsule) into triangle meshes.

Each gprim is tessellated in its own frame, centred on its origin along its ``axis`` (USD's
definitions), with trimesh's primitives: enough facets for pictures, few enough for speed.
"""

from __future__ import annotations

import numpy as np
import trimesh
from pxr import Usd, UsdGeom

__all__ = ["SECTIONS", "tessellate_gprim"]

SECTIONS = 24  # facets around round gprims

# trimesh builds round primitives along +Z: turn them onto USD's axis token
_AXIS_TURN = {
    "X": np.array([[0.0, 0, 1], [0, 1, 0], [-1, 0, 0]]),  # +Z -> +X
    "Y": np.array([[1.0, 0, 0], [0, 0, -1], [0, 1, 0]]),  # +Z -> +Y
    "Z": np.eye(3),
}


def tessellate_gprim(prim: Usd.Prim) -> tuple[np.ndarray, np.ndarray] | None:
    """Vertices (V, 3) and triangles (F, 3) of a gprim in its own frame; ``None`` if unsupported."""
    mesh = None
    axis = "Z"
    if prim.IsA(UsdGeom.Cube):
        size = float(UsdGeom.Cube(prim).GetSizeAttr().Get())
        mesh = trimesh.creation.box(extents=(size, size, size))
    elif prim.IsA(UsdGeom.Sphere):
        radius = float(UsdGeom.Sphere(prim).GetRadiusAttr().Get())
        mesh = trimesh.creation.uv_sphere(radius=radius, count=(SECTIONS // 2, SECTIONS))
    elif prim.IsA(UsdGeom.Cylinder):
        cyl = UsdGeom.Cylinder(prim)
        axis = str(cyl.GetAxisAttr().Get())
        mesh = trimesh.creation.cylinder(
            radius=float(cyl.GetRadiusAttr().Get()),
            height=float(cyl.GetHeightAttr().Get()),
            sections=SECTIONS,
        )
    elif prim.IsA(UsdGeom.Cone):
        cone = UsdGeom.Cone(prim)
        axis = str(cone.GetAxisAttr().Get())
        height = float(cone.GetHeightAttr().Get())
        mesh = trimesh.creation.cone(
            radius=float(cone.GetRadiusAttr().Get()), height=height, sections=SECTIONS
        )
        mesh.apply_translation((0.0, 0.0, -height / 2))  # USD centres cones on their origin
    elif prim.IsA(UsdGeom.Capsule):
        cap = UsdGeom.Capsule(prim)
        axis = str(cap.GetAxisAttr().Get())
        mesh = trimesh.creation.capsule(
            height=float(cap.GetHeightAttr().Get()),
            radius=float(cap.GetRadiusAttr().Get()),
            count=(SECTIONS // 2, SECTIONS),
        )
    if mesh is None:
        return None
    vertices = np.asarray(mesh.vertices, dtype=np.float64) @ _AXIS_TURN.get(axis, np.eye(3)).T
    return vertices, np.asarray(mesh.faces, dtype=np.int32)
