"""Rooms authored elsewhere: a stage's room and objects measured from its geometry when not tagged.

Only ``sgdata:class`` per object prim is required (DESIGN §3). Everything else is read when
authored and measured otherwise, in the room frame (:mod:`sgdata.usd.stage_frame`):

- the room's interior box: floor top (lowest up-facing structure face), ceiling (lowest
  down-facing face above it, else the walls' top) and, per side, the innermost large vertical
  structure plane; its low corner becomes the room frame's origin (``sgdata:roomOrigin``);
- the door: the widest gap (at least :data:`MIN_DOOR` wide) through a wall at 0.5, 1.0 and
  1.5 m; without one, a virtual entry :data:`DEFAULT_DOOR` wide in the middle of the longest
  stretch of wall with nothing standing within :data:`DOOR_CLEARANCE` of it;
- each object's box: its yaw from its prim's x-axis, its size and bottom-centre placement
  from its geometry's bounds in that heading;
- instance ids by prim path order (:mod:`sgdata.usd.object_prims`), dynamics from the catalog
  or the user's class file, colour as the mean of its face colours;
- support: the object whose top is within :data:`REST_GAP` below the object's bottom and under
  its footprint centre (the highest such), else the smallest object whose box holds that point.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from pxr import Usd

from sgdata.errors import UsdError
from sgdata.usd.geometry import stage_geometry
from sgdata.usd.meshes import MeshData, ObjectGeometry
from sgdata.usd.prims import ROOM_ORIGIN
from sgdata.usd.stage_frame import room_prim
from sgdata.world.catalog import Catalog, load_catalog
from sgdata.world.scene import WALLS, Dynamics, Opening, Placement, Room, SceneObject

__all__ = [
    "MEASURED",
    "DEFAULT_DOOR",
    "DOOR_CLEARANCE",
    "MIN_DOOR",
    "REST_GAP",
    "MeasuredRoom",
    "is_measured",
    "measure_stage",
]

MEASURED = "sgdata:placements"  # token "measured" on the room prim: placements come from geometry
MIN_DOOR = 0.5  # metres: narrower gaps in a wall are not doors
DEFAULT_DOOR = 0.9  # metres: width of the virtual entry of a room without a door gap
DOOR_CLEARANCE = 0.8  # metres in front of the virtual entry kept free of objects
DOOR_TOP = 2.0  # metres: top of a virtual entry (or of a gap with no lintel found)
REST_GAP = 0.03  # metres an object's bottom may sit above (or 1 cm inside) its support's top
_FLOOR_BAND = 0.02  # metres: an object lower than this rests on the floor
_PLANE_SHARE = 0.2  # a wall plane needs this share of the largest plane's area on its side


@dataclass(frozen=True)
class MeasuredRoom:
    """A room read from any stage, with where its values came from."""

    room: Room
    origin: tuple[float, float, float]  # the room frame's origin, Z-up metres of the stage
    paths: dict[int, str]  # instance -> object prim path
    inferred: tuple[str, ...]  # one line per value that was measured or assigned, not read


def is_measured(stage: Usd.Stage) -> bool:
    """True when the stage's room is read by measuring (not written by ``sgdata rooms``)."""
    root = room_prim(stage)
    if not root.IsValid() or not root.HasAttribute("sgdata:roomSize"):
        return True
    attr = root.GetAttribute(MEASURED)
    return bool(attr) and attr.Get() == "measured"


