"""Where furniture stands: chairs at tables, desks and walls, footstools by the seating, and
bedrooms as full as the other rooms, in generated rooms and in their layouts."""

from __future__ import annotations

import math
import os
import subprocess
import sys
from collections import Counter
from pathlib import Path

import numpy as np
import pytest

from sgdata.world.arrangement import (
    FREE,
    STAND_GAP,
    STAND_YAW_DEG,
    spot_at,
    spot_at_wall,
    standing_at,
    tier_of,
    tiers_for,
)
from sgdata.world.catalog import Catalog
from sgdata.world.dynamics import ClassDynamics, DynamicsConfig, sample_layouts, summarize_layouts
from sgdata.world.room_checks import room_problems
from sgdata.world.room_recipes import ROOM_TYPES
from sgdata.world.rooms import generate_room
from sgdata.world.scene import Dynamics, Opening, Placement, Room, SceneObject

ROOMS_PER_TYPE = 6
LAYOUTS = 3  # layout 0 (the room itself) and two moved ones
TABLES = {"DiningTable", "Desk"}
SEATING = {"Sofa", "ArmChair", "Bed", "DiningTable", "Desk"}


@pytest.fixture(scope="module")
def arranged(catalog: Catalog) -> dict[str, list[list[Room]]]:
    """Per room type: for each of six rooms of seed 0, the room and its moved layouts."""
    out: dict[str, list[list[Room]]] = {}
    for room_type in ROOM_TYPES:
        out[room_type] = []
        for index in range(ROOMS_PER_TYPE):
            room = generate_room(room_type, index, 0, catalog)
            layouts = sample_layouts(room, LAYOUTS, index, catalog)
            out[room_type].append([layout.room for layout in layouts])
    return out


# --- a reference check, written from the geometry alone (not with the module's helpers) ---


def _facing(obj: SceneObject) -> np.ndarray:
    return np.array([math.sin(obj.placement.yaw), -math.cos(obj.placement.yaw)])


def _on_footprint(point: np.ndarray, obj: SceneObject) -> bool:
    inverse = np.linalg.inv(obj.placement.matrix())
    lx, ly = inverse[:2, :2] @ point + inverse[:2, 3]
    return abs(lx) <= obj.size[0] / 2 and abs(ly) <= obj.size[1] / 2


def _faces_square(obj: SceneObject, anchor: SceneObject) -> bool:
    rel = (obj.placement.yaw - anchor.placement.yaw) % (math.pi / 2)
    return math.degrees(min(rel, math.pi / 2 - rel)) <= STAND_YAW_DEG


def _at_object(obj: SceneObject, anchor: SceneObject) -> bool:
    """Looking straight ahead from the middle of its front, the object sees the anchor within
    STAND_GAP, and stands square to it give or take the yaw noise."""
    f = _facing(obj)
    front = np.array([obj.placement.x, obj.placement.y]) + f * obj.size[1] / 2
    ahead = [front + f * g for g in np.linspace(0.0, STAND_GAP, 31)]
    return _faces_square(obj, anchor) and any(_on_footprint(p, anchor) for p in ahead)


def _at_wall(obj: SceneObject, room: Room) -> bool:
    """Its back within STAND_GAP of a wall, facing square into the room."""
    f = _facing(obj)
    back = np.array([obj.placement.x, obj.placement.y]) - f * obj.size[1] / 2
    walls = {
        (0.0, 1.0): back[1],
        (0.0, -1.0): room.depth - back[1],
        (1.0, 0.0): back[0],
        (-1.0, 0.0): room.width - back[0],
    }
    cos_tol = math.cos(math.radians(STAND_YAW_DEG))
    return any(f @ np.array(n) >= cos_tol and d <= STAND_GAP + 0.05 for n, d in walls.items())


def _where(obj: SceneObject, room: Room, anchors: set[str], *, wall: bool) -> str:
    for other in room.objects:
        if other.class_name in anchors and _at_object(obj, other):
            return other.class_name
    return "wall" if wall and _at_wall(obj, room) else FREE


