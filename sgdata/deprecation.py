"""Deprecation shims: a public name or module that moved keeps importing from its old place for
one release, with a :class:`DeprecationWarning` that names the new place."""

from __future__ import annotations

import importlib
import warnings
from collections.abc import Callable, Mapping
from typing import Any

__all__ = ["moved_names", "warn_moved"]


def warn_moved(old: str, new: str, *, stacklevel: int = 3) -> None:
    """Warn that ``old`` (a module or ``module.name``) now lives at ``new``."""
    warnings.warn(
        f"{old} moved to {new}; import it from there (the old name goes in the next release)",
        DeprecationWarning,
        stacklevel=stacklevel,
    )


def moved_names(module: str, moves: Mapping[str, str]) -> Callable[[str], Any]:
    """A module-level ``__getattr__`` for ``module`` that serves each old name of ``moves``
    (old name -> ``"new.module:new_name"``) from its new home, with a warning."""

    def __getattr__(name: str) -> Any:
        target = moves.get(name)
        if target is None:
            raise AttributeError(f"module {module!r} has no attribute {name!r}")
        home, _, new_name = target.partition(":")
        warn_moved(f"{module}.{name}", f"{home}.{new_name}")
        return getattr(importlib.import_module(home), new_name)

    return __getattr__
