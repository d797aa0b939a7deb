"""Physical placement: oriented-box collisions, walls, support surfaces and free-spot sampling.

Shared by the room generator and the dynamics sampler, so that a generated room and every
layout of it obey the same rules: inside the room, resting on a support, no interpenetration.
Collision uses each object's oriented bounding box; an object may overlap the boxes of the
objects it rests on or is attached to (a book on a shelf lies inside the shelving unit's box).
A class made of mesh files collides by its floor outline instead (the convex hull of the
mesh's projection, :func:`floor_outline`) over its box's height, so round plates and bowls
stand as close as their rims allow; two recipe objects keep the box test.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from sgdata.world.catalog import Catalog, ClassSpec
from sgdata.world.scene import Placement, Room, SceneObject
from sgdata.world.shapes import ShapeBuild, Surface, build_shape

__all__ = [
    "CONTACT_EPS",
    "WorldSurface",
    "ancestors",
    "boxes_overlap",
    "colliding",
    "floor_outline",
    "inside_room",
    "objects_overlap",
    "object_build",
    "place_on_surface",
    "shape_build",
    "wall_placement",
    "wall_yaw",
    "world_surfaces",
    "surfaces_for",
]

# Boxes that merely touch (a mug on a counter, two cabinets side by side) do not collide.
CONTACT_EPS = 2e-3


@dataclass(frozen=True)
class WorldSurface:
    """A support surface of one object, with the transform that puts it in the world."""

    owner: int  # instance id of the object offering it
    surface: Surface  # in the owner's local frame
    matrix: np.ndarray  # owner's local-to-world transform

    @property
    def area(self) -> float:
        s = self.surface
        return (s.x1 - s.x0) * (s.y1 - s.y0)


@lru_cache(maxsize=4096)
def shape_build(shape: str, size: tuple[float, float, float], variant: int) -> ShapeBuild:
    """A recipe's output for a shape, size and variant (colour-independent parts of it)."""
    return build_shape(shape, size, variant, (0.5, 0.5, 0.5))


def object_build(obj: SceneObject, catalog: Catalog) -> ShapeBuild:
    """The cached recipe (or mesh files') output for an object (surfaces and attachments do
    not depend on colour)."""
    spec = catalog[obj.class_name]
    if spec.mesh is not None:
        from sgdata.world.mesh_assets import mesh_build  # late: reads the files once

        return mesh_build(spec, obj.size, obj.variant)
    return shape_build(spec.shape, obj.size, obj.variant)


def wall_yaw(wall: str) -> float:
    """Yaw that puts an object's back (+Y local) against ``wall``, its front into the room."""
    return {"north": 0.0, "south": math.pi, "east": -math.pi / 2, "west": math.pi / 2}[wall]


def wall_placement(room: Room, wall: str, along: float, depth: float, z: float) -> Placement:
    """Placement of an object of local ``depth`` whose back touches ``wall`` at ``along``.

    ``along`` is measured from the wall's start: x = 0 for south/north, y = 0 for east/west.
    """
    half = depth / 2
    if wall == "south":
        return Placement(along, half, z, wall_yaw(wall))
    if wall == "north":
        return Placement(along, room.depth - half, z, wall_yaw(wall))
    if wall == "west":
        return Placement(half, along, z, wall_yaw(wall))
    return Placement(room.width - half, along, z, wall_yaw(wall))


def ancestors(obj: SceneObject, by_instance: Mapping[int, SceneObject]) -> set[int]:
    """Instances ``obj`` rests on or is attached to, transitively."""
    seen: set[int] = set()
    current = obj
    while True:
        parent = current.support if current.support is not None else current.attached_to
        if parent is None or parent in seen or parent not in by_instance:
            return seen
        seen.add(parent)
        current = by_instance[parent]


def _footprint_axes(corners: np.ndarray) -> np.ndarray:
    # corners from SceneObject.corners(): x-major order, so 0, 4, 2 span the local x and y edges
    e1 = corners[4, :2] - corners[0, :2]
    e2 = corners[2, :2] - corners[0, :2]
    axes = []
    for e in (e1, e2):
        n = np.hypot(*e)
        axes.append(e / n if n > 0 else np.array([1.0, 0.0]))
    return np.array(axes)


