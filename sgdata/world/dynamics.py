"""Dynamics sampler: layouts of a room in which objects moved as people move them.

Rules (paper §V-A.3, DESIGN §4):
- static objects never move;
- low-dynamic objects move locally: a new spot within ``radius_factor * r(B)`` of the old one
  (r(B) = radius of the bounding sphere of the object's box), on the same support, with a yaw
  noise of sigma ``yaw_sigma_deg`` clipped at 3 sigma (the authors used up to 10 degrees);
- high-dynamic objects relocate anywhere they fit: small objects on any surface of a class
  that may hold them, with a random yaw; furniture where its class belongs first
  (:mod:`sgdata.world.arrangement`: a chair at a table, a desk or a wall, facing it; a stool
  or an ottoman by the seating), and only in its last tries anywhere free on the floor;
- what rests on (or is attached to) a moved object moves with it, rigidly, and so does the
  furniture standing at it (the chairs at a table: rule ``"follow"``);
- every layout is physically valid (see :mod:`sgdata.world.room_checks`) and keeps the door clear;
  an object whose move fails after ``tries`` attempts stays put, and that is recorded.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from sgdata.errors import ConfigError
from sgdata.seeds import layout_seed, rng_for
from sgdata.world.arrangement import (
    FREE,
    anchor_objects,
    draw_spot,
    stands_at_object,
    tier_of,
    tiers_for,
)
from sgdata.world.catalog import Catalog
from sgdata.world.placement import (
    WorldSurface,
    colliding,
    inside_room,
    place_on_surface,
    surfaces_for,
)
from sgdata.world.poses import PosesConfig
from sgdata.world.room_checks import resting_surface
from sgdata.world.rooms import door_keepout
from sgdata.world.scene import Dynamics, Placement, Room, SceneObject

__all__ = [
    "ClassDynamics",
    "DynamicsConfig",
    "Layout",
    "LayoutSummary",
    "Move",
    "sample_layout",
    "sample_layouts",
    "summarize_layouts",
]


@dataclass(frozen=True)
class ClassDynamics:
    """Per-class overrides of the global knobs (None keeps the global value)."""

    move_chance: float | None = None
    radius_factor: float | None = None
    yaw_sigma_deg: float | None = None


@dataclass(frozen=True)
class DynamicsConfig:
    """Knobs of the sampler; validated on construction."""

    # chance that an object of each category moves in a layout (static is always 0)
    low_move_chance: float = 0.5
    high_move_chance: float = 0.8
    # low-dynamic displacement bound, as a multiple of r(B)
    radius_factor: float = 1.0
    # low-dynamic yaw noise sigma in degrees (clipped at 3 sigma)
    yaw_sigma_deg: float = 10.0
    # placement attempts per object before it stays put
    tries: int = 40
    # a floor move is refused if it leaves fewer reachable grid cells than this share of the
    # base layout's (furniture may block a cell, not cut the room in two)
    min_reachable_share: float = 0.85
    # per-class overrides, by catalog class name
    classes: dict[str, ClassDynamics] = field(default_factory=dict)

    def __post_init__(self) -> None:
        for name in ("low_move_chance", "high_move_chance"):
            value = getattr(self, name)
            if not 0.0 <= value <= 1.0:
                raise ConfigError(f"dynamics.{name} must be within [0, 1], got {value}")
        if self.radius_factor < 0:
            raise ConfigError(f"dynamics.radius_factor must be >= 0, got {self.radius_factor}")
        if self.yaw_sigma_deg < 0:
            raise ConfigError(f"dynamics.yaw_sigma_deg must be >= 0, got {self.yaw_sigma_deg}")
        if not 0.0 <= self.min_reachable_share <= 1.0:
            share = self.min_reachable_share
            raise ConfigError(f"dynamics.min_reachable_share must be within [0, 1], got {share}")
        if self.tries < 1:
            raise ConfigError(f"dynamics.tries must be >= 1, got {self.tries}")
        for cls, override in self.classes.items():
            chance = override.move_chance
            if chance is not None and not 0.0 <= chance <= 1.0:
                raise ConfigError(f"dynamics.classes.{cls}.move_chance must be within [0, 1]")

    def chance(self, obj: SceneObject) -> float:
        """Chance that ``obj`` moves in a layout."""
        if obj.dynamics is Dynamics.STATIC:
            return 0.0
        override = self.classes.get(obj.class_name, ClassDynamics()).move_chance
        if override is not None:
            return override
        return self.low_move_chance if obj.dynamics is Dynamics.LOW else self.high_move_chance

    def radius(self, obj: SceneObject) -> float:
        """Largest low-dynamic displacement of ``obj``: factor times r(B)."""
        factor = self.classes.get(obj.class_name, ClassDynamics()).radius_factor
        return (self.radius_factor if factor is None else factor) * bounding_radius(obj)

    def yaw_sigma(self, obj: SceneObject) -> float:
        """Low-dynamic yaw noise sigma of ``obj`` in radians."""
        sigma = self.classes.get(obj.class_name, ClassDynamics()).yaw_sigma_deg
        return math.radians(self.yaw_sigma_deg if sigma is None else sigma)


@dataclass(frozen=True)
class Move:
    """What happened to one object in a layout."""

    instance: int
    class_name: str
    # "low" | "high" | "carried" (moved because its support moved) | "follow" (moved with the
    # furniture it stands at: a chair with its table)
    rule: str
    before: Placement
    after: Placement
    support_before: int | None
    support_after: int | None
    moved: bool  # False: a move was drawn but no valid spot was found, so it stayed put

    @property
    def displacement(self) -> float:
        """Horizontal distance travelled, metres."""
        return math.hypot(self.after.x - self.before.x, self.after.y - self.before.y)

    def as_dict(self) -> dict[str, object]:
        """Plain-data form, as stored in the layout layer's customData."""
        return {
            "instance": self.instance,
            "class": self.class_name,
            "rule": self.rule,
            "from": [self.before.x, self.before.y, self.before.z, self.before.yaw],
            "to": [self.after.x, self.after.y, self.after.z, self.after.yaw],
            "fromSupport": -1 if self.support_before is None else self.support_before,
            "toSupport": -1 if self.support_after is None else self.support_after,
            "moved": self.moved,
        }


