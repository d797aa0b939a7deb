"""The object catalog: class specs loaded from ``assets/catalog.toml`` and validated on load."""

from __future__ import annotations

import glob
from collections.abc import Sequence
from dataclasses import dataclass
from functools import cache
from importlib import resources
from pathlib import Path
from typing import Any

from sgdata.errors import CatalogError
from sgdata.fileio import read_toml
from sgdata.world.scene import Dynamics

__all__ = [
    "DEFAULT_MAX_TRIANGLES",
    "PLACEMENTS",
    "SIDES",
    "WALL",
    "ClassSpec",
    "Catalog",
    "MeshSource",
    "load_catalog",
    "default_catalog_path",
]

# How a class is put into a room:
#   floor       stands on the floor, anywhere free
#   wall_floor  stands on the floor with its back against a wall (counters, fridges, beds)
#   wall        hangs on a wall between wall_height[0] and wall_height[1] (bottom edge)
#   surface     rests on a top surface of one of `receptacles` or inside one of `containers`
#   part        created only as an attached part of another class's recipe (shelf boards)
PLACEMENTS = ("floor", "wall_floor", "wall", "surface", "part")

# Where a floor object belongs (see sgdata.world.arrangement): `anchors` lists the classes it
# stands at, facing them, and WALL for "back to a wall"; `anchor_sides` the sides of a class
# that others may stand at when it is their anchor, in its local frame (front = -Y).
WALL = "wall"
SIDES = ("front", "right", "back", "left")

_FIELDS = {
    "dynamics",
    "shape",
    "size_min",
    "size_max",
    "placement",
    "wall_height",
    "receptacles",
    "containers",
    "max_instances",
    "palette",
    "variants",
    "description",
    "anchors",
    "anchor_sides",
    "rooms",
    # a class made of mesh files (sgdata.world.mesh_assets) instead of a recipe
    "mesh",
    "scale",
    "up",
    "units",
    "front",
    "max_triangles",
}

# The recipe name a mesh class reports as its ``shape`` (no recipe of that name exists).
MESH_SHAPE = "mesh"
MESH_SCALES = ("keep", "fit")  # keep the file's true size (within bounds) | scale it into them
MESH_UPS = ("auto", "y", "z")  # the file's up axis; auto: measured against the size bounds
MESH_UNITS = ("auto", "m", "cm", "mm")  # the file's unit; auto: measured likewise
MESH_FRONTS = ("-y", "+y", "-x", "+x")  # the file's front axis, once its up axis is +Z
# triangles a mesh class draws per variant at most (sgdata.world.mesh_detail; 0: all): a
# 224-pixel view shows no more, and a CPU rasteriser pays for every triangle (bench/assets.py)
DEFAULT_MAX_TRIANGLES = 2_000


@dataclass(frozen=True)
class MeshSource:
    """Where a mesh class's variants come from and how its files are read (one per file)."""

    files: tuple[str, ...]  # absolute paths, sorted: variant k is files[k]
    pattern: str  # the ``mesh`` value as written (for messages)
    scale: str = "keep"  # one of MESH_SCALES
    up: str = "auto"  # one of MESH_UPS
    units: str = "auto"  # one of MESH_UNITS
    front: str = "-y"  # one of MESH_FRONTS
    recolor: bool = False  # a palette was given: its colours replace the main material's
    max_triangles: int = DEFAULT_MAX_TRIANGLES  # drawn per variant at most; 0: every triangle


@dataclass(frozen=True)
class ClassSpec:
    """Everything the generator needs to know about one object class."""

    name: str  # catalog name, AI2-THOR style CamelCase ("CoffeeMachine")
    dynamics: Dynamics
    shape: str  # procedural recipe name in sgdata.world.shapes
    size_min: tuple[float, float, float]  # width, depth, height lower bounds (m)
    size_max: tuple[float, float, float]  # ... upper bounds (m)
    placement: str  # one of PLACEMENTS
    wall_height: tuple[float, float]  # bottom-edge height range for `wall` placement (m)
    receptacles: tuple[str, ...]  # classes whose top surfaces it may rest on
    containers: tuple[str, ...]  # classes whose inside surfaces it may rest in
    max_instances: int  # per room; also the class's run of GCN node slots
    palette: tuple[tuple[float, float, float], ...]  # main colours, linear RGB in [0, 1]
    variants: int  # number of shape variants the recipe offers
    description: str = ""
    anchors: tuple[str, ...] = ()  # floor classes: what it stands at, in order of preference
    anchor_sides: tuple[str, ...] = ()  # sides others stand at; () = by placement (see below)
    mesh: MeshSource | None = None  # a class of mesh files (then ``shape`` is MESH_SHAPE)
    # the room types whose recipes place it, with how many per room: (type, low, high), added
    # to the shipped recipes by sgdata.world.room_recipes (how a new class gets into rooms)
    rooms: tuple[tuple[str, int, int], ...] = ()

    def sides_to_stand_at(self) -> tuple[str, ...]:
        """Sides of this class that an object anchored to it may stand at: ``anchor_sides``
        when given, else every side of a free-standing class and the front of one against a
        wall (a desk, a bed); none for the rest."""
        if self.anchor_sides:
            return self.anchor_sides
        return {"floor": SIDES, "wall_floor": ("front",)}.get(self.placement, ())