def boxes_overlap(a: SceneObject, b: SceneObject, eps: float = CONTACT_EPS) -> bool:
    """True when the oriented boxes of ``a`` and ``b`` interpenetrate by more than ``eps``.

    Along each axis the contact allowance shrinks to a quarter of the thinner extent, so two
    paper-thin objects (a CD beside a mug on a shelf) still collide.
    """
    ca, cb = a.corners(), b.corners()
    if _separated(ca[:, 2], cb[:, 2], eps):
        return False
    # separating axis test on the two footprints (rectangles in the XY plane)
    for axis in np.vstack([_footprint_axes(ca), _footprint_axes(cb)]):
        if _separated(ca[:, :2] @ axis, cb[:, :2] @ axis, eps):
            return False
    return True


def _separated(pa: np.ndarray, pb: np.ndarray, eps: float) -> bool:
    """Do two projected intervals overlap by no more than the contact allowance?"""
    allowance = min(eps, 0.25 * (pa.max() - pa.min()), 0.25 * (pb.max() - pb.min()))
    return bool(pa.max() - allowance <= pb.min() or pb.max() - allowance <= pa.min())


def floor_outline(obj: SceneObject, catalog: Catalog | None = None) -> np.ndarray:
    """(K, 2) world outline of ``obj`` on the floor, counter-clockwise: the convex hull of a
    mesh class's projection, else its oriented box's footprint (4 corners)."""
    spec = catalog[obj.class_name] if catalog is not None and obj.class_name in catalog else None
    if spec is not None and spec.mesh is not None:
        from sgdata.world.mesh_assets import mesh_footprint  # late: reads the files once

        local = mesh_footprint(spec, obj.size, obj.variant)
        if len(local) >= 3:
            matrix = obj.placement.matrix()
            return local @ matrix[:2, :2].T + matrix[:2, 3]
    # corners from SceneObject.corners(): x-major order, so 0, 4, 6, 2 go round the bottom
    return obj.corners()[[0, 4, 6, 2], :2]


def _is_mesh(obj: SceneObject, catalog: Catalog | None) -> bool:
    return (
        catalog is not None
        and obj.class_name in catalog
        and catalog[obj.class_name].mesh is not None
    )


def objects_overlap(
    a: SceneObject, b: SceneObject, catalog: Catalog | None = None, eps: float = CONTACT_EPS
) -> bool:
    """True when ``a`` and ``b`` interpenetrate by more than ``eps``: their boxes' heights
    overlap and so do their floor outlines (:func:`floor_outline`; the separating axis test
    over both convex polygons' edge normals). Two recipe objects (or no ``catalog``) take
    :func:`boxes_overlap` unchanged."""
    if not (_is_mesh(a, catalog) or _is_mesh(b, catalog)):
        return boxes_overlap(a, b, eps)
    if _separated(a.corners()[:, 2], b.corners()[:, 2], eps):
        return False
    pa, pb = floor_outline(a, catalog), floor_outline(b, catalog)
    return _polygons_overlap(pa, pb, eps)


def _polygons_overlap(pa: np.ndarray, pb: np.ndarray, eps: float) -> bool:
    """Do two convex polygons (K, 2) overlap by more than the contact allowance along every
    edge normal of either (the separating axis theorem, all axes at once)?"""
    edges = np.vstack([np.roll(pa, -1, axis=0) - pa, np.roll(pb, -1, axis=0) - pb])
    length = np.hypot(edges[:, 0], edges[:, 1])
    edges = edges[length > 1e-12] / length[length > 1e-12, None]
    axes = np.stack([-edges[:, 1], edges[:, 0]], axis=1)  # (E, 2) unit normals
    ja, jb = pa @ axes.T, pb @ axes.T  # (Ka, E), (Kb, E)
    lo_a, hi_a, lo_b, hi_b = ja.min(axis=0), ja.max(axis=0), jb.min(axis=0), jb.max(axis=0)
    allowance = np.minimum(eps, 0.25 * np.minimum(hi_a - lo_a, hi_b - lo_b))
    separated = (hi_a - allowance <= lo_b) | (hi_b - allowance <= lo_a)
    return not bool(separated.any())


