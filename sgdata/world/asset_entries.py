"""``sgdata assets add``: a catalog entry for a folder of mesh files, written after measuring them.

The entry goes into a user catalog file (``[catalog] files`` of a config): a class of the
shipped catalog keeps its rules and size bounds and only gets ``mesh`` (and the options given);
a new class gets its size bounds from the files' measured sizes (10 % either way), so it needs
its dynamics and placement, and ``--on`` receptacles when it rests on surfaces. The file is
rewritten only once the merged catalog loads with the new entry, so a bad mesh leaves it as it
was.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass
from pathlib import Path

from sgdata.errors import CatalogError
from sgdata.fileio import atomic_write_text
from sgdata.world.catalog import PLACEMENTS, ClassSpec, load_catalog
from sgdata.world.mesh_assets import MESH_FORMATS, MeshAsset, class_assets
from sgdata.world.room_recipes import load_room_recipes

__all__ = ["AddedClass", "add_asset_class"]

SIZE_MARGIN = 0.1  # a new class's bounds: its files' sizes, this share either way
# The largest side a new class may measure (m) by where it goes: a file past it is in other
# units, or not the object it names (a sofa is 2.5 m, a counter 4 m, a mug 0.1 m)
LARGEST_SIDE = {"floor": 5.0, "wall_floor": 5.0, "wall": 5.0, "surface": 2.0, "part": 2.0}
_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]*")


@dataclass(frozen=True)
class AddedClass:
    """What ``add_asset_class`` wrote and measured."""

    name: str
    catalog: Path  # the user catalog file written
    entry: str  # the TOML table written
    assets: tuple[MeshAsset, ...]  # the files, measured (variant order)
    new: bool  # a class the shipped catalog lacks
    appears: str  # where generated rooms will hold it, for people


def add_asset_class(
    folder: Path,
    class_name: str,
    catalog: Path,
    *,
    dynamics: str | None = None,
    placement: str | None = None,
    receptacles: tuple[str, ...] = (),
    containers: tuple[str, ...] = (),
    up: str | None = None,
    units: str | None = None,
    scale: str | None = None,
    front: str | None = None,
    rooms: dict[str, tuple[int, int]] | None = None,
) -> AddedClass:
    """Write (or replace) ``class_name``'s entry in ``catalog`` for the mesh files in
    ``folder``, and measure them. ``rooms`` (room type -> how many per room) puts the class
    into those room types' recipes: how a new class gets into generated rooms.

    Raises:
        CatalogError: no mesh file in ``folder``, a new class without dynamics or placement, a
            bad mesh, or an entry the merged catalog refuses (the file is left unchanged).
    """
    folder, catalog = Path(folder), Path(catalog)
    if not _NAME.fullmatch(class_name):
        raise CatalogError(f"class name {class_name!r}: expected a CamelCase name such as Mug")
    suffixes = sorted(
        {p.suffix.lower() for p in folder.glob("*") if p.suffix.lower() in MESH_FORMATS}
    )
    if not suffixes:
        raise CatalogError(
            f"{folder}: no mesh file ({', '.join(sorted(MESH_FORMATS))}); put the files there"
        )
    shipped = load_catalog()
    new = class_name not in shipped
    rel = Path(os.path.relpath(folder.resolve(), catalog.resolve().parent)).as_posix()
    fields: dict[str, object] = {"mesh": [f"{rel}/*{s}" for s in suffixes]}
    if len(suffixes) == 1:
        fields["mesh"] = f"{rel}/*{suffixes[0]}"
    options = {"up": up, "units": units, "scale": scale, "front": front}
    fields.update({k: v for k, v in options.items() if v is not None})
    if dynamics is not None:
        fields["dynamics"] = dynamics
    if placement is not None:
        if placement not in PLACEMENTS:
            raise CatalogError(f"placement {placement!r}: expected one of {PLACEMENTS}")
        fields["placement"] = placement
    if receptacles:
        fields["receptacles"] = list(receptacles)
    if containers:
        fields["containers"] = list(containers)
    if rooms:
        fields["rooms"] = {t: list(count) for t, count in rooms.items()}
        if new:  # a room may hold as many as its entry asks (each instance takes a GCN slot)
            fields["max_instances"] = max(1, *(high for _, high in rooms.values()))
    if new:
        if dynamics is None or placement is None:
            raise CatalogError(
                f"class {class_name} is not in the shipped catalog: give --dynamics and "
                "--placement (and --on for surface placement)"
            )
        fields["size_min"], fields["size_max"] = [0.001] * 3, [1000.0] * 3
    before = catalog.read_text(encoding="utf-8") if catalog.is_file() else ""
    text = _with_entry(before, class_name, fields)
    if new:  # measure once with open bounds, then bound the class by what was measured
        assets = _load(catalog, text, class_name)
        _check_plausible(assets, str(placement), catalog, before)
        lo = [min(a.size[k] for a in assets) * (1 - SIZE_MARGIN) for k in range(3)]
        hi = [max(a.size[k] for a in assets) * (1 + SIZE_MARGIN) for k in range(3)]
        fields["size_min"] = [round(v, 3) for v in lo]
        fields["size_max"] = [round(v, 3) for v in hi]
        text = _with_entry(before, class_name, fields)
    assets = _load(catalog, text, class_name)
    appears = _where_it_appears(load_catalog(extra=[catalog])[class_name], new)
    return AddedClass(class_name, catalog, _table(class_name, fields), assets, new, appears)


def _where_it_appears(spec: ClassSpec, new: bool) -> str:
    """Where generated rooms will hold the class: the room types its entry names (and on
    what), the shipped class's places for an override, or nowhere."""
    on = [*spec.receptacles, *(f"in {c}" for c in spec.containers)]
    resting = f", on {', '.join(on)}" if spec.placement == "surface" and on else ""
    added = [f"{t} rooms ({lo}-{hi} per room{resting})" for t, lo, hi in spec.rooms]
    if not new:
        added.insert(0, f"wherever the shipped {spec.name} stands")
    if not added:
        return (
            "in no generated room: no room recipe places a new class; give --rooms "
            "kitchen:1-2 (any of its room types), or put it in your own rooms ([rooms] files)"
        )
    return "; ".join(added)


