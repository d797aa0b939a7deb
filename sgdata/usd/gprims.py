"""Tessellating USD gprims (Cube, Sphere, Cylinder, Cone, Capsule) into triangle meshes.

Each gprim is tessellated in its own frame, centred on its origin along its ``axis`` (USD's
definitions), with trimesh's primitives: enough facets for pictures, few enough for speed.
"""

from __future__ import annotations

import numpy as np
import trimesh
from pxr import Usd, UsdGeom

from sgdata.errors import UsdError

__all__ = ["SECTIONS", "tessellate_gprim"]

SECTIONS = 24  # facets around round gprims

# trimesh builds round primitives along +Z: turn them onto USD's axis token
_AXIS_TURN = {
    "X": np.array([[0.0, 0, 1], [0, 1, 0], [-1, 0, 0]]),  # +Z -> +X
    "Y": np.array([[1.0, 0, 0], [0, 0, -1], [0, 1, 0]]),  # +Z -> +Y
    "Z": np.eye(3),
}


def tessellate_gprim(prim: Usd.Prim) -> tuple[np.ndarray, np.ndarray] | None:
    """Vertices (V, 3) and triangles (F, 3) of a gprim in its own frame; ``None`` if unsupported.

    Raises:
        UsdError: a size, radius or height that is not a positive finite number (names the prim).
    """
    mesh = None
    axis = "Z"
    if prim.IsA(UsdGeom.Cube):
        size = _dimension(UsdGeom.Cube(prim).GetSizeAttr())
        mesh = trimesh.creation.box(extents=(size, size, size))
    elif prim.IsA(UsdGeom.Sphere):
        radius = _dimension(UsdGeom.Sphere(prim).GetRadiusAttr())
        mesh = trimesh.creation.uv_sphere(radius=radius, count=(SECTIONS // 2, SECTIONS))
    elif prim.IsA(UsdGeom.Cylinder):
        cyl = UsdGeom.Cylinder(prim)
        axis = str(cyl.GetAxisAttr().Get())
        mesh = trimesh.creation.cylinder(
            radius=_dimension(cyl.GetRadiusAttr()),
            height=_dimension(cyl.GetHeightAttr()),
            sections=SECTIONS,
        )
    elif prim.IsA(UsdGeom.Cone):
        cone = UsdGeom.Cone(prim)
        axis = str(cone.GetAxisAttr().Get())
        height = _dimension(cone.GetHeightAttr())
        mesh = trimesh.creation.cone(
            radius=_dimension(cone.GetRadiusAttr()), height=height, sections=SECTIONS
        )
        mesh.apply_translation((0.0, 0.0, -height / 2))  # USD centres cones on their origin
    elif prim.IsA(UsdGeom.Capsule):
        cap = UsdGeom.Capsule(prim)
        axis = str(cap.GetAxisAttr().Get())
        mesh = trimesh.creation.capsule(
            height=_dimension(cap.GetHeightAttr()),
            radius=_dimension(cap.GetRadiusAttr()),
            count=(SECTIONS // 2, SECTIONS),
        )
    if mesh is None:
        return None
    vertices = np.asarray(mesh.vertices, dtype=np.float64) @ _AXIS_TURN.get(axis, np.eye(3)).T
    return vertices, np.asarray(mesh.faces, dtype=np.int32)


def _dimension(attr: Usd.Attribute) -> float:
    """A gprim's size, radius or height: trimesh needs a positive finite number (NaN hangs or
    overflows it, a negative one turns the shape inside out)."""
    value = attr.Get()
    try:
        number = float(value)
    except (TypeError, ValueError):
        number = float("nan")
    if not np.isfinite(number) or number <= 0:
        raise UsdError(f"{attr.GetPath()} is {value!r}; expected a positive finite number")
    return number