@dataclass(frozen=True, eq=False)  # hashed by identity: loaded once, cached
class Catalog:
    """The validated catalog: class specs by name, in file order."""

    classes: dict[str, ClassSpec]
    source: str  # path or resource name it was read from

    def __getitem__(self, name: str) -> ClassSpec:
        try:
            return self.classes[name]
        except KeyError:
            raise CatalogError(f"unknown object class {name!r} (not in {self.source})") from None

    def __contains__(self, name: object) -> bool:
        return name in self.classes

    def __len__(self) -> int:
        return len(self.classes)

    def names(self) -> list[str]:
        """Class names in catalog order (the order of the class vocabulary)."""
        return list(self.classes)


def default_catalog_path() -> Path:
    """The catalog shipped in ``assets/``."""
    return Path(str(resources.files("sgdata_assets").joinpath("catalog.toml")))


@cache
def _load_cached(path: str, extra: tuple[tuple[str, int, int], ...]) -> Catalog:
    return _parse(Path(path), tuple(Path(p) for p, _, _ in extra))


def _stamped(path: Path) -> tuple[str, int, int]:
    """A user catalog file's cache key: its path, modification time and size (an edited file
    is read again)."""
    try:
        stat = path.stat()
    except OSError:
        return (str(path), 0, -1)  # _parse names it missing
    return (str(path), stat.st_mtime_ns, stat.st_size)


def load_catalog(path: str | Path | None = None, *, extra: Sequence[str | Path] = ()) -> Catalog:
    """Load and validate a catalog TOML file (the shipped one by default), merged with the
    user's catalog files ``extra`` in order: a class of theirs is new (appended to the
    vocabulary) or overrides the fields it names of a class before it (in place). A user's
    class may name mesh files instead of a recipe (``mesh``, relative to its own file's folder):
    the files are found here, and read, checked and measured on first use
    (:func:`sgdata.world.mesh_assets.class_assets`).

    Raises:
        CatalogError: naming the file, the class and the field at fault (or the mesh file).
    """
    resolved = Path(path) if path is not None else default_catalog_path()
    extras = tuple(_stamped(Path(p).resolve()) for p in extra)
    return _load_cached(str(resolved.resolve()), extras)


def _read_table(path: Path) -> dict[str, Any]:
    data = read_toml(path, "catalog file", error=CatalogError)
    table = data.get("classes")
    if not isinstance(table, dict) or not table:
        raise CatalogError(f"{path}: expected a [classes.<Name>] table per object class")
    for name, entry in table.items():
        if not isinstance(entry, dict):
            raise CatalogError(f"{path}: class {name}: expected a table of fields")
    return table


def _parse(path: Path, extra: tuple[Path, ...] = ()) -> Catalog:
    entries: dict[str, tuple[Path, dict[str, Any]]] = {
        name: (path, entry) for name, entry in _read_table(path).items()
    }
    for user_file in extra:
        for name, entry in _read_table(user_file).items():
            if name in entries and "mesh" not in entry:
                entries[name] = (user_file, {**entries[name][1], **entry})
            elif name in entries:  # a recipe class turned into mesh files: no recipe fields
                kept = {k: v for k, v in entries[name][1].items() if k not in _RECIPE_ONLY}
                entries[name] = (user_file, {**kept, **entry})
            else:
                entries[name] = (user_file, dict(entry))
    specs = {name: _parse_class(where, name, entry) for name, (where, entry) in entries.items()}
    source = " + ".join(str(p) for p in (path, *extra))
    _check_references(Path(source), specs)
    return Catalog(classes=specs, source=source)


# fields of a recipe class that a mesh class (overriding it) does not inherit
_RECIPE_ONLY = {"shape", "variants", "palette"}


