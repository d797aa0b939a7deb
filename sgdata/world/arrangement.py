"""Where furniture belongs: chairs at tables, desks and walls, footstools by the seating.

A floor class lists its ``anchors`` in the catalog, in order of preference: classes it stands
at, facing one of their :meth:`~sgdata.world.catalog.ClassSpec.sides_to_stand_at` square on
(a chair at a table), and ``"wall"``, its back to a wall (a chair or a bin along a wall). The
room generator and the dynamics sampler draw spots in tiers (:func:`tier_of`): at an anchor
object, then at a wall, and only in the last tries anywhere free. Every spot faces its anchor
square on give or take a small yaw noise (sigma :data:`ANCHOR_YAW_SIGMA_DEG`, clipped at
3 sigma) and keeps a small gap to it (:data:`ANCHOR_GAP`, :data:`WALL_GAP`).

:func:`standing_at` reads the arrangement back: the anchor an object stands at, if any. The
dynamics sampler moves what stands at a moved anchor along with it (chairs follow their
table), and the tests and statistics count chairs at tables, desks and walls with it.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence

import numpy as np

from sgdata.world.catalog import SIDES, WALL, Catalog, ClassSpec
from sgdata.world.placement import wall_yaw
from sgdata.world.scene import WALLS, Placement, Room, SceneObject

__all__ = [
    "ANCHOR_GAP",
    "ANCHOR_YAW_SIGMA_DEG",
    "FREE",
    "STAND_GAP",
    "STAND_YAW_DEG",
    "WALL_GAP",
    "anchor_objects",
    "draw_spot",
    "facing",
    "spot_at",
    "spot_at_wall",
    "standing_at",
    "stands_at_object",
    "tier_of",
    "tiers_for",
]

ANCHOR_GAP = (0.03, 0.2)  # metres between an object and the furniture it stands at
WALL_GAP = (0.01, 0.08)  # metres between an object's back and the wall
ANCHOR_YAW_SIGMA_DEG = 4.0  # yaw noise about square on, clipped at 3 sigma
# standing_at: the largest gap and yaw error that still count as standing at an anchor (the
# drawn ones plus a margin)
STAND_GAP = 0.3
STAND_YAW_DEG = 3 * ANCHOR_YAW_SIGMA_DEG + 1.0
FREE = "free"  # the last tier: anywhere free, no anchor
FREE_SHARE = 0.1  # share of the tries (at least one) left for anywhere free

# outward normals of an object's sides (catalog SIDES: front, right, back, left) in its local
# frame, where the front faces -Y
_NORMALS = dict(zip(SIDES, ((0.0, -1.0), (1.0, 0.0), (0.0, 1.0), (-1.0, 0.0)), strict=True))
# inward normals of the walls (WALLS: south y = 0, east x = width, north y = depth, west x = 0)
_WALL_NORMALS = {"south": (0.0, 1.0), "east": (-1.0, 0.0), "north": (0.0, -1.0), "west": (1.0, 0.0)}


def facing(placement: Placement) -> np.ndarray:
    """The unit world direction an object's front (local -Y) looks along."""
    return np.array([math.sin(placement.yaw), -math.cos(placement.yaw)])


def _yaw_facing(direction: Sequence[float]) -> float:
    """The yaw that turns an object's front towards ``direction`` (inverse of :func:`facing`)."""
    return math.atan2(direction[0], -direction[1])


def _yaw_noise(rng: np.random.Generator) -> float:
    sigma = math.radians(ANCHOR_YAW_SIGMA_DEG)
    return float(np.clip(rng.normal(0.0, sigma), -3 * sigma, 3 * sigma))


def anchor_objects(
    spec: ClassSpec, objects: Iterable[SceneObject], catalog: Catalog, *, exclude: set[int]
) -> list[tuple[SceneObject, str]]:
    """Every (object, side) among ``objects`` that a ``spec`` object may stand at, in the
    objects' order; objects in ``exclude`` (itself, what moves with it) are left out."""
    wanted = {name for name in spec.anchors if name != WALL}
    out = []
    for other in objects:
        if other.class_name in wanted and other.instance not in exclude:
            out += [(other, side) for side in catalog[other.class_name].sides_to_stand_at()]
    return out


def tiers_for(spec: ClassSpec, has_anchor_objects: bool) -> tuple[str, ...]:
    """The tiers a ``spec`` object's spots are drawn from, in order: ``"object"`` (when one of
    its anchor classes is there), ``"wall"`` (when it lists the wall) and :data:`FREE`."""
    tiers = ["object"] if has_anchor_objects else []
    if WALL in spec.anchors:
        tiers.append(WALL)
    return (*tiers, FREE)