def _tally(arranged, classes: set[str], anchors: set[str], *, wall: bool):  # noqa: ANN001, ANN202
    base, moved = Counter(), Counter()
    for rooms in arranged.values():
        for layouts in rooms:
            for k, room in enumerate(layouts):
                for obj in room.objects:
                    if obj.class_name in classes:
                        (base if k == 0 else moved)[_where(obj, room, anchors, wall=wall)] += 1
    return base, moved


# --- tests ---


def test_chairs_stand_at_a_table_desk_or_wall_facing_it(arranged) -> None:  # noqa: ANN001
    base, moved = _tally(arranged, {"Chair"}, TABLES, wall=True)
    for counts in (base, moved):
        total = sum(counts.values())
        assert total >= 20, counts
        assert counts[FREE] / total <= 0.05, counts  # "anywhere free" is the rare fallback
        assert counts["DiningTable"] + counts["Desk"] > counts["wall"], counts


def test_module_check_agrees_with_the_reference(arranged, catalog: Catalog) -> None:  # noqa: ANN001
    checked = 0
    for rooms in arranged.values():
        for layouts in rooms:
            for room in layouts:
                for obj in room.objects:
                    if obj.class_name != "Chair":
                        continue
                    found = standing_at(obj, room.objects, room, catalog)
                    name = found.class_name if isinstance(found, SceneObject) else found
                    assert (name or FREE) == _where(obj, room, TABLES, wall=True), obj.prim_name
                    checked += 1
    assert checked >= 40


def test_stools_and_ottomans_stand_by_the_seating(arranged) -> None:  # noqa: ANN001
    base, moved = _tally(arranged, {"Stool", "Ottoman"}, SEATING, wall=False)
    stools_at_walls, _ = _tally(arranged, {"Stool"}, set(), wall=True)
    base[FREE] -= stools_at_walls["wall"]  # a stool may also stand back to a wall
    total = sum(base.values()) - stools_at_walls["wall"]
    assert total >= 5, base
    assert base[FREE] / total <= 0.15, base
    assert sum(moved.values()) >= 5, moved


def test_bedrooms_hold_about_as_much_as_the_other_rooms(arranged) -> None:  # noqa: ANN001
    mean = {t: np.mean([len(layouts[0].objects) for layouts in arranged[t]]) for t in ROOM_TYPES}
    assert 38 <= mean["bedroom"] <= 60, mean  # 28 before the bedroom clutter
    assert mean["bedroom"] >= max(mean["living_room"], mean["bathroom"]), mean
    assert mean["bedroom"] >= 0.65 * mean["kitchen"], mean
    bedrooms = [layouts[0] for layouts in arranged["bedroom"]]
    assert min(len(room.objects) for room in bedrooms) >= 32
    held = Counter(o.class_name for room in bedrooms for o in room.objects)
    for name in ("Clothes", "Blanket", "PictureFrame", "Book", "Box", "DeskLamp", "Shoes"):
        assert held[name] >= ROOMS_PER_TYPE // 2, (name, held[name])
    inside = [
        o
        for room in bedrooms
        for o in room.objects
        if o.support is not None and room.by_instance()[o.support].class_name in ("Box", "Shelf")
    ]
    assert len(inside) >= ROOMS_PER_TYPE  # things in boxes and on the shelves of a unit


def test_rooms_and_layouts_stay_physically_valid(arranged, catalog: Catalog) -> None:  # noqa: ANN001
    for rooms in arranged.values():
        for layouts in rooms:
            for k, room in enumerate(layouts):
                assert room_problems(room, catalog) == [], f"{room.room_id} layout {k}"