def _parse_class(path: Path, name: str, entry: Any) -> ClassSpec:
    where = f"{path}: class {name}"
    if not isinstance(entry, dict):
        raise CatalogError(f"{where}: expected a table of fields")
    unknown = set(entry) - _FIELDS
    if unknown:
        raise CatalogError(
            f"{where}: unknown field {sorted(unknown)[0]!r}; known: {sorted(_FIELDS)}"
        )
    is_mesh = "mesh" in entry
    if is_mesh:
        for recipe_only in ("shape", "variants"):
            if recipe_only in entry:
                raise CatalogError(
                    f"{where}: field {recipe_only!r} is for recipe classes; a class with "
                    f"'mesh' has one variant per file"
                )
    else:
        for mesh_only in sorted(_MESH_ONLY & set(entry)):
            raise CatalogError(f"{where}: field {mesh_only!r} needs a 'mesh' (files) field")
    needed = ("dynamics", "size_min", "size_max", "placement")
    for required in (*needed, *(() if is_mesh else ("shape", "palette"))):
        if required not in entry:
            raise CatalogError(f"{where}: missing field {required!r}")
    try:
        dynamics = Dynamics(entry["dynamics"])
    except ValueError:
        raise CatalogError(
            f"{where}: field 'dynamics' is {entry['dynamics']!r}; expected static, low or high"
        ) from None
    size_min = _triple(where, "size_min", entry["size_min"])
    size_max = _triple(where, "size_max", entry["size_max"])
    if any(lo > hi for lo, hi in zip(size_min, size_max, strict=True)):
        raise CatalogError(f"{where}: field 'size_min' exceeds 'size_max' {size_max}")
    placement = entry["placement"]
    if placement not in PLACEMENTS:
        raise CatalogError(
            f"{where}: field 'placement' is {placement!r}; expected one of {PLACEMENTS}"
        )
    wall_height = tuple(float(v) for v in entry.get("wall_height", (0.0, 0.0)))
    if len(wall_height) != 2 or wall_height[0] > wall_height[1]:
        raise CatalogError(f"{where}: field 'wall_height' must be [low, high] with low <= high")
    receptacles = _names(where, "receptacles", entry.get("receptacles", []))
    containers = _names(where, "containers", entry.get("containers", []))
    if placement == "surface" and not (receptacles or containers):
        raise CatalogError(f"{where}: placement 'surface' needs 'receptacles' or 'containers'")
    max_instances = entry.get("max_instances", 1)
    if not isinstance(max_instances, int) or max_instances < 1:
        raise CatalogError(f"{where}: field 'max_instances' must be an integer >= 1")
    variants = entry.get("variants", 1)
    if not isinstance(variants, int) or variants < 1:
        raise CatalogError(f"{where}: field 'variants' must be an integer >= 1")
    mesh = _mesh_source(path, where, entry) if is_mesh else None
    if mesh is not None:
        variants = len(mesh.files)
    palette = entry.get("palette", [_NEUTRAL])
    if not isinstance(palette, list) or not palette:
        raise CatalogError(
            f"{where}: field 'palette' must be a non-empty list of '#rrggbb' colours"
        )
    colors = tuple(_hex_color(where, c) for c in palette)
    anchors = _names(where, "anchors", entry.get("anchors", []))
    if anchors and placement != "floor":
        raise CatalogError(f"{where}: field 'anchors' is for placement 'floor' only")
    anchor_sides = _names(where, "anchor_sides", entry.get("anchor_sides", []))
    if any(side not in SIDES for side in anchor_sides) or len(set(anchor_sides)) < len(
        anchor_sides
    ):
        raise CatalogError(f"{where}: field 'anchor_sides' must list distinct sides of {SIDES}")
    return ClassSpec(
        name=name,
        dynamics=dynamics,
        shape=MESH_SHAPE if is_mesh else str(entry["shape"]),
        size_min=size_min,
        size_max=size_max,
        placement=placement,
        wall_height=(wall_height[0], wall_height[1]),
        receptacles=receptacles,
        containers=containers,
        max_instances=max_instances,
        palette=colors,
        variants=variants,
        description=str(entry.get("description", "")),
        anchors=anchors,
        anchor_sides=anchor_sides,
        mesh=mesh,
        rooms=_rooms(where, entry.get("rooms", {}), placement, max_instances),
    )


def _rooms(
    where: str, value: Any, placement: str, max_instances: int
) -> tuple[tuple[str, int, int], ...]:
    """The ``rooms`` field, ``{kitchen = [1, 2], ...}``: per room type, how many per room
    (the type names are checked against the recipes, sgdata.world.room_recipes)."""
    if not value:
        return ()
    if placement == "part":
        raise CatalogError(f"{where}: field 'rooms': a 'part' is placed by its owner's recipe")
    shape = "like {kitchen = [1, 2]} (room type = [low, high] per room)"
    if not isinstance(value, dict):
        raise CatalogError(f"{where}: field 'rooms' must be a table {shape}")
    out = []
    for room_type, count in sorted(value.items()):
        if not (
            isinstance(count, list)
            and len(count) == 2
            and all(isinstance(c, int) and not isinstance(c, bool) for c in count)
            and 0 <= count[0] <= count[1] <= max_instances
        ):
            raise CatalogError(
                f"{where}: field 'rooms': {room_type} = {count!r}; expected [low, high] with "
                f"0 <= low <= high <= max_instances ({max_instances})"
            )
        out.append((str(room_type), count[0], count[1]))
    return tuple(out)