@dataclass(frozen=True)
class Layout:
    """One arrangement of a room; layout 0 is the base arrangement."""

    index: int
    seed: int
    room: Room
    moves: tuple[Move, ...]


def bounding_radius(obj: SceneObject) -> float:
    """r(B): radius of the smallest sphere around the object's box (half its diagonal)."""
    return 0.5 * math.sqrt(sum(s * s for s in obj.size))


def sample_layouts(
    base: Room,
    count: int,
    seed: int,
    catalog: Catalog,
    config: DynamicsConfig | None = None,
    *,
    poses: PosesConfig | None = None,
) -> list[Layout]:
    """Layouts 0 .. count-1 of ``base``; layout 0 is ``base`` itself, each other one is
    drawn from its own seed derived from ``seed`` and its index. Reachability is kept on the
    run's pose grid (``poses``)."""
    if count < 1:
        raise ConfigError(f"layout count must be >= 1, got {count}")
    config = config or DynamicsConfig()
    layouts = [Layout(0, layout_seed(seed, 0), base, ())]
    for index in range(1, count):
        layouts.append(
            sample_layout(base, index, layout_seed(seed, index), catalog, config, poses=poses)
        )
    return layouts


def sample_layout(
    base: Room,
    index: int,
    seed: int,
    catalog: Catalog,
    config: DynamicsConfig | None = None,
    *,
    poses: PosesConfig | None = None,
) -> Layout:
    """One layout of ``base`` drawn from ``seed``."""
    config = config or DynamicsConfig()
    sampler = _LayoutSampler(base, catalog, config, poses or PosesConfig(), rng_for(seed))
    room, moves = sampler.run()
    return Layout(index, seed, room, tuple(moves))


