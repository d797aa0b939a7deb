"""Dynamics sampler: who moves, how far, onto what; layouts as USD layers."""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import numpy as np
import pytest

from sgdata.errors import ConfigError, SceneError, SgdataError
from sgdata.usd.room_io import read_room
from sgdata.usd.scene_dirs import layout_file, load_layout, write_layouts
from sgdata.usd.stage import validate_stage
from sgdata.world.catalog import Catalog
from sgdata.world.dynamics import DynamicsConfig, bounding_radius, sample_layouts, summarize_layouts
from sgdata.world.room_checks import room_problems
from sgdata.world.scene import Dynamics, Room


@pytest.fixture(scope="module")
def twenty(kitchen: Room, catalog: Catalog):
    return sample_layouts(kitchen, 20, 11, catalog)


def test_static_objects_never_move(twenty, kitchen: Room) -> None:
    base = kitchen.by_instance()
    for layout in twenty:
        for obj in layout.room.objects:
            if obj.dynamics is Dynamics.STATIC and obj.attached_to is None:
                assert obj.placement == base[obj.instance].placement


def test_low_dynamic_moves_within_radius_on_same_support(twenty, kitchen: Room) -> None:
    base = kitchen.by_instance()
    config = DynamicsConfig()
    moved = 0
    for layout in twenty:
        for move in layout.moves:
            if move.rule != "low" or not move.moved:
                continue
            moved += 1
            obj = base[move.instance]
            assert move.displacement <= config.radius_factor * bounding_radius(obj) + 1e-9
            assert move.support_after == move.support_before
            yaw_change = math.atan2(
                math.sin(move.after.yaw - move.before.yaw),
                math.cos(move.after.yaw - move.before.yaw),
            )
            assert abs(math.degrees(yaw_change)) <= 3 * config.yaw_sigma_deg + 1e-6
    assert moved > 0


def test_high_dynamic_objects_spread(twenty, kitchen: Room) -> None:
    chairs = [o.instance for o in kitchen.objects if o.class_name == "Chair"]
    mugs = [o.instance for o in kitchen.objects if o.class_name == "Mug"]
    assert chairs and mugs
    spots = {
        (round(o.placement.x / 0.25), round(o.placement.y / 0.25))
        for layout in twenty
        for o in layout.room.objects
        if o.instance == chairs[0]
    }
    assert len(spots) >= 4
    supports = {layout.room.by_instance()[mugs[0]].support for layout in twenty}
    assert len(supports) >= 2


def test_every_layout_is_physically_valid(twenty, catalog: Catalog) -> None:
    for layout in twenty:
        assert room_problems(layout.room, catalog) == [], f"layout {layout.index}"


def test_carried_objects_follow_their_support(twenty, kitchen: Room) -> None:
    for layout in twenty:
        now = layout.room.by_instance()
        for move in layout.moves:
            if move.rule == "carried":
                parent = kitchen.by_instance()[move.instance]
                owner = parent.support if parent.support is not None else parent.attached_to
                assert owner is not None
                assert now[owner].placement != kitchen.by_instance()[owner].placement


def test_summary_reports_shares(twenty) -> None:
    summary = summarize_layouts(twenty)
    assert summary.share_moved["static"] == 0.0
    assert 0.0 < summary.share_moved["low"] <= 1.0
    assert summary.share_moved["high"] > summary.share_moved["low"] * 0.5
    assert summary.mean_displacement["high"] > summary.mean_displacement["low"]
    assert any("moved" in line for line in summary.lines())


def test_same_seed_identical_layers(tmp_path: Path, kitchen_dir: Path, catalog: Catalog) -> None:
    copy = tmp_path / "kitchen_000"
    shutil.copytree(kitchen_dir, copy)
    write_layouts(copy, count=5, seed=0, catalog=catalog)
    for k in range(5):
        assert layout_file(copy, k).read_bytes() == layout_file(kitchen_dir, k).read_bytes()
    write_layouts(copy, count=2, seed=1, catalog=catalog)
    assert layout_file(copy, 1).read_bytes() != layout_file(kitchen_dir, 1).read_bytes()


def test_layout_reads_back_over_room(kitchen_dir: Path, catalog: Catalog) -> None:
    layouts = sample_layouts(
        read_room(kitchen_dir / "room.usda"),
        5,
        __import__("sgdata.seeds", fromlist=["derive_seed"]).derive_seed(
            read_room(kitchen_dir / "room.usda").seed, 0
        ),
        catalog,
    )
    for layout in layouts:
        back = load_layout(kitchen_dir, layout.index, catalog)
        for a, b in zip(layout.room.objects, back.objects, strict=True):
            assert a.support == b.support
            assert np.allclose(a.placement.matrix(), b.placement.matrix(), atol=1e-6)
        assert validate_stage(layout_file(kitchen_dir, layout.index)) == []


def test_bad_input(tmp_path: Path, kitchen_dir: Path, catalog: Catalog) -> None:
    with pytest.raises(ConfigError, match="count must be >= 1"):
        write_layouts(kitchen_dir, count=0, seed=0, catalog=catalog)
    with pytest.raises(ConfigError, match="not a directory"):
        write_layouts(tmp_path / "nowhere", count=2, seed=0, catalog=catalog)
    with pytest.raises(ConfigError, match="dynamics.low_move_chance"):
        DynamicsConfig(low_move_chance=1.5)
    # a layout whose room.usda is gone
    orphan = tmp_path / "orphan"
    orphan.mkdir()
    shutil.copy(layout_file(kitchen_dir, 1), orphan / "layout_1.usda")
    with pytest.raises(SgdataError):
        read_room(orphan / "layout_1.usda")


def test_layer_edited_into_a_wall_is_refused(
    tmp_path: Path, kitchen_dir: Path, catalog: Catalog
) -> None:
    copy = tmp_path / "kitchen_000"
    shutil.copytree(kitchen_dir, copy)
    room = read_room(copy / "room.usda")
    text = layout_file(copy, 2).read_text()
    # an object on the floor (a chair when one stays put) that the layer does not override
    # already, so ours is the one read
    free = [
        o
        for o in room.objects
        if o.support is None and o.attached_to is None and f'over "{o.prim_name}"' not in text
    ]
    chair = min(free, key=lambda o: (o.class_name != "Chair", o.instance))
    # author a translate for the chair that puts it half through the west wall
    override = (
        f'    over "{chair.prim_name}"\n    {{\n'
        f"        double3 xformOp:translate = (0, {room.depth / 2}, 0)\n    }}\n"
    )
    anchor = 'over "Objects"\n    {\n'
    assert anchor in text
    text = text.replace(anchor, anchor + override, 1)
    layout_file(copy, 2).write_text(text)
    with pytest.raises(SceneError, match=chair.prim_name):
        load_layout(copy, 2, catalog)