def test_chairs_follow_their_table(kitchen: Room, catalog: Catalog) -> None:
    only_the_table = DynamicsConfig(
        low_move_chance=0.0,
        high_move_chance=0.0,
        classes={"DiningTable": ClassDynamics(move_chance=1.0)},
    )
    table = next(o for o in kitchen.objects if o.class_name == "DiningTable")
    seated = {
        o.instance
        for o in kitchen.objects
        if o.class_name == "Chair" and standing_at(o, kitchen.objects, kitchen, catalog) == table
    }
    assert seated
    layouts = sample_layouts(kitchen, 4, 5, catalog, only_the_table)
    followed = 0
    for layout in layouts[1:]:
        rules = {m.instance: m.rule for m in layout.moves}
        now = layout.room.by_instance()
        if now[table.instance].placement == table.placement:
            continue  # the table found no spot: nothing moved
        for instance in seated:
            assert rules.get(instance) == "follow", (layout.index, instance, rules)
            found = standing_at(now[instance], layout.room.objects, layout.room, catalog)
            assert found == now[table.instance]
            followed += 1
        assert room_problems(layout.room, catalog) == []
    assert followed > 0
    assert summarize_layouts(layouts).carried >= followed


def _square_room(catalog: Catalog) -> tuple[Room, SceneObject]:
    door = Opening("south", 0.8, 0.9, 0.0, 2.1)
    table = SceneObject(
        1, "DiningTable", Dynamics.LOW, (1.4, 0.9, 0.75), Placement(2.5, 2.5, 0.0, 0.4)
    )
    return Room("test_000", "kitchen", 5.0, 5.0, 2.6, 0, door, (table,)), table


def test_spots_read_back_as_standing_there(catalog: Catalog) -> None:
    room, table = _square_room(catalog)
    rng = np.random.default_rng(0)
    size = (0.5, 0.5, 0.9)
    for side in ("front", "right", "back", "left"):
        for _ in range(20):
            chair = SceneObject(2, "Chair", Dynamics.HIGH, size, spot_at(rng, table, side, size))
            assert standing_at(chair, room.objects, room, catalog) == table, side
            assert _at_object(chair, table), side
    for _ in range(40):
        chair = SceneObject(2, "Chair", Dynamics.HIGH, size, spot_at_wall(rng, room, size))
        assert standing_at(chair, room.objects, room, catalog) == "wall"
        assert _at_wall(chair, room)
    # turned away from the table, or too far from it, it stands anywhere
    away = Placement(table.placement.x, table.placement.y - 1.5, 0.0, math.pi / 2)
    chair = SceneObject(2, "Chair", Dynamics.HIGH, size, away)
    assert standing_at(chair, room.objects, room, catalog) is None


def test_tiers_share_the_tries(catalog: Catalog) -> None:
    chair = catalog["Chair"]
    tiers = tiers_for(chair, True)
    assert tiers == ("object", "wall", FREE)
    drawn = [tier_of(k, 40, tiers) for k in range(40)]
    assert drawn == ["object"] * 18 + ["wall"] * 18 + [FREE] * 4
    assert tiers_for(chair, False) == ("wall", FREE)
    assert tiers_for(catalog["DiningTable"], False) == (FREE,)
    assert tier_of(0, 1, tiers) == FREE


_SCRIPT = """
import hashlib, sys
from pathlib import Path
from sgdata.usd.scene_dirs import write_layouts, write_rooms
out = Path(sys.argv[1])
for room_type in ("bedroom", "kitchen"):
    write_rooms(out, room_type, count=1, seed=3)
    write_layouts(out / f"{room_type}_000", count=3, seed=3)
for path in sorted(out.rglob("*.usda")):
    print(path.relative_to(out), hashlib.sha256(path.read_bytes()).hexdigest())
"""


def test_same_seed_same_bytes_whatever_the_hash_seed(tmp_path: Path) -> None:
    digests = []
    for hash_seed in ("1", "2"):
        env = {**os.environ, "PYTHONHASHSEED": hash_seed}
        out = tmp_path / f"h{hash_seed}"
        done = subprocess.run(
            [sys.executable, "-c", _SCRIPT, str(out)],
            env=env,
            capture_output=True,
            text=True,
            check=True,
            timeout=300,
        )
        digests.append(done.stdout)
    assert digests[0] == digests[1]
    assert digests[0].count("layout_") == 6
