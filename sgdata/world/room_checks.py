"""Physical validity of a room or layout: inside the walls, resting on supports, no overlaps."""

from __future__ import annotations

import numpy as np

from sgdata.world.catalog import Catalog
from sgdata.world.placement import (
    CONTACT_EPS,
    ancestors,
    inside_room,
    objects_overlap,
    world_surfaces,
)
from sgdata.world.scene import Room, SceneObject

__all__ = ["room_problems", "resting_surface"]

REST_TOLERANCE = 5e-3  # metres an object may float above or sink into its support surface


def resting_surface(obj: SceneObject, support: SceneObject, catalog: Catalog) -> bool:
    """True when ``obj``'s footprint lies on one of ``support``'s surfaces at its height."""
    corners = obj.corners()
    bottom = corners[corners[:, 2] <= corners[:, 2].min() + 1e-9]
    for inside in (False, True):
        for target in world_surfaces(support, catalog, inside=inside):
            s = target.surface
            local = (np.linalg.inv(target.matrix) @ np.c_[bottom, np.ones(len(bottom))].T).T
            if abs(float(local[:, 2].mean()) - s.z) > REST_TOLERANCE:
                continue
            eps = CONTACT_EPS
            if (
                local[:, 0].min() >= s.x0 - eps
                and local[:, 0].max() <= s.x1 + eps
                and local[:, 1].min() >= s.y0 - eps
                and local[:, 1].max() <= s.y1 + eps
            ):
                return True
    return False


def room_problems(room: Room, catalog: Catalog, *, limit: int = 20) -> list[str]:
    """Every physical problem found (up to ``limit``), one readable line each; [] when valid."""
    problems: list[str] = []
    by_instance = room.by_instance()
    objects = list(room.objects)
    for obj in objects:
        if not inside_room(obj, room):
            lo, hi = obj.world_aabb()
            shell = f"{room.width:.2f} x {room.depth:.2f} x {room.height:.2f}"
            problems.append(
                f"{obj.prim_name} is not inside the room (box {np.round(lo, 2).tolist()} .. "
                f"{np.round(hi, 2).tolist()}, room {shell})"
            )
        for key in (obj.support, obj.attached_to):
            if key is not None and key not in by_instance:
                problems.append(f"{obj.prim_name} refers to missing instance {key}")
        if obj.support is not None and obj.support in by_instance:
            if not resting_surface(obj, by_instance[obj.support], catalog):
                problems.append(
                    f"{obj.prim_name} does not rest on a surface of its support "
                    f"{by_instance[obj.support].prim_name}"
                )
        elif obj.support is None and obj.attached_to is None and obj.placement.z > REST_TOLERANCE:
            spec = catalog[obj.class_name] if obj.class_name in catalog else None
            if spec is None or spec.placement != "wall":
                problems.append(f"{obj.prim_name} floats {obj.placement.z:.3f} m above the floor")
    lineage = {o.instance: ancestors(o, by_instance) for o in objects}
    boxes = np.array([np.concatenate(o.world_aabb()) for o in objects])
    for a_index, a in enumerate(objects):
        # cheap axis-aligned prefilter before the oriented test
        lo_ok = (boxes[a_index + 1 :, :3] < boxes[a_index, 3:] - CONTACT_EPS).all(axis=1)
        hi_ok = (boxes[a_index + 1 :, 3:] > boxes[a_index, :3] + CONTACT_EPS).all(axis=1)
        for offset in np.nonzero(lo_ok & hi_ok)[0]:
            b = objects[a_index + 1 + int(offset)]
            if b.instance in lineage[a.instance] or a.instance in lineage[b.instance]:
                continue
            if objects_overlap(a, b, catalog):
                problems.append(f"{a.prim_name} and {b.prim_name} interpenetrate")
        if len(problems) >= limit:
            break
    return problems[:limit]
