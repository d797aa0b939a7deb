"""Room recipes: per room type, what it holds and how it is arranged (``assets/rooms.toml``)."""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import cache
from importlib import resources
from pathlib import Path
from typing import Any

from sgdata.errors import CatalogError
from sgdata.fileio import read_toml
from sgdata.world.catalog import Catalog

__all__ = ["ROOM_TYPES", "CountedClass", "RoomRecipe", "load_room_recipes", "never_placed"]

ROOM_TYPES = ("kitchen", "living_room", "bedroom", "bathroom")
SIDES = ("any", "front", "sides")


@dataclass(frozen=True)
class CountedClass:
    """A class to add to a room, how many, and an optional anchor class."""

    class_name: str
    count: tuple[int, int]  # inclusive range
    # furniture: stand beside (and face) an instance of this class; None: where the class's
    # catalog anchors say (a chair at a table, a desk or a wall), else anywhere free
    near: str | None = None
    above: str | None = None  # wall items: hang above an instance of this class
    side: str = "any"  # with `near`: which side of the anchor (any | front | sides)


@dataclass(frozen=True)
class RoomRecipe:
    """How to build one room type."""

    room_type: str
    size_min: tuple[float, float]
    size_max: tuple[float, float]
    height: tuple[float, float]
    signature: tuple[str, ...]
    runs: tuple[tuple[str, ...], ...]
    wall_items: tuple[CountedClass, ...]
    furniture: tuple[CountedClass, ...]
    small: tuple[CountedClass, ...]


def load_room_recipes(catalog: Catalog, path: str | Path | None = None) -> dict[str, RoomRecipe]:
    """Load and validate the room recipes against ``catalog``.

    Raises:
        CatalogError: naming the file, room type and field at fault.
    """
    resolved = Path(path) if path is not None else _default_path()
    return _load(str(resolved.resolve()), catalog)


def _default_path() -> Path:
    return Path(str(resources.files("sgdata_assets").joinpath("rooms.toml")))


@cache
def _load(path: str, catalog: Catalog) -> dict[str, RoomRecipe]:
    data = read_toml(Path(path), "room recipe file", error=CatalogError)
    table = data.get("room_types", {})
    missing = [t for t in ROOM_TYPES if t not in table]
    if missing:
        raise CatalogError(f"{path}: no [room_types.{missing[0]}] table")
    recipes = {t: _parse(path, t, table[t], catalog) for t in ROOM_TYPES}
    return {t: _with_catalog_rooms(recipe, catalog) for t, recipe in recipes.items()}


# Which list of a recipe places a class of each placement kind
_LIST_OF_PLACEMENT = {
    "floor": "furniture",
    "wall_floor": "furniture",
    "wall": "wall_items",
    "surface": "small",
}


def _with_catalog_rooms(recipe: RoomRecipe, catalog: Catalog) -> RoomRecipe:
    """``recipe`` with the classes whose catalog entry names its room type in ``rooms``
    appended to the list their placement kind fills (after the recipe's own, so a recipe
    without such classes draws exactly as before)."""
    added: dict[str, list[CountedClass]] = {}
    for spec in catalog.classes.values():
        for room_type, low, high in spec.rooms:
            if room_type not in ROOM_TYPES:
                raise CatalogError(
                    f"{catalog.source}: class {spec.name}: field 'rooms' names room type "
                    f"{room_type!r}; expected one of {', '.join(ROOM_TYPES)}"
                )
            if room_type == recipe.room_type:
                key = _LIST_OF_PLACEMENT[spec.placement]
                added.setdefault(key, []).append(CountedClass(spec.name, (low, high)))
    if not added:
        return recipe
    lists = {key: (*getattr(recipe, key), *items) for key, items in added.items()}
    return replace(recipe, **lists)


def never_placed(catalog: Catalog) -> list[str]:
    """The classes a user catalog adds to the shipped ones that no room recipe places (a run,
    a wall item, furniture or a small object; parts come only with their owners): they can
    appear in your own rooms only."""
    from sgdata.world.catalog import load_catalog

    shipped = load_catalog()
    placed = set()
    for recipe in load_room_recipes(catalog).values():
        placed.update(name for run in recipe.runs for name in run)
        placed.update(i.class_name for i in (*recipe.wall_items, *recipe.furniture, *recipe.small))
    return [name for name in catalog.classes if name not in shipped and name not in placed]


def _parse(path: str, room_type: str, entry: dict[str, Any], catalog: Catalog) -> RoomRecipe:
    where = f"{path}: room type {room_type}"

    def pair(key: str) -> tuple[float, float]:
        value = entry.get(key)
        if not (isinstance(value, list) and len(value) == 2 and 0 < value[0] <= value[1]):
            raise CatalogError(f"{where}: field {key!r} must be [low, high] with 0 < low <= high")
        return float(value[0]), float(value[1])

    def known(name: Any, key: str) -> str:
        if name not in catalog:
            raise CatalogError(f"{where}: field {key!r} names unknown class {name!r}")
        return str(name)

    def counted(key: str) -> tuple[CountedClass, ...]:
        items = []
        for item in entry.get(key, []):
            if not isinstance(item, dict) or "class" not in item:
                raise CatalogError(
                    f"{where}: field {key!r} needs entries like {{class = ..., count = [1, 2]}}"
                )
            count = item.get("count", [1, 1])
            if not (isinstance(count, list) and len(count) == 2 and 0 <= count[0] <= count[1]):
                raise CatalogError(
                    f"{where}: field {key!r}: class {item['class']}: count must be [low, high]"
                )
            near = item.get("near")
            above = item.get("above")
            side = item.get("side", "any")
            if side not in SIDES:
                raise CatalogError(
                    f"{where}: field {key!r}: class {item['class']}: side must be one of {SIDES}"
                )
            items.append(
                CountedClass(
                    class_name=known(item["class"], key),
                    count=(int(count[0]), int(count[1])),
                    near=known(near, key) if near is not None else None,
                    above=known(above, key) if above is not None else None,
                    side=side,
                )
            )
        return tuple(items)

    size_lo = entry.get("size_min")
    size_hi = entry.get("size_max")
    for key, value in (("size_min", size_lo), ("size_max", size_hi)):
        if not (isinstance(value, list) and len(value) == 2 and all(v > 1.5 for v in value)):
            raise CatalogError(f"{where}: field {key!r} must be [width, depth], each > 1.5 m")
    runs = tuple(tuple(known(name, "runs") for name in run) for run in entry.get("runs", []))
    return RoomRecipe(
        room_type=room_type,
        size_min=(float(size_lo[0]), float(size_lo[1])),
        size_max=(float(size_hi[0]), float(size_hi[1])),
        height=pair("height"),
        signature=tuple(known(name, "signature") for name in entry.get("signature", [])),
        runs=runs,
        wall_items=counted("wall_items"),
        furniture=counted("furniture"),
        small=counted("small"),
    )
