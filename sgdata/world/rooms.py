"""Room generator: a believable, collision-free room of a given type from a seed.

Order of work, each step checked against everything placed before it:
shell and door -> fixture runs along walls -> wall-floor and floor furniture (beside the
anchor its recipe names; else where its class belongs, see :mod:`sgdata.world.arrangement`:
chairs at tables, desks or walls, footstools by the seating; only then anywhere free) -> wall
items (windows, paintings, mirrors) -> small objects on receptacle surfaces or inside
containers. Attached parts (counter tops, shelf boards, basins, burners) come with their
owners as objects of their own.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sgdata import seeds
from sgdata.errors import ConfigError
from sgdata.seeds import rng_for
from sgdata.world.arrangement import FREE, anchor_objects, draw_spot, tier_of, tiers_for
from sgdata.world.catalog import Catalog, ClassSpec, load_catalog
from sgdata.world.placement import (
    colliding,
    inside_room,
    object_build,
    place_on_surface,
    surfaces_for,
    wall_placement,
)
from sgdata.world.room_recipes import ROOM_TYPES, CountedClass, RoomRecipe, load_room_recipes
from sgdata.world.scene import WALLS, Dynamics, Opening, Placement, Room, SceneObject

__all__ = ["door_keepout", "generate_room", "room_id", "room_seed", "RoomStats", "room_stats"]

DOOR_WIDTH = 0.9
DOOR_HEIGHT = 2.1
DOOR_CLEARANCE = 1.0  # metres kept free in front of the door so the room stays enterable
FLOOR_TRIES = 60  # placement attempts per floor object before it is left out
SURFACE_TRIES = 30  # placement attempts per small object


def room_id(room_type: str, index: int) -> str:
    """The room's id, e.g. ``kitchen_003``."""
    return f"{room_type}_{index:03d}"


def room_seed(seed: int, room_type: str, index: int) -> int:
    """The seed of one room, derived from the dataset seed, the room type and its index."""
    return seeds.room_seed(seed, ROOM_TYPES.index(room_type), index)


def generate_room(
    room_type: str,
    index: int,
    seed: int,
    catalog: Catalog | None = None,
    *,
    recipes: dict[str, RoomRecipe] | None = None,
) -> Room:
    """Generate room ``index`` of ``room_type`` from the dataset ``seed``.

    Deterministic: the same arguments give the same room, object for object.

    Raises:
        ConfigError: unknown room type or negative index.
    """
    if room_type not in ROOM_TYPES:
        raise ConfigError(
            f"unknown room type {room_type!r}; expected one of {', '.join(ROOM_TYPES)}"
        )
    if index < 0:
        raise ConfigError(f"room index must be >= 0, got {index}")
    catalog = catalog or load_catalog()
    recipe = (recipes or load_room_recipes(catalog))[room_type]
    own_seed = room_seed(seed, room_type, index)
    builder = _RoomBuilder(recipe, catalog, rng_for(own_seed), room_id(room_type, index), own_seed)
    return builder.build()


@dataclass(frozen=True)
class RoomStats:
    """Counts for a generated room, for summaries."""

    objects: int
    by_dynamics: dict[str, int]
    classes: int


def room_stats(room: Room) -> RoomStats:
    """Object counts of a room by dynamics category."""
    by_dyn = {d.value: 0 for d in Dynamics}
    for obj in room.objects:
        by_dyn[obj.dynamics.value] += 1
    return RoomStats(len(room.objects), by_dyn, len({o.class_name for o in room.objects}))