def measure_stage(
    stage: Usd.Stage,
    path: Path,
    *,
    classes: dict[str, Dynamics] | None = None,
    catalog: Catalog | None = None,
) -> MeasuredRoom:
    """The room of any stage, every missing ``sgdata:*`` value measured from its geometry.

    Args:
        stage: the composed stage.
        path: its file, named in messages and giving the default room id (its stem).
        classes: dynamics of classes the catalog lacks (the user's class file).
        catalog: the catalog giving known classes' dynamics (the shipped one when ``None``).

    Raises:
        UsdError: no room prim, an object without geometry, a class neither in the catalog nor
            in ``classes`` without ``sgdata:dynamics``, a bad ``sgdata:support`` target, or
            supports (or attachments) that go round in a circle.
    """
    root = room_prim(stage)
    if not root.IsValid():
        raise UsdError(f"{path}: no /Room prim and no default prim; cannot find the room")
    catalog = catalog or load_catalog()
    inferred: list[str] = []
    geometry = stage_geometry(stage, path)
    authored_origin = _vec(root, ROOM_ORIGIN, (0.0, 0.0, 0.0))
    size = (
        root.GetAttribute("sgdata:roomSize").Get() if root.HasAttribute("sgdata:roomSize") else None
    )
    if size is not None:
        shift = np.zeros(3)
        width, depth, height = (float(v) for v in size)
    else:
        lo, hi = _shell(geometry.structure, geometry.objects)
        shift = lo
        width, depth, height = (float(v) for v in hi - lo)
        inferred.append(f"room size {width:.2f} x {depth:.2f} x {height:.2f} m (from structure)")
    origin = tuple(float(a + b) for a, b in zip(authored_origin, shift, strict=True))
    structure = [_shifted(m.vertices, shift) for m in geometry.structure]
    tris = [v[m.faces] for v, m in zip(structure, geometry.structure, strict=True)]
    structure_tris = np.concatenate(tris) if tris else np.zeros((0, 3, 3))

    paths: dict[int, str] = {}
    boxes = []
    for og in geometry.objects:
        key = og.mesh.name
        prim = stage.GetPrimAtPath(key)
        paths[og.instance] = key
        if not prim.HasAttribute("sgdata:instance"):
            inferred.append(f"{key}: instance {og.instance} (by prim path order)")
        boxes.append((og, prim, _object_box(path, og, shift)))
    by_path = {p: i for i, p in paths.items()}
    objects = []
    for og, prim, (placement, obj_size) in boxes:
        key = og.mesh.name
        cls = (
            str(prim.GetAttribute("sgdata:class").Get() or "")
            if prim.HasAttribute("sgdata:class")
            else ""
        )
        if not cls:
            raise UsdError(f"{path}: {key} lacks attribute sgdata:class")
        dynamics = _dynamics(path, prim, cls, classes or {}, catalog, inferred)
        objects.append(
            SceneObject(
                instance=og.instance,
                class_name=cls,
                dynamics=dynamics,
                size=obj_size,
                placement=placement,
                variant=int(_value(prim, "sgdata:variant", 0)),
                color=_color(prim, og.mesh),
                support=_target(path, prim, "sgdata:support", by_path),
                attached_to=_target(path, prim, "sgdata:attachedTo", by_path),
            )
        )
    objects = _infer_supports(objects, stage, paths, inferred)
    _check_acyclic(path, objects, paths)
    shell = Room(
        room_id=str(_value(root, "sgdata:roomId", path.stem)),
        room_type=str(_value(root, "sgdata:roomType", "custom")),
        width=width,
        depth=depth,
        height=height,
        seed=int(_value(root, "sgdata:seed", 0)),
        door=Opening("south", width / 2, min(DEFAULT_DOOR, width), 0.0, min(DOOR_TOP, height)),
        objects=tuple(objects),
    )
    door = _authored_door(path, root)
    if door is None:
        door = _find_door(structure_tris, shell)
        how = "a gap in the walls"
        if door is None:
            door, how = _default_door(shell), "no gap found: virtual entry"
        inferred.append(
            f"door on the {door.wall} wall at {door.center:.2f} m, {door.width:.2f} m wide ({how})"
        )
    return MeasuredRoom(replace(shell, door=door), origin, paths, tuple(inferred))  # type: ignore[arg-type]


# ------------------------------------------------------------------------------ the shell


def _shifted(vertices: np.ndarray, shift: np.ndarray) -> np.ndarray:
    return np.asarray(vertices, dtype=np.float64) - shift