_MESH_ONLY = {"scale", "up", "units", "front", "max_triangles"}
_NEUTRAL = "#b3b3b3"  # the palette of a mesh class that keeps its files' colours (unused)


def _mesh_source(path: Path, where: str, entry: dict[str, Any]) -> MeshSource:
    """The files of a ``mesh`` field (a glob or a list of them, relative to ``path``'s folder)
    and how to read them."""
    value = entry["mesh"]
    patterns = [value] if isinstance(value, str) else value
    if not (
        isinstance(patterns, list) and patterns and all(isinstance(p, str) and p for p in patterns)
    ):
        raise CatalogError(f"{where}: field 'mesh' must be a file glob or a list of them")
    files: list[str] = []
    for pattern in patterns:
        full = Path(pattern).expanduser()
        full = full if full.is_absolute() else path.parent / full
        matched = sorted(p for p in glob.glob(str(full), recursive=True) if Path(p).is_file())
        if not matched:
            raise CatalogError(
                f"{where}: field 'mesh' {pattern!r} matches no file (looked in "
                f"{full.parent}); fix the path or the pattern"
            )
        files += [str(Path(p).resolve()) for p in matched if str(Path(p).resolve()) not in files]
    options = {}
    for key, allowed in (
        ("scale", MESH_SCALES),
        ("up", MESH_UPS),
        ("units", MESH_UNITS),
        ("front", MESH_FRONTS),
    ):
        if key in entry:
            if entry[key] not in allowed:
                raise CatalogError(
                    f"{where}: field {key!r} is {entry[key]!r}; expected one of {allowed}"
                )
            options[key] = entry[key]
    if "max_triangles" in entry:
        limit = entry["max_triangles"]
        if isinstance(limit, bool) or not isinstance(limit, int) or limit < 0:
            raise CatalogError(
                f"{where}: field 'max_triangles' is {limit!r}; expected a whole number >= 0 "
                "(0 draws every triangle)"
            )
        options["max_triangles"] = limit
    return MeshSource(
        files=tuple(files),
        pattern=value if isinstance(value, str) else ", ".join(patterns),
        recolor="palette" in entry,
        **options,
    )


def _triple(where: str, key: str, value: Any) -> tuple[float, float, float]:
    ok = isinstance(value, list) and len(value) == 3
    ok = ok and all(isinstance(v, int | float) and v > 0 for v in value)
    if not ok:
        raise CatalogError(
            f"{where}: field {key!r} must be 3 positive numbers [width, depth, height]"
        )
    return (float(value[0]), float(value[1]), float(value[2]))


def _names(where: str, key: str, value: Any) -> tuple[str, ...]:
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        raise CatalogError(f"{where}: field {key!r} must be a list of class names")
    return tuple(value)


def _hex_color(where: str, text: Any) -> tuple[float, float, float]:
    if not (isinstance(text, str) and len(text) == 7 and text.startswith("#")):
        raise CatalogError(f"{where}: field 'palette' holds {text!r}; expected '#rrggbb'")
    try:
        rgb = [int(text[i : i + 2], 16) / 255.0 for i in (1, 3, 5)]
    except ValueError:
        raise CatalogError(f"{where}: field 'palette' holds {text!r}; expected '#rrggbb'") from None
    return (rgb[0], rgb[1], rgb[2])


def _check_references(path: Path, specs: dict[str, ClassSpec]) -> None:
    from sgdata.world.shapes import (
        RECIPES,  # late: shapes imports trimesh, the catalog file does not need it
    )

    for spec in specs.values():
        if spec.mesh is None and spec.shape not in RECIPES:
            raise CatalogError(
                f"{path}: class {spec.name}: field 'shape' is {spec.shape!r}; "
                f"no such recipe in sgdata.world.shapes"
            )
        for key in ("receptacles", "containers"):
            for other in getattr(spec, key):
                if other not in specs:
                    raise CatalogError(
                        f"{path}: class {spec.name}: field {key!r} names unknown class {other!r}"
                    )
        for other in spec.anchors:
            if other != WALL and (other not in specs or not specs[other].sides_to_stand_at()):
                raise CatalogError(
                    f"{path}: class {spec.name}: field 'anchors' names {other!r}; expected "
                    f"{WALL!r} or a class standing on the floor"
                )