def tier_of(attempt: int, tries: int, tiers: Sequence[str]) -> str:
    """The tier of placement attempt ``attempt`` of ``tries``: the anchored tiers share the
    tries in order, the last tenth (at least one try) goes anywhere free."""
    anchored = [t for t in tiers if t != FREE]
    free = max(1, int(tries * FREE_SHARE))
    if not anchored or attempt >= tries - free:
        return FREE
    return anchored[attempt * len(anchored) // (tries - free)]


def draw_spot(
    rng: np.random.Generator,
    tier: str,
    anchors: Sequence[tuple[SceneObject, str]],
    room: Room,
    size: tuple[float, float, float],
) -> Placement | None:
    """A spot of ``tier``: at a side of one of ``anchors`` drawn at random (``"object"``), back
    to a wall (``"wall"``), or ``None`` for :data:`FREE` (the caller's own free draw)."""
    if tier == "object" and anchors:
        anchor, side = anchors[int(rng.integers(len(anchors)))]
        return spot_at(rng, anchor, side, size)
    if tier == WALL:
        return spot_at_wall(rng, room, size)
    return None


def spot_at(
    rng: np.random.Generator, anchor: SceneObject, side: str, size: tuple[float, float, float]
) -> Placement:
    """A floor spot at ``side`` of ``anchor`` for an object of ``size``, facing the anchor.

    The object stands square to that side (give or take the yaw noise), a gap of
    :data:`ANCHOR_GAP` away, anywhere along the side that keeps it within the side's span.
    """
    noise = _yaw_noise(rng)
    nx, ny = _NORMALS[side]
    aw, ad, _ = anchor.size
    w, d, _ = size
    c, s = abs(math.cos(noise)), abs(math.sin(noise))
    half_n = (d * c + w * s) / 2  # the object's half extent towards the anchor
    half_t = (w * c + d * s) / 2  # ... and along the side
    span = aw if ny else ad
    slack = max(0.0, span / 2 - half_t)
    reach = (ad if ny else aw) / 2 + float(rng.uniform(*ANCHOR_GAP)) + half_n
    offset = float(rng.uniform(-slack, slack))
    local = np.array([nx * reach - ny * offset, ny * reach + nx * offset, 0.0, 1.0])
    world = anchor.placement.matrix() @ local
    rotation = anchor.placement.matrix()[:2, :2]
    yaw = _yaw_facing(rotation @ np.array([-nx, -ny])) + noise
    return Placement(float(world[0]), float(world[1]), 0.0, yaw)


def spot_at_wall(
    rng: np.random.Generator, room: Room, size: tuple[float, float, float]
) -> Placement:
    """A floor spot with the object's back to a wall (drawn by wall length), a gap of
    :data:`WALL_GAP` from it, facing into the room give or take the yaw noise."""
    lengths = np.array([room.wall_length(w) for w in WALLS])
    pick = float(rng.uniform(0.0, lengths.sum()))
    wall = WALLS[min(int(np.searchsorted(np.cumsum(lengths), pick)), len(WALLS) - 1)]
    noise = _yaw_noise(rng)
    w, d, _ = size
    c, s = abs(math.cos(noise)), abs(math.sin(noise))
    half_n, half_t = (d * c + w * s) / 2, (w * c + d * s) / 2
    length = room.wall_length(wall)
    along = float(rng.uniform(min(half_t, length / 2), max(length - half_t, length / 2)))
    away = float(rng.uniform(*WALL_GAP)) + half_n
    x, y = {
        "south": (along, away),
        "north": (along, room.depth - away),
        "west": (away, along),
        "east": (room.width - away, along),
    }[wall]
    return Placement(x, y, 0.0, wall_yaw(wall) + noise)


def standing_at(
    obj: SceneObject, objects: Iterable[SceneObject], room: Room, catalog: Catalog
) -> SceneObject | str | None:
    """The anchor ``obj`` stands at: an object of one of its anchor classes whose side it
    faces within :data:`STAND_YAW_DEG`, no more than :data:`STAND_GAP` away and overlapping
    that side's span; else ``"wall"`` when it lists the wall and stands with its back to one
    as closely; else ``None`` (it stands anywhere free, or its class has no anchors)."""
    if obj.class_name not in catalog or obj.support is not None:
        return None
    spec = catalog[obj.class_name]
    pool = list(objects)
    for name in spec.anchors:
        if name == WALL:
            if _at_wall(obj, room):
                return WALL
            continue
        for other in pool:
            if other.class_name == name and stands_at_object(obj, other, catalog):
                return other
    return None


def stands_at_object(obj: SceneObject, anchor: SceneObject, catalog: Catalog) -> bool:
    """Does ``obj`` stand at one of ``anchor``'s sides, facing it (as :func:`standing_at`)?"""
    if obj.instance == anchor.instance or anchor.class_name not in catalog:
        return False
    sides = catalog[anchor.class_name].sides_to_stand_at()
    return any(_at_side(obj, anchor, side) for side in sides)


def _at_side(obj: SceneObject, anchor: SceneObject, side: str) -> bool:
    """Does ``obj`` stand at ``side`` of ``anchor``, facing it?"""
    inverse = np.linalg.inv(anchor.placement.matrix())
    corners = (inverse[:2, :2] @ obj.corners()[:, :2].T).T + inverse[:2, 3]
    look = inverse[:2, :2] @ facing(obj.placement)
    normal = np.array(_NORMALS[side])
    if float(look @ -normal) < math.cos(math.radians(STAND_YAW_DEG)):
        return False
    aw, ad, _ = anchor.size
    front_or_back = bool(normal[1])
    half_n = (ad if front_or_back else aw) / 2  # the anchor's half extent along the normal
    half_t = (aw if front_or_back else ad) / 2  # ... and along the side
    gap = float((corners @ normal).min()) - half_n
    tangent = np.array([-normal[1], normal[0]])
    along = corners @ tangent
    overlaps = along.max() > -half_t and along.min() < half_t
    return -0.01 <= gap <= STAND_GAP and bool(overlaps)


def _at_wall(obj: SceneObject, room: Room) -> bool:
    """Does ``obj`` stand with its back to a wall, facing into the room?"""
    look = facing(obj.placement)
    corners = obj.corners()[:, :2]
    for wall, (nx, ny) in _WALL_NORMALS.items():
        if float(look @ np.array([nx, ny])) < math.cos(math.radians(STAND_YAW_DEG)):
            continue
        distance = {
            "south": corners[:, 1].min(),
            "north": room.depth - corners[:, 1].max(),
            "west": corners[:, 0].min(),
            "east": room.width - corners[:, 0].max(),
        }[wall]
        if float(distance) <= STAND_GAP:
            return True
    return False
