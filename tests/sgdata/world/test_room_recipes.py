"""A catalog entry's ``rooms`` puts its class into the room recipes: how a new class gets into
generated rooms; a recipe no entry names draws exactly as before."""

from __future__ import annotations

from pathlib import Path

import pytest

from sgdata.errors import CatalogError
from sgdata.world.catalog import load_catalog
from sgdata.world.room_recipes import load_room_recipes, never_placed
from sgdata.world.rooms import generate_room
from tests.asset_meshes import plate

CHARGER = """\
[classes.Charger]
mesh = "p.stl"
dynamics = "high"
placement = "surface"
receptacles = ["CounterTop", "DiningTable"]
size_min = [0.2, 0.2, 0.01]
size_max = [0.3, 0.3, 0.03]
max_instances = 3
"""


def _catalog(tmp_path: Path, extra: str = "") -> Path:
    (tmp_path / "p.stl").write_bytes(plate().export(file_type="stl"))
    path = tmp_path / "user.toml"
    path.write_text(CHARGER + extra, encoding="utf-8")
    return path


def test_rooms_put_a_new_class_into_its_room_types_only(tmp_path: Path) -> None:
    catalog = load_catalog(extra=[_catalog(tmp_path, "rooms = { kitchen = [2, 3] }\n")])
    recipes = load_room_recipes(catalog)
    shipped = load_room_recipes(load_catalog())
    kitchen = recipes["kitchen"]
    assert kitchen.small[: len(shipped["kitchen"].small)] == shipped["kitchen"].small
    assert kitchen.small[-1].class_name == "Charger" and kitchen.small[-1].count == (2, 3)
    assert recipes["bathroom"] == shipped["bathroom"]  # not named: unchanged
    assert never_placed(catalog) == []
    room = generate_room("kitchen", 0, 7, catalog)
    held = [o for o in room.objects if o.class_name == "Charger"]
    assert 2 <= len(held) <= 3
    # a room type no entry names is the same room, object for object
    bathroom = generate_room("bathroom", 0, 7, catalog)
    assert bathroom.objects == generate_room("bathroom", 0, 7, load_catalog()).objects


def test_a_new_class_no_recipe_places_is_named(tmp_path: Path) -> None:
    assert never_placed(load_catalog(extra=[_catalog(tmp_path)])) == ["Charger"]


@pytest.mark.parametrize(
    ("rooms", "message"),
    [
        ("{ garage = [1, 1] }", "names room type 'garage'"),
        ("{ kitchen = [2, 1] }", "expected [low, high]"),
        ("{ kitchen = [1, 4] }", "max_instances (3)"),
        ('"kitchen"', "must be a table"),
    ],
)
def test_bad_rooms_are_one_line(tmp_path: Path, rooms: str, message: str) -> None:
    with pytest.raises(CatalogError, match="Charger") as caught:
        load_room_recipes(load_catalog(extra=[_catalog(tmp_path, f"rooms = {rooms}\n")]))
    assert message in str(caught.value) and "\n" not in str(caught.value)
