"""A class file (``--classes MAP.toml``): classes the catalog lacks, and aliases of its own.

One pair a line, at the top level or under ``[classes]``. A dynamics value names a new class;
a catalog class name makes the name an alias, read as that catalog class (its dynamics,
placement rules and GCN slots) -- what ``sgdata generate`` needs for a dataset::

    [classes]
    Teapot = "high"          # a class of its own (sgdata tag, preview, layouts)
    Radiator = "static"
    Teacup = "Cup"           # an alias: every Teacup prim is a Cup
    "coffee mug" = "Mug"

``Name = { dynamics = "high" }`` works too.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from sgdata.errors import ConfigError
from sgdata.fileio import read_toml
from sgdata.world.catalog import Catalog, load_catalog
from sgdata.world.scene import Dynamics

__all__ = ["UserClasses", "load_user_classes", "read_class_file"]


@dataclass(frozen=True)
class UserClasses:
    """What a class file says, both kinds of line together."""

    dynamics: dict[str, Dynamics] = field(default_factory=dict)  # every name of the file
    aliases: dict[str, str] = field(default_factory=dict)  # name -> the catalog class it is


def read_class_file(path: Path | None, catalog: Catalog | None = None) -> UserClasses:
    """New classes with their dynamics, and aliases of catalog classes; empty for ``None``.

    Args:
        path: the class file.
        catalog: the catalog aliases point into (the shipped one when ``None``; loaded only
            when a value is not a dynamics).

    Raises:
        ConfigError: the file is missing or not TOML, or a value is neither static, low, high
            nor a catalog class (the message names the file and the class).
    """
    if path is None:
        return UserClasses()
    path = Path(path)
    raw = read_toml(path, "class file")
    table = raw.get("classes", raw) if isinstance(raw.get("classes"), dict) else raw
    dynamics: dict[str, Dynamics] = {}
    aliases: dict[str, str] = {}
    for name, value in table.items():
        given = value.get("dynamics") if isinstance(value, dict) else value
        try:
            dynamics[str(name)] = Dynamics(str(given))
            continue
        except ValueError:
            pass
        if isinstance(value, str):
            catalog = catalog or load_catalog()
            if value in catalog:
                aliases[str(name)] = value
                dynamics[str(name)] = Dynamics(catalog[value].dynamics)
                continue
        raise ConfigError(
            f'{path}: class {name!r} is {given!r}; expected "static", "low", "high" or a '
            f'catalog class such as "Mug" (see assets/catalog.toml)'
        )
    return UserClasses(dynamics, aliases)


def load_user_classes(path: Path | None) -> dict[str, Dynamics]:
    """Class name -> dynamics from a class file (aliases get their catalog class's); empty
    for ``None``. See :func:`read_class_file`."""
    return read_class_file(path).dynamics