def _shell(structure: tuple[MeshData, ...], objects: tuple[ObjectGeometry, ...]) -> tuple:
    """Low and high corners of the room's interior (floor top to ceiling, wall to wall)."""
    tris = [np.asarray(m.vertices)[m.faces] for m in structure if len(m.faces)]
    if not tris:  # no structure: the objects' bounds, 2.5 m high
        points = [o.world_vertices() for o in objects if len(o.mesh.vertices)]
        if not points:
            raise UsdError("stage has neither structure nor object geometry to measure")
        allp = np.concatenate(points)
        lo, hi = allp.min(axis=0), allp.max(axis=0)
        lo[2] = 0.0 if lo[2] > 0 else lo[2]
        return lo, np.array([hi[0], hi[1], max(hi[2], lo[2] + 2.5)])
    t = np.concatenate(tris)
    normal = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])
    area = np.linalg.norm(normal, axis=1)
    keep = area > 1e-12
    t, normal, area = t[keep], normal[keep] / area[keep, None], area[keep] / 2
    centre = t.mean(axis=1)
    allp = t.reshape(-1, 3)
    amin, amax = allp.min(axis=0), allp.max(axis=0)
    up = normal[:, 2] > 0.9
    z0 = float(centre[up, 2].min()) if up.any() else float(amin[2])
    mid = (amin + amax) / 2
    lo, hi = amin.copy(), amax.copy()
    for axis in (0, 1):
        vertical = np.abs(normal[:, axis]) > 0.9
        planes: dict[float, float] = {}
        for c, a in zip(np.round(centre[vertical, axis], 3), area[vertical], strict=True):
            planes[float(c)] = planes.get(float(c), 0.0) + float(a)
        low = {c: a for c, a in planes.items() if c < mid[axis]}
        high = {c: a for c, a in planes.items() if c > mid[axis]}
        if low:
            lo[axis] = max(c for c, a in low.items() if a >= _PLANE_SHARE * max(low.values()))
        if high:
            hi[axis] = min(c for c, a in high.items() if a >= _PLANE_SHARE * max(high.values()))
    # the ceiling: the lowest large down-facing plane (a door's lintel is not one), else the top
    down = (normal[:, 2] < -0.9) & (centre[:, 2] > z0 + 1.0)
    ceilings: dict[float, float] = {}
    for c, a in zip(np.round(centre[down, 2], 3), area[down], strict=True):
        ceilings[float(c)] = ceilings.get(float(c), 0.0) + float(a)
    floor_area = float((hi[0] - lo[0]) * (hi[1] - lo[1]))
    large = [c for c, a in ceilings.items() if a >= 0.5 * floor_area]
    z1 = min(large) if large else float(amax[2])
    if z1 <= z0 + 0.5:
        z1 = z0 + 2.5
    lo[2], hi[2] = z0, z1
    return lo, hi


def _authored_door(path: Path, root: Usd.Prim) -> Opening | None:
    if not root.HasAttribute("sgdata:door:wall"):
        return None
    wall = str(root.GetAttribute("sgdata:door:wall").Get())
    if wall not in WALLS:
        raise UsdError(
            f"{path}: {root.GetPath()} sgdata:door:wall is {wall!r}; expected one of {WALLS}"
        )
    try:
        return Opening(
            wall=wall,
            center=float(root.GetAttribute("sgdata:door:center").Get()),
            width=float(root.GetAttribute("sgdata:door:width").Get()),
            bottom=float(_value(root, "sgdata:door:bottom", 0.0)),
            top=float(root.GetAttribute("sgdata:door:top").Get()),
        )
    except TypeError:
        raise UsdError(
            f"{path}: {root.GetPath()} has sgdata:door:wall but lacks door:center, width or top"
        ) from None


def _wall_axes(wall: str, room: Room) -> tuple[int, int, float, float]:
    """(along axis, across axis, the wall's coordinate across, its length) of a wall."""
    return {
        "south": (0, 1, 0.0, room.width),
        "north": (0, 1, room.depth, room.width),
        "west": (1, 0, 0.0, room.depth),
        "east": (1, 0, room.width, room.depth),
    }[wall]


def _find_door(tris: np.ndarray, room: Room) -> Opening | None:
    """The widest gap through a wall at every probe height, or ``None``."""
    best = None
    for wall in WALLS:
        along, across, at, length = _wall_axes(wall, room)
        band = np.abs(tris[:, :, across] - at).max(axis=1) < 0.6 if len(tris) else np.zeros(0, bool)
        wall_tris = tris[band]
        if not len(wall_tris):
            continue  # an open side is not a door
        covered: list[tuple[float, float]] = []
        for z in (0.5, 1.0, 1.5):
            covered += _slice(wall_tris, along, z)
        for a, b in _gaps(covered, 0.0, length):
            if b - a >= MIN_DOOR and (best is None or b - a > best[2] - best[1]):
                best = (wall, a, b, wall_tris, along)
    if best is None:
        return None
    wall, a, b, wall_tris, along = best
    lo_along = wall_tris[:, :, along].min(axis=1)
    hi_along = wall_tris[:, :, along].max(axis=1)
    low_z = wall_tris[:, :, 2].min(axis=1)
    over = (lo_along < b) & (hi_along > a) & (low_z > 1.5)
    top = float(low_z[over].min()) if over.any() else room.height
    return Opening(wall, (a + b) / 2, b - a, 0.0, min(top, room.height))


