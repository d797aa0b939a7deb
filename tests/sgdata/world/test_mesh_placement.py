"""Mesh classes collide by the convex hull of their floor projection, not their box."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import trimesh

from sgdata.world.catalog import load_catalog
from sgdata.world.placement import boxes_overlap, colliding, floor_outline, objects_overlap
from sgdata.world.room_checks import room_problems
from sgdata.world.rooms import generate_room
from sgdata.world.scene import Placement, SceneObject
from tests.asset_meshes import write_demo_assets


@pytest.fixture(scope="module")
def demo(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("demo_assets")
    write_demo_assets(folder)
    return folder / "catalog.toml"


def _plate(instance: int, x: float, y: float, yaw: float = 0.0) -> SceneObject:
    return SceneObject(instance, "Plate", "high", (0.24, 0.24, 0.02), Placement(x, y, 0.0, yaw))


def test_round_plates_stand_as_close_as_their_rims_allow(demo: Path) -> None:
    catalog = load_catalog(extra=[demo])
    a = _plate(1, 0.0, 0.0)
    # diagonal neighbours: the boxes' corners overlap, the discs (radius 0.12) do not
    b = _plate(2, 0.2, 0.2)
    assert boxes_overlap(a, b)
    assert not objects_overlap(a, b, catalog)
    assert colliding(b, [a], {1: a, 2: b}, catalog) is None
    assert colliding(b, [a], {1: a, 2: b}) is a  # without the catalog: the boxes
    # nearer along the diagonal the rims meet
    c = _plate(3, 0.15, 0.15)
    assert objects_overlap(a, c, catalog)
    # heights apart: no collision whatever the outline
    d = SceneObject(4, "Plate", "high", (0.24, 0.24, 0.02), Placement(0.0, 0.0, 0.5, 0.0))
    assert not objects_overlap(a, d, catalog)


def test_outline_follows_the_placement(demo: Path) -> None:
    catalog = load_catalog(extra=[demo])
    obj = _plate(1, 1.0, 2.0, yaw=0.7)
    outline = floor_outline(obj, catalog)
    assert len(outline) == 48
    assert np.hypot(outline[:, 0] - 1.0, outline[:, 1] - 2.0) == pytest.approx(0.12, abs=1e-3)
    # a recipe object (or none given): its box's four corners
    assert floor_outline(obj).shape == (4, 2)


def test_a_box_mesh_collides_exactly_as_its_box(tmp_path: Path) -> None:
    """The polygon test against the reference box test: a mesh that is a box agrees with the
    oriented-box test at every random pose."""
    (tmp_path / "crate.stl").write_bytes(
        trimesh.creation.box((0.4, 0.3, 0.2)).export(file_type="stl")
    )
    (tmp_path / "user.toml").write_text(
        '[classes.Crate]\nmesh = "crate.stl"\ndynamics = "high"\nplacement = "floor"\n'
        "size_min = [0.3, 0.2, 0.1]\nsize_max = [0.5, 0.4, 0.3]\n",
        encoding="utf-8",
    )
    catalog = load_catalog(extra=[tmp_path / "user.toml"])
    rng = np.random.default_rng(0)
    agree = 0
    for _ in range(300):
        a, b = (
            SceneObject(
                i,
                "Crate",
                "high",
                (0.4, 0.3, 0.2),
                Placement(*rng.uniform(0, 0.6, 2), 0.0, float(rng.uniform(-math.pi, math.pi))),
            )
            for i in (1, 2)
        )
        assert objects_overlap(a, b, catalog) == boxes_overlap(a, b)
        agree += boxes_overlap(a, b)
    assert 30 < agree < 270  # both outcomes were tried


def test_demo_rooms_and_layouts_are_valid_under_the_hull_test(demo: Path) -> None:
    from sgdata.world.dynamics import DynamicsConfig, sample_layouts

    catalog = load_catalog(extra=[demo])
    room = generate_room("kitchen", 0, 0, catalog)
    assert room_problems(room, catalog) == []
    for layout in sample_layouts(room, 3, 7, catalog, DynamicsConfig()):
        assert room_problems(layout.room, catalog) == []


def test_recipe_rooms_are_unchanged_by_the_catalog_argument() -> None:
    """Recipe objects keep the box test: the same room with or without mesh support."""
    catalog = load_catalog()
    room = generate_room("kitchen", 0, 3, catalog)
    for a in room.objects[:20]:
        for b in room.objects[:20]:
            assert objects_overlap(a, b, catalog) == boxes_overlap(a, b)