def _check_plausible(
    assets: tuple[MeshAsset, ...], placement: str, catalog: Path, before: str
) -> None:
    """Refuse a new class whose files measure past what its placement allows (the catalog
    put back as it was), naming the size and the fix."""
    limit = LARGEST_SIDE[placement]
    for asset in assets:
        if max(asset.size) > limit:
            _restore(catalog, before)
            size = " x ".join(f"{v:g}" for v in asset.size)
            raise CatalogError(
                f"{asset.path}: {size} m looks wrong for a {placement} object (at most {limit:g} m "
                f"a side); if the file is in millimetres or centimetres give --units mm or cm, "
                "or --scale fit to fit it into the class's bounds"
            )


def _restore(catalog: Path, before: str) -> None:
    if before:
        atomic_write_text(catalog, before)
    else:
        catalog.unlink(missing_ok=True)


def _load(catalog: Path, text: str, class_name: str) -> tuple[MeshAsset, ...]:
    """Write ``text`` to ``catalog`` and load it merged; put the old file back on failure."""
    before = catalog.read_bytes() if catalog.is_file() else None
    atomic_write_text(catalog, text)
    try:
        merged = load_catalog(extra=[catalog])
        load_room_recipes(merged)  # its rooms name known room types
        return class_assets(merged[class_name])
    except CatalogError:
        if before is None:
            catalog.unlink()
        else:
            catalog.write_bytes(before)
        raise


def _toml(value: object) -> str:
    if isinstance(value, dict):
        return "{ " + ", ".join(f"{k} = {_toml(v)}" for k, v in value.items()) + " }"
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(value, list):
        return "[" + ", ".join(_toml(v) for v in value) + "]"
    return repr(value)


def _table(name: str, fields: dict[str, object]) -> str:
    lines = [f"[classes.{name}]"] + [f"{k} = {_toml(v)}" for k, v in fields.items()]
    return "\n".join(lines) + "\n"


def _with_entry(text: str, name: str, fields: dict[str, object]) -> str:
    """``text`` with the ``[classes.<name>]`` table replaced (or appended)."""
    lines = text.splitlines(keepends=True)
    start = next((i for i, ln in enumerate(lines) if ln.strip() == f"[classes.{name}]"), None)
    if start is None:
        head = text if not text or text.endswith("\n") else text + "\n"
        return head + ("\n" if head else "") + _table(name, fields)
    end = next(
        (i for i in range(start + 1, len(lines)) if lines[i].lstrip().startswith("[")), len(lines)
    )
    while end > start + 1 and not lines[end - 1].strip():
        end -= 1
    return "".join(lines[:start]) + _table(name, fields) + "".join(lines[end:])