def _slice(tris: np.ndarray, along: int, z: float) -> list[tuple[float, float]]:
    """Intervals along ``along`` that the triangles cover at height ``z``."""
    out = []
    for t in tris:
        zs = t[:, 2]
        if zs.min() > z or zs.max() < z:
            continue
        points = []
        for i, j in ((0, 1), (1, 2), (2, 0)):
            za, zb = zs[i], zs[j]
            if za == zb:
                if za == z:
                    points += [t[i, along], t[j, along]]
                continue
            s = (z - za) / (zb - za)
            if 0.0 <= s <= 1.0:
                points.append(t[i, along] + s * (t[j, along] - t[i, along]))
        if points:
            out.append((float(min(points)), float(max(points))))
    return out


def _gaps(
    intervals: list[tuple[float, float]], start: float, end: float
) -> list[tuple[float, float]]:
    """The stretches of [start, end] no interval covers (1 mm slack)."""
    gaps, reach = [], start
    for a, b in sorted(intervals):
        if a > reach + 1e-3:
            gaps.append((reach, min(a, end)))
        reach = max(reach, b)
    if reach < end - 1e-3:
        gaps.append((reach, end))
    return [(a, b) for a, b in gaps if b > a]


def _default_door(room: Room) -> Opening:
    """A virtual entry in the middle of the longest free stretch of wall (south wins ties)."""
    best = ("south", room.width / 2, room.width / 2)  # nothing free anywhere: the south middle
    for wall in WALLS:
        along, across, at, length = _wall_axes(wall, room)
        blocked = []
        for obj in room.objects:
            lo, hi = obj.world_aabb()
            if min(abs(lo[across] - at), abs(hi[across] - at)) < DOOR_CLEARANCE or (
                lo[across] <= at <= hi[across]
            ):
                blocked.append((float(lo[along]), float(hi[along])))
        for a, b in _gaps(blocked, 0.0, length):
            if b - a > best[2] - best[1] + 1e-9:  # strictly longer: WALLS order breaks ties
                best = (wall, a, b)
    wall, a, b = best
    width = min(DEFAULT_DOOR, b - a) if b > a else min(DEFAULT_DOOR, room.width)
    return Opening(wall, (a + b) / 2, width, 0.0, min(DOOR_TOP, room.height))


# ---------------------------------------------------------------------------- the objects


