"""Tests for the shipped object catalog and the catalog loader's validation."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from sgdata.errors import CatalogError
from sgdata.world.catalog import PLACEMENTS, load_catalog
from sgdata.world.scene import Dynamics
from sgdata.world.shapes import build_shape

CATALOG_PATH = Path(__file__).resolve().parents[3] / "assets" / "catalog.toml"
CATALOG = load_catalog(CATALOG_PATH)
SLOT_BUDGET = 256  # GCN node slots M

STATIC = """CounterTop Cabinet Drawer Sink SinkBasin Stove StoveBurner StoveKnob Fridge Window Shelf
Toilet Bathtub BathtubBasin Mirror Painting LightSwitch TowelHolder ToiletPaperHanger""".split()
LOW = """Microwave CoffeeMachine ShelvingUnit DiningTable DeskLamp ArmChair Toaster SideTable
RoomDecor CoffeeTable TVStand Sofa Safe Television Desk Dresser Bed HousePlant FloorLamp""".split()
HIGH_FURNITURE = """GarbageCan Stool Chair GarbageBag LaundryHamper Desktop VacuumCleaner Ottoman
DogBed""".split()
HIGH_SMALL = """Mug Cup Bowl Plate Pot Pan Kettle Apple Tomato Potato Lettuce Bread Egg Knife Fork
Spoon ButterKnife Spatula Ladle Bottle WineBottle SoapBottle DishSponge PaperTowelRoll SaltShaker
PepperShaker Book Laptop RemoteControl CellPhone KeyChain Pillow Box Vase Statue Newspaper
CreditCard Pen Pencil AlarmClock CD TeddyBear BasketBall TennisRacket Watch TissueBox Candle
Towel HandTowel ToiletPaper SoapBar SprayBottle Plunger ScrubBrush Cloth""".split()
PARTS = ["CounterTop", "Drawer", "SinkBasin", "StoveBurner", "StoveKnob", "Shelf", "BathtubBasin"]


def test_shipped_catalog_loads() -> None:
    assert len(CATALOG) >= 95
    assert CATALOG.names()[0] == "CounterTop"  # file order is the vocabulary order
    for spec in CATALOG.classes.values():
        assert spec.placement in PLACEMENTS
        assert spec.description
        assert 2 <= len(spec.palette) <= 6, spec.name


def test_default_path_is_the_shipped_catalog() -> None:
    pytest.importorskip("sgdata_assets")  # present once the package is installed
    assert load_catalog().names() == CATALOG.names()


@pytest.mark.parametrize(
    ("names", "dynamics"),
    [
        (STATIC, Dynamics.STATIC),
        (LOW, Dynamics.LOW),
        (HIGH_FURNITURE, Dynamics.HIGH),
        (HIGH_SMALL, Dynamics.HIGH),
    ],
)
def test_dynamics_sets(names: list[str], dynamics: Dynamics) -> None:
    for name in names:
        assert name in CATALOG, f"{name} missing from the catalog"
        assert CATALOG[name].dynamics is dynamics, name


def test_parts_and_wall_classes() -> None:
    for name in PARTS:
        assert CATALOG[name].placement == "part", name
    for name in ["Window", "Mirror", "Painting", "LightSwitch", "TowelHolder", "ToiletPaperHanger"]:
        spec = CATALOG[name]
        assert spec.placement == "wall", name
        assert 0.0 < spec.wall_height[0] <= spec.wall_height[1] < 2.0, name


def test_slot_budget() -> None:
    total = sum(spec.max_instances for spec in CATALOG.classes.values())
    assert total <= SLOT_BUDGET, total


def test_sizes_are_sane() -> None:
    for spec in CATALOG.classes.values():
        assert all(0 < lo <= hi <= 3.5 for lo, hi in zip(spec.size_min, spec.size_max, strict=True))


def _surfaces(name: str, *, inside: bool) -> list[bool]:
    """For size_min and size_max: whether the class's recipe offers a surface of that kind."""
    spec = CATALOG[name]
    found = []
    for size in (spec.size_min, spec.size_max):
        build = build_shape(spec.shape, size, 0, spec.palette[0])
        found.append(any(s.inside == inside for s in build.surfaces))
    return found


def test_receptacles_and_containers_offer_surfaces() -> None:
    receptacles = {r for spec in CATALOG.classes.values() for r in spec.receptacles}
    containers = {c for spec in CATALOG.classes.values() for c in spec.containers}
    assert {"CounterTop", "Shelf", "Plate", "Bed", "Toilet", "Fridge"} <= receptacles
    assert {"SinkBasin", "BathtubBasin", "Bowl", "Pot", "GarbageCan", "Box"} <= containers
    for name in receptacles:
        assert all(_surfaces(name, inside=False)), f"{name} offers no top surface"
    for name in containers:
        assert all(_surfaces(name, inside=True)), f"{name} offers no inside surface"