class _LayoutSampler:
    """Moves the objects of one layout, keeping the arrangement valid after every move."""

    def __init__(
        self,
        base: Room,
        catalog: Catalog,
        config: DynamicsConfig,
        poses: PosesConfig,
        rng: np.random.Generator,
    ) -> None:
        self.base = base
        self.poses = poses
        self.catalog = catalog
        self.config = config
        self.rng = rng
        self.base_objects = base.by_instance()
        self.objects: dict[int, SceneObject] = dict(self.base_objects)
        self.keepout = door_keepout(base)
        children: dict[int, list[int]] = {}
        for obj in base.objects:
            parent = obj.support if obj.support is not None else obj.attached_to
            if parent is not None:
                children.setdefault(parent, []).append(obj.instance)
        self.children = children
        self.followed: set[int] = set()  # moved with the furniture they stand at
        self.min_reachable = config.min_reachable_share * len(poses.grid(base).cells)

    def run(self) -> tuple[Room, list[Move]]:
        order = {Dynamics.LOW: 0, Dynamics.HIGH: 1}
        movers = [o for o in self.base.objects if o.dynamics is not Dynamics.STATIC]
        # furniture before the small things on it; the draw for each happens in this order
        movers.sort(key=lambda o: (order[o.dynamics], o.support is not None, o.instance))
        moves: dict[int, Move] = {}
        for obj in movers:
            if self.rng.random() >= self.config.chance(obj):
                continue
            current = self.objects[obj.instance]
            if current.dynamics is Dynamics.LOW:
                moved = self._try(current, self._low_candidate)
                rule = "low"
            else:
                moved = self._try(current, self._high_candidate)
                rule = "high"
            self._record(moves, current, self.objects[obj.instance], rule, moved)
        room = self.base.with_objects([self.objects[o.instance] for o in self.base.objects])
        self._record_carried(moves, room)
        # an object may have been carried or followed after its own move: record where it ended
        final = room.by_instance()
        return room, [
            replace(moves[k], after=final[k].placement, support_after=final[k].support)
            for k in sorted(moves)
        ]

    def _record(
        self,
        moves: dict[int, Move],
        before: SceneObject,
        after: SceneObject,
        rule: str,
        moved: bool,
    ) -> None:
        # "before" is always the base arrangement, even for an object carried earlier
        original = self.base_objects[before.instance]
        earlier = moves.get(before.instance)
        moves[before.instance] = Move(
            before.instance,
            before.class_name,
            rule,
            original.placement,
            after.placement,
            original.support,
            after.support,
            moved or (earlier.moved if earlier else False),
        )

    def _record_carried(self, moves: dict[int, Move], room: Room) -> None:
        for obj in room.objects:
            original = self.base_objects[obj.instance]
            if obj.instance in moves or obj.placement == original.placement:
                continue
            moves[obj.instance] = Move(
                obj.instance,
                obj.class_name,
                "follow" if obj.instance in self.followed else "carried",
                original.placement,
                obj.placement,
                original.support,
                obj.support,
                True,
            )

    def _descendants(self, instance: int) -> list[int]:
        out, stack = [], list(self.children.get(instance, []))
        while stack:
            child = stack.pop()
            out.append(child)
            stack.extend(self.children.get(child, []))
        return out

    def _followers(self, obj: SceneObject) -> list[int]:
        """Furniture standing at ``obj`` (chairs at a table), and at those, transitively."""
        found: list[int] = []
        frontier = [obj]
        while frontier:
            anchor = frontier.pop(0)
            for other in self.objects.values():  # base order: deterministic
                if (
                    other.instance == obj.instance
                    or other.instance in found
                    or other.dynamics is Dynamics.STATIC
                    or other.support is not None
                    or other.attached_to is not None
                    or other.class_name not in self.catalog
                    or anchor.class_name not in self.catalog[other.class_name].anchors
                ):
                    continue
                if stands_at_object(other, anchor, self.catalog):
                    found.append(other.instance)
                    frontier.append(other)
        return found

    def _try(self, obj: SceneObject, propose) -> bool:  # noqa: ANN001
        followers = self._followers(obj)
        carried = self._descendants(obj.instance)
        for follower in followers:
            carried += [follower, *self._descendants(follower)]
        moving = {obj.instance, *carried}
        for attempt in range(self.config.tries):
            proposal = propose(obj, moving, attempt)
            if proposal is None:
                continue
            placement, support = proposal
            candidate = obj.moved_to(placement, support)
            delta = placement.matrix() @ np.linalg.inv(obj.placement.matrix())
            moved = [candidate] + [_carry(self.objects[i], delta) for i in carried]
            if self._valid(moved, moving):
                if support != obj.support:
                    self._reparent(obj, support)
                for item in moved:
                    self.objects[item.instance] = item
                self.followed.update(followers)
                return True
        return False

    def _reparent(self, obj: SceneObject, support: int | None) -> None:
        old = obj.support if obj.support is not None else obj.attached_to
        if old is not None:
            self.children[old].remove(obj.instance)
        if support is not None:
            self.children.setdefault(support, []).append(obj.instance)

    def _valid(self, moved: list[SceneObject], moving: set[int]) -> bool:
        lookup = {**self.objects, **{m.instance: m for m in moved}}
        still = [o for i, o in self.objects.items() if i not in moving]
        room = self.base
        for item in moved:
            if not inside_room(item, room):
                return False
            floor_standing = item.support is None and item.attached_to is None
            others = [*still, self.keepout] if floor_standing else still
            if colliding(item, others, lookup, self.catalog) is not None:
                return False
        if any(m.support is None and m.attached_to is None for m in moved):
            layout = room.with_objects([lookup[o.instance] for o in room.objects])
            if len(self.poses.grid(layout).cells) < self.min_reachable:
                return False
        return True

    def _low_candidate(
        self, obj: SceneObject, moving: set[int], attempt: int
    ) -> tuple[Placement, int | None] | None:
        radius = self.config.radius(obj)
        distance = radius * math.sqrt(self.rng.random())  # uniform over the disk
        angle = self.rng.uniform(-math.pi, math.pi)
        sigma = self.config.yaw_sigma(obj)
        yaw_noise = (
            float(np.clip(self.rng.normal(0.0, sigma), -3 * sigma, 3 * sigma)) if sigma else 0.0
        )
        p = obj.placement
        placement = Placement(
            p.x + distance * math.cos(angle),
            p.y + distance * math.sin(angle),
            p.z,
            p.yaw + yaw_noise,
        )
        if obj.support is not None:
            support = self.objects[obj.support]
            if not resting_surface(obj.moved_to(placement), support, self.catalog):
                return None
        return placement, obj.support

    def _high_candidate(
        self, obj: SceneObject, moving: set[int], attempt: int
    ) -> tuple[Placement, int | None] | None:
        spec = self.catalog[obj.class_name]
        if spec.placement in ("floor", "wall_floor") and obj.support is None:
            # where it belongs first (at a table, a wall, ...), anywhere free in the last tries
            anchors = anchor_objects(spec, self.objects.values(), self.catalog, exclude=moving)
            tier = tier_of(attempt, self.config.tries, tiers_for(spec, bool(anchors)))
            spot = draw_spot(self.rng, tier, anchors, self.base, obj.size)
            if tier != FREE and spot is not None:
                return spot, None
        yaw = float(self.rng.uniform(-math.pi, math.pi))
        if spec.placement in ("floor", "wall_floor") and obj.support is None:
            room = self.base
            half = bounding_radius(obj)
            x = float(
                self.rng.uniform(min(half, room.width / 2), max(room.width - half, room.width / 2))
            )
            y = float(
                self.rng.uniform(min(half, room.depth / 2), max(room.depth - half, room.depth / 2))
            )
            return Placement(x, y, obj.placement.z, yaw), None
        surfaces = self._surfaces_for(obj, moving)
        if not surfaces:
            return None
        target = surfaces[int(self.rng.integers(len(surfaces)))]
        placement = place_on_surface(self.rng, target, obj.size)
        return None if placement is None else (placement, target.owner)

    def _surfaces_for(self, obj: SceneObject, moving: set[int]) -> list[WorldSurface]:
        # never onto itself or what it carries
        others = (o for o in self.objects.values() if o.instance not in moving)
        return surfaces_for(self.catalog[obj.class_name], others, self.catalog)


