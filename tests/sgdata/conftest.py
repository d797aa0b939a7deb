"""Factories for generated rooms and scene directories, shared by the sgdata tests."""

from __future__ import annotations

from pathlib import Path

import pytest

from sgdata.world.catalog import Catalog, load_catalog
from sgdata.world.room_recipes import ROOM_TYPES
from sgdata.world.rooms import generate_room
from sgdata.world.scene import Room


@pytest.fixture(scope="session")
def catalog() -> Catalog:
    return load_catalog()


@pytest.fixture(scope="session")
def rooms_by_type(catalog: Catalog) -> dict[str, list[Room]]:
    """Three rooms of each type from seed 0."""
    return {t: [generate_room(t, i, 0, catalog) for i in range(3)] for t in ROOM_TYPES}


@pytest.fixture(scope="session")
def kitchen(rooms_by_type: dict[str, list[Room]]) -> Room:
    return rooms_by_type["kitchen"][0]


@pytest.fixture(scope="session")
def kitchen_dir(tmp_path_factory: pytest.TempPathFactory, catalog: Catalog) -> Path:
    """A scene directory holding kitchen_000/room.usda and five layouts."""
    from sgdata.usd.scene_dirs import write_layouts, write_rooms

    out = tmp_path_factory.mktemp("scenes")
    write_rooms(out, "kitchen", count=1, seed=0, catalog=catalog)
    write_layouts(out / "kitchen_000", count=5, seed=0, catalog=catalog)
    return out / "kitchen_000"