@pytest.mark.parametrize(
    "name",
    [
        "CounterTop",
        "DiningTable",
        "CoffeeTable",
        "SideTable",
        "Desk",
        "Dresser",
        "TVStand",
        "Shelf",
        "Bed",
        "Sofa",
        "ArmChair",
        "Ottoman",
        "Stool",
        "Chair",
        "Toilet",
        "Microwave",
        "Fridge",
        "Plate",
    ],
)
def test_listed_receptacles_have_top_surfaces(name: str) -> None:
    assert all(_surfaces(name, inside=False)), name


@pytest.mark.parametrize(
    "name",
    ["SinkBasin", "BathtubBasin", "Bowl", "Pot", "Pan", "GarbageCan", "LaundryHamper", "Box"],
)
def test_listed_containers_have_inside_surfaces(name: str) -> None:
    assert all(_surfaces(name, inside=True)), name


def test_surface_classes_have_somewhere_to_go() -> None:
    for spec in CATALOG.classes.values():
        if spec.placement == "surface":
            assert spec.receptacles or spec.containers, spec.name
            for other in spec.receptacles + spec.containers:
                assert CATALOG[other].placement != "surface" or other in {
                    "Plate",
                    "Bowl",
                    "Pot",
                    "Pan",
                    "Box",
                    "Microwave",
                }, (spec.name, other)


def _broken(tmp_path: Path, name: str, old: str, new: str) -> Path:
    """A copy of the shipped catalog with one line of class ``name`` replaced."""
    text = CATALOG_PATH.read_text(encoding="utf-8")
    start = text.index(f"[classes.{name}]")
    end = text.index("\n\n", start)
    block = text[start:end]
    assert re.search(old, block), (name, old)
    text = text[:start] + re.sub(old, new, block, count=1) + text[end:]
    path = tmp_path / "catalog.toml"
    path.write_text(text, encoding="utf-8")
    return path


@pytest.mark.parametrize(
    ("name", "old", "new", "field"),
    [
        ("Mug", r'dynamics = "high"', 'dynamics = "fast"', "dynamics"),
        ("Chair", r"size_min = \[[^\]]*\]", "size_min = [9.0, 9.0, 9.0]", "size_min"),
        ("Apple", r'shape = "fruit"', 'shape = "no_such_recipe"', "shape"),
        ("Book", r"max_instances = 6", "max_instances = 6\ncolour = 3", "colour"),
        ("Sofa", r'placement = "wall_floor"', 'placement = "ceiling"', "placement"),
        ("Bowl", r"palette = \[", 'palette = ["red", ', "palette"),
        ("Cup", r'receptacles = \["CounterTop"', 'receptacles = ["Countertop"', "receptacles"),
        ("Window", r"wall_height = \[[^\]]*\]", "wall_height = [1.5, 1.0]", "wall_height"),
        ("Chair", r"anchors = \[[^\]]*\]", 'anchors = ["DinnerTable", "wall"]', "anchors"),
        ("Chair", r"anchors = \[[^\]]*\]", 'anchors = ["Mug"]', "anchors"),
        ("Mug", r'placement = "surface"', 'placement = "surface"\nanchors = ["wall"]', "anchors"),
        ("Bed", r"anchor_sides = \[[^\]]*\]", 'anchor_sides = ["top"]', "anchor_sides"),
    ],
)
def test_broken_entry_names_class_and_field(
    tmp_path: Path, name: str, old: str, new: str, field: str
) -> None:
    path = _broken(tmp_path, name, old, new)
    with pytest.raises(CatalogError) as info:
        load_catalog(path)
    message = str(info.value)
    assert f"class {name}" in message, message
    assert field in message, message


def test_missing_file_raises(tmp_path: Path) -> None:
    with pytest.raises(CatalogError, match="not found"):
        load_catalog(tmp_path / "nope.toml")


def test_palettes_are_in_range() -> None:
    colours = np.array([c for spec in CATALOG.classes.values() for c in spec.palette])
    assert colours.min() >= 0.0 and colours.max() <= 1.0


def test_floor_classes_know_where_they_belong() -> None:
    assert CATALOG["Chair"].anchors == ("DiningTable", "Desk", "wall")
    assert {"ArmChair", "Sofa", "Bed"} <= set(CATALOG["Ottoman"].anchors)
    assert CATALOG["DiningTable"].sides_to_stand_at() == ("front", "right", "back", "left")
    assert CATALOG["Desk"].sides_to_stand_at() == ("front",)  # it stands against a wall
    assert CATALOG["ArmChair"].sides_to_stand_at() == ("front",)
    assert CATALOG["Mug"].sides_to_stand_at() == ()
    for spec in CATALOG.classes.values():
        if spec.anchors:
            assert spec.placement == "floor", spec.name
