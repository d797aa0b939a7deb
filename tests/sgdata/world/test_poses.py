"""Reachable pose grid: walls, furniture footprints, enclosed pockets, the door side."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sgdata.errors import ConfigError
from sgdata.world.poses import pose_grid
from sgdata.world.scene import Dynamics, Opening, Placement, Room, SceneObject


def _room(objects: list[SceneObject], door: Opening | None = None) -> Room:
    return Room(
        room_id="t_000", room_type="bedroom", width=4.0, depth=3.0, height=2.5, seed=0,
        door=door or Opening("south", center=0.6, width=0.9, bottom=0.0, top=2.0),
        objects=tuple(objects),
    )  # fmt: skip


def _obj(
    inst: int, size: tuple[float, float, float], x: float, y: float, **kw: object
) -> SceneObject:
    z = float(kw.pop("z", 0.0))  # type: ignore[arg-type]
    yaw = float(kw.pop("yaw", 0.0))  # type: ignore[arg-type]
    return SceneObject(inst, "Box", Dynamics.LOW, size, Placement(x, y, z, yaw), **kw)  # type: ignore[arg-type]


def test_empty_room_cells_inside_walls() -> None:
    g = pose_grid(_room([]))
    assert g.shape == (16, 12)
    # the outer ring of centres is 0.125 m from a wall, closer than r = 0.2
    assert g.free[1:-1, 1:-1].all() and g.free.sum() == 14 * 10
    assert np.array_equal(g.reachable, g.free)
    for i, j in g.cells:
        x, y = g.center(i, j)
        assert 0 < x < 4 and 0 < y < 3


def test_cells_too_close_to_walls_are_not_free() -> None:
    g = pose_grid(_room([]), cell=0.5, radius=0.3)
    # centres at 0.25 from the walls: a 0.3 m disk does not fit
    assert not g.free[0].any() and not g.free[:, 0].any() and g.free[1:-1, 1:-1].all()


def test_table_blocks_its_cells() -> None:
    table = _obj(1, (1.0, 1.0, 0.75), 2.0, 1.5)
    g = pose_grid(_room([table]))
    i, j = 8, 6  # cell centre (2.125, 1.625): under the table
    assert not g.free[i, j]
    assert g.center(0, 0) == (0.125, 0.125)
    # cells whose disk clears the footprint by > r stay free
    for (ci, cj), free in np.ndenumerate(g.free):
        cx, cy = g.center(ci, cj)
        gap = math.hypot(max(abs(cx - 2.0) - 0.5, 0), max(abs(cy - 1.5) - 0.5, 0))
        inside_walls = 0.2 <= cx <= 3.8 and 0.2 <= cy <= 2.8
        assert free == (inside_walls and gap > 0.2)


def test_rotated_footprint_and_ignored_objects() -> None:
    bed = _obj(1, (2.0, 0.4, 0.5), 2.0, 1.5, yaw=math.pi / 2)  # long along y once rotated
    mug = _obj(2, (0.1, 0.1, 0.1), 1.0, 1.0, support=1)
    painting = _obj(3, (1.0, 0.05, 0.6), 1.0, 2.9, z=1.4)
    board = _obj(4, (0.5, 0.5, 0.02), 3.0, 1.0, attached_to=1)
    g = pose_grid(_room([bed, mug, painting, board]))
    col = [g.free[8, j] for j in range(12)]  # x = 2.125: inside the rotated bed everywhere
    assert not any(col[1:11])
    assert g.free[4, 4]  # (1.125, 1.125) under the mug's spot: the mug is not on the floor
    assert g.free[12, 4]  # the board is attached to something: not a floor obstacle


def test_enclosed_pocket_is_excluded_and_door_side_reachable() -> None:
    # a ring of furniture around (3.0, 1.5) leaves free cells inside it that no one can reach
    walls = [
        _obj(1, (1.6, 0.2, 1.0), 3.0, 0.7),
        _obj(2, (1.6, 0.2, 1.0), 3.0, 2.3),
        _obj(3, (0.2, 1.8, 1.0), 2.2, 1.5),
        _obj(4, (0.2, 1.8, 1.0), 3.8, 1.5),
    ]
    g = pose_grid(_room(walls), cell=0.2, radius=0.1)
    pocket = [
        (i, j)
        for (i, j), f in np.ndenumerate(g.free)
        if f and 2.3 < g.center(i, j)[0] < 3.7 and 0.8 < g.center(i, j)[1] < 2.2
    ]
    assert pocket, "the pocket has free cells"
    assert not any(g.reachable[c] for c in pocket)
    door_cell = min(g.cells, key=lambda c: math.hypot(g.center(*c)[0] - 0.6, g.center(*c)[1]))
    assert math.hypot(g.center(*door_cell)[0] - 0.6, g.center(*door_cell)[1]) < 0.5
    assert g.reachable.sum() == len(g.cells) and g.reachable.sum() > 100


def test_blocked_door_falls_back_to_largest_component() -> None:
    wall = _obj(1, (0.2, 3.0, 1.0), 1.5, 1.5)  # splits the room; the door side is small
    sofa = _obj(2, (1.4, 1.3, 0.8), 0.7, 0.65)  # in front of the door
    g = pose_grid(_room([wall, sofa]))
    xs = [g.center(i, j)[0] for i, j in g.cells]
    assert min(xs) > 1.5  # the big east part


def test_pose_world_and_noise() -> None:
    g = pose_grid(_room([]))
    assert g.pose_world(2, 3, 1) == pytest.approx((0.625, 0.875, math.pi / 2))
    rng = np.random.default_rng(0)
    for _ in range(200):
        x, y, th = g.pose_world(2, 3, 0, rng=rng)
        assert abs(x - 0.625) <= 0.25 / 4 + 1e-12 and abs(y - 0.875) <= 0.25 / 4 + 1e-12
        assert abs(th) <= math.radians(9) + 1e-12
    with pytest.raises(ConfigError):
        g.pose_world(0, 0, 4)
    with pytest.raises(ConfigError):
        pose_grid(_room([]), cell=0.0)
