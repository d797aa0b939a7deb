"""The class names a labeler may type: the catalog's, plus a user map of other names onto them."""

from __future__ import annotations

import difflib
from dataclasses import dataclass, field
from pathlib import Path

from sgdata.errors import ConfigError
from sgdata.fileio import read_toml
from sgdata.world.catalog import Catalog, load_catalog

__all__ = ["ClassNames", "load_class_names"]


@dataclass(frozen=True)
class ClassNames:
    """Catalog classes in catalog order, and extra names -> catalog class."""

    catalog: tuple[str, ...]
    mapped: dict[str, str] = field(default_factory=dict)
    # catalog classes others rest *inside* (some class lists them as `containers`): the only
    # ones a contained box is proposed to be `in`
    containers: frozenset[str] = frozenset()

    def resolve(self, name: str) -> str | None:
        """The catalog class a typed name stands for; None when unknown."""
        if name in self.mapped:
            return self.mapped[name]
        return name if name in self.catalog else None

    def all_names(self) -> list[str]:
        """Every name the page offers: catalog classes, then mapped names."""
        return [*self.catalog, *(n for n in self.mapped if n not in self.catalog)]

    def closest(self, name: str, n: int = 3) -> list[str]:
        """Up to ``n`` offered names most like ``name`` (ignoring case), best first."""
        by_lower = {x.lower(): x for x in self.all_names()}
        near = difflib.get_close_matches(name.lower(), list(by_lower), n=n, cutoff=0.4)
        return [by_lower[x] for x in near]

    def unknown(self, name: str) -> str:
        """The one-line message for a typed name that is neither a class nor mapped."""
        near = self.closest(name)
        hint = f"closest: {', '.join(near)}; " if near else ""
        target = near[0] if near else "CatalogClass"
        return (
            f"unknown class {name!r}; {hint}pick one, or map the name in a --classes TOML file "
            f'(a line "{name}" = "{target}") and restart `sgdata label` with it'
        )


def load_class_names(class_map: Path | None = None, catalog: Catalog | None = None) -> ClassNames:
    """The catalog's class names plus the names of a class-mapping TOML file.

    The file maps each extra name to a catalog class, one ``name = "CatalogClass"`` pair a line
    (quote names with spaces: ``"coffee mug" = "Mug"``).

    Raises:
        ConfigError: the file is missing, not TOML, or maps onto a class the catalog lacks.
    """
    catalog = catalog or load_catalog()
    names = tuple(catalog.names())
    containers = frozenset(c for n in names for c in catalog[n].containers)
    if class_map is None:
        return ClassNames(names, containers=containers)
    path = Path(class_map)
    raw = read_toml(path, "class map")
    mapped = {}
    for name, target in raw.items():
        if not isinstance(target, str):
            raise ConfigError(
                f'{path}: {name!r} maps to {target!r}; expected name = "CatalogClass" pairs'
            )
        if target not in catalog:
            raise ConfigError(
                f"{path}: {name!r} maps to {target!r}, which is not a catalog class "
                "(see assets/catalog.toml)"
            )
        if not name.strip():
            raise ConfigError(f"{path}: an empty class name; expected a name to type")
        mapped[name] = target
    return ClassNames(names, mapped, containers)
