"""The class names a labeler may type: the catalog's, plus a user map of other names onto them."""

from __future__ import annotations

import tomllib
from dataclasses import dataclass, field
from pathlib import Path

from sgdata.errors import ConfigError
from sgdata.world.catalog import Catalog, load_catalog

__all__ = ["ClassNames", "load_class_names"]


@dataclass(frozen=True)
class ClassNames:
    """Catalog classes in catalog order, and extra names -> catalog class."""

    catalog: tuple[str, ...]
    mapped: dict[str, str] = field(default_factory=dict)

    def resolve(self, name: str) -> str | None:
        """The catalog class a typed name stands for; None when unknown."""
        if name in self.mapped:
            return self.mapped[name]
        return name if name in self.catalog else None

    def all_names(self) -> list[str]:
        """Every name the page offers: catalog classes, then mapped names."""
        return [*self.catalog, *(n for n in self.mapped if n not in self.catalog)]


def load_class_names(class_map: Path | None = None, catalog: Catalog | None = None) -> ClassNames:
    """The catalog's class names plus the names of a class-mapping TOML file.

    The file maps each extra name to a catalog class, one ``name = "CatalogClass"`` pair a line
    (quote names with spaces: ``"coffee mug" = "Mug"``).

    Raises:
        ConfigError: the file is missing, not TOML, or maps onto a class the catalog lacks.
    """
    catalog = catalog or load_catalog()
    names = tuple(catalog.names())
    if class_map is None:
        return ClassNames(names)
    path = Path(class_map)
    try:
        raw = tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise ConfigError(f"{path}: class map not found") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ConfigError(f"{path}: cannot read the class map ({exc})") from None
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{path}: not valid TOML ({exc})") from None
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
    return ClassNames(names, mapped)