def colliding(
    candidate: SceneObject,
    others: Iterable[SceneObject],
    by_instance: Mapping[int, SceneObject],
    catalog: Catalog | None = None,
) -> SceneObject | None:
    """The first object in ``others`` that ``candidate`` interpenetrates, ignoring its own
    support chain and everything resting on or attached to it. With ``catalog``, mesh
    classes collide by their floor outlines (:func:`objects_overlap`)."""
    mine = ancestors(candidate, by_instance)
    pool = [
        o
        for o in others
        if o.instance != candidate.instance
        and o.instance not in mine
        and candidate.instance not in ancestors(o, by_instance)
    ]
    if not pool:
        return None
    # axis-aligned prefilter over all objects at once; the oriented test decides the rest
    corners = np.stack([o.corners() for o in pool])
    own = candidate.corners()
    overlap = (corners.min(axis=1) < own.max(axis=0)) & (corners.max(axis=1) > own.min(axis=0))
    for index in np.nonzero(overlap.all(axis=1))[0]:
        if objects_overlap(candidate, pool[index], catalog):
            return pool[index]
    return None


def inside_room(obj: SceneObject, room: Room, eps: float = CONTACT_EPS) -> bool:
    """True when the object's oriented box lies within the room's walls, floor and ceiling."""
    c = obj.corners()
    lo, hi = c.min(axis=0), c.max(axis=0)
    return bool(
        lo[0] >= -eps
        and lo[1] >= -eps
        and lo[2] >= -eps
        and hi[0] <= room.width + eps
        and hi[1] <= room.depth + eps
        and hi[2] <= room.height + eps
    )


def surfaces_for(
    spec: ClassSpec, objects: Iterable[SceneObject], catalog: Catalog
) -> list[WorldSurface]:
    """Every surface among ``objects`` that a ``spec`` object may rest on (its receptacles'
    tops) or in (its containers' insides), in the objects' order."""
    surfaces: list[WorldSurface] = []
    for other in objects:
        if other.class_name in spec.receptacles:
            surfaces += world_surfaces(other, catalog, inside=False)
        if other.class_name in spec.containers:
            surfaces += world_surfaces(other, catalog, inside=True)
    return surfaces


def world_surfaces(obj: SceneObject, catalog: Catalog, *, inside: bool) -> list[WorldSurface]:
    """The top (``inside=False``) or inner (``inside=True``) surfaces ``obj`` offers."""
    build = object_build(obj, catalog)
    matrix = obj.placement.matrix()
    return [WorldSurface(obj.instance, s, matrix) for s in build.surfaces if s.inside == inside]


def place_on_surface(
    rng: np.random.Generator,
    target: WorldSurface,
    size: tuple[float, float, float],
    *,
    yaw: float | None = None,
) -> Placement | None:
    """A random placement of a box of ``size`` resting on ``target``, fully on the surface.

    ``yaw`` is relative to the owner; ``None`` draws a random one. Returns ``None`` when the box
    cannot fit (too tall for the clearance, or too wide for the surface).
    """
    s = target.surface
    w, d, h = size
    if h > s.clearance:
        return None
    rel_yaw = float(rng.uniform(-math.pi, math.pi)) if yaw is None else yaw
    c, si = abs(math.cos(rel_yaw)), abs(math.sin(rel_yaw))
    half_x = (w * c + d * si) / 2  # half extents of the rotated footprint in the owner frame
    half_y = (w * si + d * c) / 2
    if s.x1 - s.x0 < 2 * half_x or s.y1 - s.y0 < 2 * half_y:
        return None
    lx = float(rng.uniform(s.x0 + half_x, s.x1 - half_x))
    ly = float(rng.uniform(s.y0 + half_y, s.y1 - half_y))
    world = target.matrix @ np.array([lx, ly, s.z, 1.0])
    owner_yaw = math.atan2(target.matrix[1, 0], target.matrix[0, 0])
    return Placement(float(world[0]), float(world[1]), float(world[2]), _wrap(owner_yaw + rel_yaw))


def _wrap(angle: float) -> float:
    """Angle wrapped into (-pi, pi]."""
    wrapped = math.atan2(math.sin(angle), math.cos(angle))
    return wrapped if wrapped != -math.pi else math.pi
