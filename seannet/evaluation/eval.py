"""Deprecated: ``seannet.evaluation.eval`` moved to :mod:`seannet.evaluation.run_eval` (its
``SCENE_TERMS`` and ``scene_term`` to :mod:`seannet.model.specs`). Kept as an alias for one
release (CHANGELOG 2026-12-02)."""

import warnings
from typing import Any

from seannet.evaluation import run_eval as _moved_to
from seannet.model import specs as _specs

__all__ = list(_moved_to.__all__)

warnings.warn(
    "seannet.evaluation.eval moved to seannet.evaluation.run_eval",
    DeprecationWarning,
    stacklevel=2,
)


def __getattr__(name: str) -> Any:
    if name in ("SCENE_TERMS", "scene_term"):  # served from their new home too
        return getattr(_specs, name)
    return getattr(_moved_to, name)