class _RoomBuilder:
    """Holds the room being built and the bookkeeping of one generation run."""

    def __init__(
        self, recipe: RoomRecipe, catalog: Catalog, rng: np.random.Generator, rid: str, seed: int
    ) -> None:
        self.recipe = recipe
        self.catalog = catalog
        self.rng = rng
        width = self._uniform(recipe.size_min[0], recipe.size_max[0], step=0.05)
        depth = self._uniform(recipe.size_min[1], recipe.size_max[1], step=0.05)
        height = self._uniform(*recipe.height, step=0.05)
        wall = WALLS[int(rng.integers(len(WALLS)))]
        length = width if wall in ("south", "north") else depth
        center = self._uniform(0.7 + DOOR_WIDTH / 2, length - 0.7 - DOOR_WIDTH / 2, step=0.05)
        door = Opening(wall, center, DOOR_WIDTH, 0.0, DOOR_HEIGHT)
        self.room = Room(rid, recipe.room_type, width, depth, height, seed, door)
        self.objects: list[SceneObject] = []
        self.by_instance: dict[int, SceneObject] = {}
        self.theme: dict[str, tuple[float, float, float]] = {}
        self.keepout = door_keepout(self.room)
        self._mesh_variant = 0  # the file of the mesh class drawn last (see _mesh_size)

    # -- helpers -------------------------------------------------------------------------
    def _uniform(self, low: float, high: float, *, step: float = 0.0) -> float:
        value = float(self.rng.uniform(low, high))
        return round(value / step) * step if step else value

    def _size(self, spec: ClassSpec) -> tuple[float, float, float]:
        if spec.mesh is not None:
            return self._mesh_size(spec)
        lo, hi = np.array(spec.size_min), np.array(spec.size_max)
        return tuple(float(v) for v in np.round(lo + self.rng.random(3) * (hi - lo), 3))  # type: ignore[return-value]

    def _mesh_size(self, spec: ClassSpec) -> tuple[float, float, float]:
        """A mesh class's file is drawn first (its size is the file's): ``keep`` places it at
        its measured size, ``fit`` at a uniform scale drawn within the class's bounds."""
        from sgdata.world.mesh_assets import class_sizes  # late: reads the files once

        self._mesh_variant = int(self.rng.integers(spec.variants))
        size = np.array(class_sizes(spec)[self._mesh_variant])
        if spec.mesh is not None and spec.mesh.scale == "fit":
            low = float(np.max(np.array(spec.size_min) / size))
            high = float(np.min(np.array(spec.size_max) / size))
            size = size * (self._uniform(low, high) if low <= high else 1.0)
        return tuple(float(v) for v in np.round(size, 4))  # type: ignore[return-value]

    def _color(self, spec: ClassSpec) -> tuple[float, float, float]:
        # Fixtures share one colour per class in a room (a kitchen's cabinets match).
        if spec.dynamics is Dynamics.STATIC:
            if spec.name not in self.theme:
                self.theme[spec.name] = spec.palette[int(self.rng.integers(len(spec.palette)))]
            return self.theme[spec.name]
        return spec.palette[int(self.rng.integers(len(spec.palette)))]

    def _count(self, spec: ClassSpec) -> int:
        return sum(1 for o in self.objects if o.class_name == spec.name)

    def _new(
        self,
        spec: ClassSpec,
        size: tuple[float, float, float],
        placement: Placement,
        *,
        support: int | None = None,
    ) -> SceneObject:
        if spec.mesh is not None:  # drawn with its size (_mesh_size)
            variant = self._mesh_variant
        else:
            variant = int(self.rng.integers(spec.variants))
        return SceneObject(
            instance=len(self.objects) + 1,
            class_name=spec.name,
            dynamics=spec.dynamics,
            size=size,
            placement=placement,
            variant=variant,
            color=self._color(spec),
            support=support,
        )

    def _fits(self, candidate: SceneObject) -> bool:
        if not inside_room(candidate, self.room):
            return False
        others = [*self.objects, self.keepout]
        return (
            colliding(
                candidate,
                others,
                {**self.by_instance, candidate.instance: candidate},
                self.catalog,
            )
            is None
        )

    def _commit(self, obj: SceneObject) -> None:
        """Add an object and, recursively, the attached parts its recipe brings."""
        self.objects.append(obj)
        self.by_instance[obj.instance] = obj
        matrix = obj.placement.matrix()
        owner_yaw = obj.placement.yaw
        for part in object_build(obj, self.catalog).attachments:
            spec = self.catalog[part.class_name]
            world = matrix @ np.array([part.x, part.y, part.z, 1.0])
            placement = Placement(
                float(world[0]), float(world[1]), float(world[2]), owner_yaw + part.yaw
            )
            child = SceneObject(
                instance=len(self.objects) + 1,
                class_name=spec.name,
                dynamics=spec.dynamics,
                size=part.size,
                placement=placement,
                variant=0,
                color=self._color(spec),
                attached_to=obj.instance,
            )
            self._commit(child)

    # -- stages --------------------------------------------------------------------------
    def build(self) -> Room:
        for run in self.recipe.runs:
            self._place_run(run)
        for item in self.recipe.furniture:
            self._place_counted(item, self._place_furniture)
        for item in self.recipe.wall_items:
            self._place_counted(item, self._place_wall_item)
        for item in self.recipe.small:
            self._place_counted(item, self._place_small)
        return self.room.with_objects(self.objects)

    def _place_counted(self, item: CountedClass, place) -> None:  # noqa: ANN001
        spec = self.catalog[item.class_name]
        count = int(self.rng.integers(item.count[0], item.count[1] + 1))
        count = min(count, spec.max_instances - self._count(spec))
        for _ in range(count):
            place(spec, item)

    def _free_walls(self) -> list[str]:
        """Walls in random order (the draw keeps runs on different walls in different rooms)."""
        order = self.rng.permutation(len(WALLS))
        return [WALLS[i] for i in order]

    def _place_run(self, run: tuple[str, ...]) -> None:
        """Units side by side along one wall, from a corner, skipping the door."""
        specs = [self.catalog[name] for name in run]
        run_depth = self._uniform(0.58, 0.64, step=0.01)
        for wall in self._free_walls():
            length = self.room.wall_length(wall)
            reverse = bool(self.rng.integers(2))
            placed = self._try_run_on_wall(specs, wall, length, reverse, run_depth)
            if placed:
                return

    def _try_run_on_wall(
        self, specs: list[ClassSpec], wall: str, length: float, reverse: bool, run_depth: float
    ) -> bool:
        cursor = 0.0
        candidates: list[SceneObject] = []
        start_count = len(self.objects)
        for spec in specs:
            if self._count(spec) >= spec.max_instances:
                continue
            size = self._size(spec)
            if spec.name != "Fridge" and spec.placement == "wall_floor" and spec.mesh is None:
                depth = float(np.clip(run_depth, spec.size_min[1], spec.size_max[1]))
                height = round((spec.size_min[2] + spec.size_max[2]) / 2, 3)
                size = (size[0], depth, height)
            placed = None
            while cursor + size[0] <= length:
                along = cursor + size[0] / 2
                along = length - along if reverse else along
                candidate = self._new(
                    spec, size, wall_placement(self.room, wall, along, size[1], 0.0)
                )
                if self._fits(candidate):
                    placed = candidate
                    break
                cursor += 0.05
            if placed is None:
                break
            self._commit(placed)
            candidates.append(placed)
            cursor += size[0]
        if len(candidates) >= max(1, len(specs) // 2):
            return True
        # Too little of the run fits on this wall: take it back and try another wall.
        for obj in self.objects[start_count:]:
            del self.by_instance[obj.instance]
        del self.objects[start_count:]
        return False

    def _place_furniture(self, spec: ClassSpec, item: CountedClass) -> None:
        if item.near is None and spec.anchors:
            self._place_anchored(spec)
            return
        anchors = [o for o in self.objects if item.near and o.class_name == item.near]
        for _ in range(FLOOR_TRIES):
            size = self._size(spec)
            if anchors:
                anchor = anchors[int(self.rng.integers(len(anchors)))]
                placement = self._beside(anchor, size, item.side)
            elif spec.placement == "wall_floor":
                wall = WALLS[int(self.rng.integers(len(WALLS)))]
                along = self._uniform(size[0] / 2, self.room.wall_length(wall) - size[0] / 2)
                placement = wall_placement(self.room, wall, along, size[1], 0.0)
            else:
                placement = self._anywhere(spec, size)
            candidate = self._new(spec, size, placement)
            if self._fits(candidate):
                self._commit(candidate)
                return

    def _place_anchored(self, spec: ClassSpec) -> None:
        """Where the class belongs: at one of its anchor objects, facing it; else back to a
        wall; only in the last tries anywhere free (the tiers of ``arrangement.tier_of``)."""
        anchors = anchor_objects(spec, self.objects, self.catalog, exclude=set())
        tiers = tiers_for(spec, bool(anchors))
        for attempt in range(FLOOR_TRIES):
            size = self._size(spec)
            tier = tier_of(attempt, FLOOR_TRIES, tiers)
            placement = draw_spot(self.rng, tier, anchors, self.room, size)
            if tier == FREE or placement is None:
                placement = self._anywhere(spec, size)
            candidate = self._new(spec, size, placement)
            if self._fits(candidate):
                self._commit(candidate)
                return

    def _anywhere(self, spec: ClassSpec, size: tuple[float, float, float]) -> Placement:
        x = self._uniform(size[0] / 2, self.room.width - size[0] / 2)
        y = self._uniform(size[1] / 2, self.room.depth - size[1] / 2)
        if spec.dynamics is Dynamics.HIGH:
            yaw = self._uniform(-math.pi, math.pi)
        else:  # heavier furniture stands square to the walls, give or take a few degrees
            yaw = int(self.rng.integers(4)) * math.pi / 2 + self._uniform(-0.05, 0.05)
        return Placement(x, y, 0.0, yaw)

    def _beside(
        self, anchor: SceneObject, size: tuple[float, float, float], where: str
    ) -> Placement:
        """A spot next to one side of ``anchor``: facing it, or beside it facing the same way."""
        aw, ad, _ = anchor.size
        choices = {"any": (0, 1, 2, 3), "front": (0,), "sides": (1, 3)}[where]
        side = choices[int(self.rng.integers(len(choices)))]
        gap = self._uniform(0.02, 0.45 if where == "front" else 0.25)
        # side normals in the anchor frame: front (-y), right (+x), back (+y), left (-x)
        nx, ny = [(0, -1), (1, 0), (0, 1), (-1, 0)][side]
        reach = (ad if ny else aw) / 2 + size[1] / 2 + gap
        span = (aw if ny else ad) / 2
        offset = self._uniform(-span * 0.7, span * 0.7)
        lx, ly = nx * reach + (offset if ny else 0.0), ny * reach + (offset if nx else 0.0)
        world = anchor.placement.matrix() @ np.array([lx, ly, 0.0, 1.0])
        dx, dy = anchor.placement.x - world[0], anchor.placement.y - world[1]
        if where == "sides":  # a night stand or side table stands square with its anchor
            yaw = anchor.placement.yaw
        else:
            yaw = math.atan2(dy, dx) + math.pi / 2  # front (-Y local) towards the anchor
        return Placement(float(world[0]), float(world[1]), 0.0, yaw)

    def _place_wall_item(self, spec: ClassSpec, item: CountedClass) -> None:
        anchors = [o for o in self.objects if item.above and o.class_name == item.above]
        for _ in range(FLOOR_TRIES):
            size = self._size(spec)
            z = self._uniform(*spec.wall_height)
            if anchors:
                anchor = anchors[int(self.rng.integers(len(anchors)))]
                wall, along = _wall_of(anchor)
                along += self._uniform(-0.1, 0.1)
                z = max(z, anchor.world_aabb()[1][2] + 0.1)
            else:
                wall = WALLS[int(self.rng.integers(len(WALLS)))]
                along = self._uniform(
                    size[0] / 2 + 0.05, self.room.wall_length(wall) - size[0] / 2 - 0.05
                )
            if z + size[2] > self.room.height - 0.05:
                continue
            candidate = self._new(spec, size, wall_placement(self.room, wall, along, size[1], z))
            if self._fits(candidate) and not _over_door(candidate, self.room):
                self._commit(candidate)
                return

    def _place_small(self, spec: ClassSpec, item: CountedClass) -> None:
        surfaces = surfaces_for(spec, self.objects, self.catalog)
        if not surfaces:
            return
        for _ in range(SURFACE_TRIES):
            target = surfaces[int(self.rng.integers(len(surfaces)))]
            size = self._size(spec)
            yaw = (
                None if spec.dynamics is Dynamics.HIGH else int(self.rng.integers(4)) * math.pi / 2
            )
            placement = place_on_surface(self.rng, target, size, yaw=yaw)
            if placement is None:
                continue
            candidate = self._new(spec, size, placement, support=target.owner)
            if self._fits(candidate):
                self._commit(candidate)
                return


def door_keepout(room: Room) -> SceneObject:
    """A pseudo-object (instance 0) filling the space in front of the door: nothing may stand
    there, so every room and layout stays enterable."""
    door = room.door
    placement = wall_placement(room, door.wall, door.center, DOOR_CLEARANCE, 0.0)
    size = (door.width + 0.2, DOOR_CLEARANCE, door.top)
    return SceneObject(0, "_DoorClearance", Dynamics.STATIC, size, placement)


def _wall_of(obj: SceneObject) -> tuple[str, float]:
    """The wall an object stands against (by its yaw) and its position along that wall."""
    p = obj.placement
    facing = round(math.degrees(p.yaw) / 90) % 4
    wall = {0: "north", 2: "south", 3: "east", 1: "west"}[facing]
    along = p.x if wall in ("south", "north") else p.y
    return wall, along


def _over_door(obj: SceneObject, room: Room) -> bool:
    """True when a wall item would hang in the door gap."""
    door = room.door
    wall, along = _wall_of(obj)
    if wall != door.wall:
        return False
    return abs(along - door.center) < (door.width + obj.size[0]) / 2