def _object_box(
    path: Path, og: ObjectGeometry, shift: np.ndarray
) -> tuple[Placement, tuple[float, float, float]]:
    """Placement (bottom centre, yaw) and size of an object's box in its heading."""
    if not len(og.mesh.vertices):
        raise UsdError(f"{path}: {og.mesh.name} has no geometry to measure (no mesh or gprim)")
    m = og.matrix
    yaw = math.atan2(m[1, 0], m[0, 0]) if math.hypot(m[0, 0], m[1, 0]) > 1e-9 else 0.0
    world = og.world_vertices() - shift
    c, s = math.cos(yaw), math.sin(yaw)
    local = world @ np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])  # rotate by -yaw
    lo, hi = local.min(axis=0), local.max(axis=0)
    cx, cy = (lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2
    size = tuple(float(f"{v:.6g}") for v in hi - lo)
    placement = Placement(c * cx - s * cy, s * cx + c * cy, float(lo[2]), yaw)
    return placement, size  # type: ignore[return-value]


def _dynamics(
    path: Path,
    prim: Usd.Prim,
    cls: str,
    classes: dict[str, Dynamics],
    catalog: Catalog,
    inferred: list[str],
) -> Dynamics:
    authored = _value(prim, "sgdata:dynamics", None)
    if authored is not None:
        try:
            return Dynamics(str(authored))
        except ValueError:
            raise UsdError(
                f"{path}: {prim.GetPath()} sgdata:dynamics is {authored!r}; "
                f"expected static, low or high"
            ) from None
    if cls in classes:
        found = classes[cls]
    elif cls in catalog:
        found = catalog[cls].dynamics
    else:
        raise UsdError(
            f"{path}: {prim.GetPath()} sgdata:class {cls!r} is not a catalog class; "
            f"list it with its dynamics in a class file (--classes MAP.toml)"
        )
    inferred.append(f"{prim.GetPath()}: dynamics {found} (class {cls})")
    return Dynamics(found)


def _target(path: Path, prim: Usd.Prim, name: str, by_path: dict[str, int]) -> int | None:
    rel = prim.GetRelationship(name)
    targets = rel.GetTargets() if rel else []
    if not targets:
        return None
    if len(targets) > 1 or str(targets[0]) not in by_path:
        raise UsdError(
            f"{path}: {prim.GetPath()} {name} targets {[str(t) for t in targets]}; "
            f"expected one object prim (one with sgdata:class)"
        )
    return by_path[str(targets[0])]


def _infer_supports(
    objects: list[SceneObject], stage: Usd.Stage, paths: dict[int, str], inferred: list[str]
) -> list[SceneObject]:
    """Objects whose support is not authored get the one their geometry rests on."""
    out = []
    for obj in objects:
        prim = stage.GetPrimAtPath(paths[obj.instance])
        if prim.GetRelationship("sgdata:support") or obj.placement.z < _FLOOR_BAND:
            out.append(obj)
            continue
        support = _support_of(obj, objects)
        if support is not None:
            by = {o.instance: o for o in objects}
            inferred.append(
                f"{paths[obj.instance]}: rests on {paths[support]} ({by[support].class_name})"
            )
            obj = obj.moved_to(obj.placement, support)
        out.append(obj)
    return out


def _check_acyclic(path: Path, objects: list[SceneObject], paths: dict[int, str]) -> None:
    """Refuse objects that rest on (or hang from) each other in a circle: nothing would hold
    them up, and moving one would move the others without end."""
    for link in ("support", "attached_to"):
        up = {o.instance: getattr(o, link) for o in objects}
        for start in up:
            seen, at = [start], up[start]
            while at is not None and at not in seen:
                seen.append(at)
                at = up.get(at)
            if at is not None:
                circle = seen[seen.index(at) :] + [at]
                name = "sgdata:support" if link == "support" else "sgdata:attachedTo"
                raise UsdError(
                    f"{path}: {' -> '.join(paths[i] for i in circle)}: {name} goes round in a "
                    f"circle; expected every chain to end at an object on the floor or a wall: "
                    f"remove {name} from one of them"
                )


def _support_of(obj: SceneObject, objects: list[SceneObject]) -> int | None:
    p = obj.placement
    on, inside = [], []
    for other in objects:
        if other.instance == obj.instance:
            continue
        q = other.placement
        c, s = math.cos(q.yaw), math.sin(q.yaw)
        dx, dy = p.x - q.x, p.y - q.y
        lx, ly = c * dx + s * dy, -s * dx + c * dy  # obj's centre in other's frame
        w, d, h = other.size
        if abs(lx) > w / 2 + 0.01 or abs(ly) > d / 2 + 0.01:
            continue
        top = q.z + h
        if top - 0.01 <= p.z <= top + REST_GAP:
            on.append((top, other.instance))
        elif q.z <= p.z < top:
            inside.append((w * d * h, other.instance))
    if on:
        return max(on)[1]
    if inside:
        return min(inside)[1]
    return None


def _color(prim: Usd.Prim, mesh: MeshData) -> tuple[float, float, float]:
    authored = _value(prim, "sgdata:color", None)
    values = (
        authored
        if authored is not None
        else (mesh.face_colors.mean(axis=0) if len(mesh.face_colors) else (0.7, 0.7, 0.7))
    )
    a, b, c = (float(str(np.float32(v))) for v in values)
    return (a, b, c)


def _value(prim: Usd.Prim, name: str, default: object) -> object:
    attr = prim.GetAttribute(name)
    value = attr.Get() if attr else None
    return default if value is None else value


def _vec(prim: Usd.Prim, name: str, default: tuple[float, float, float]) -> np.ndarray:
    return np.array(_value(prim, name, default), dtype=np.float64)