def _carry(obj: SceneObject, delta: np.ndarray) -> SceneObject:
    """``obj`` moved rigidly by the 4x4 transform ``delta`` (its support moved)."""
    p = obj.placement
    world = delta @ np.array([p.x, p.y, p.z, 1.0])
    yaw = p.yaw + math.atan2(delta[1, 0], delta[0, 0])
    return obj.moved_to(Placement(float(world[0]), float(world[1]), float(world[2]), yaw))


@dataclass(frozen=True)
class LayoutSummary:
    """Per dynamics category: share of objects that moved by their own rule, and the mean
    displacement of those moves; plus how many objects were only carried along."""

    share_moved: dict[str, float]
    mean_displacement: dict[str, float]
    carried: int  # object moves caused only by their support (or their anchor) moving
    failed_moves: int  # drawn moves that found no valid spot (the object stayed put)

    def lines(self) -> list[str]:
        """Readable lines for the CLI."""
        out = []
        for category, share in self.share_moved.items():
            out.append(
                f"{category:>6}: {100 * share:5.1f} % moved, mean displacement "
                f"{self.mean_displacement[category]:.2f} m"
            )
        out.append(f"carried along by a moved support or anchor: {self.carried}")
        out.append(f"failed moves (stayed put): {self.failed_moves}")
        return out


def summarize_layouts(layouts: list[Layout]) -> LayoutSummary:
    """Statistics over layouts 1.. (layout 0 is the base and moves nothing)."""
    counts = {d.value: 0 for d in Dynamics}
    moved = {d.value: 0 for d in Dynamics}
    distance = {d.value: 0.0 for d in Dynamics}
    carried = failed = 0
    for layout in layouts[1:]:
        by_instance = {m.instance: m for m in layout.moves}
        for obj in layout.room.objects:
            category = obj.dynamics.value
            counts[category] += 1
            move = by_instance.get(obj.instance)
            if move is None:
                continue
            if not move.moved:
                failed += 1
            elif move.rule in ("carried", "follow"):
                carried += 1
            else:
                moved[category] += 1
                distance[category] += move.displacement
    share = {k: (moved[k] / counts[k] if counts[k] else 0.0) for k in counts}
    mean = {k: (distance[k] / moved[k] if moved[k] else 0.0) for k in counts}
    return LayoutSummary(share, mean, carried, failed)
