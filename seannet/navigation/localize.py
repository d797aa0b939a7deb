"""A moved module, kept as an alias for one release (CHANGELOG 2026-12-02)."""

import warnings
from typing import Any

from seannet.navigation import map_localization as _moved_to

__all__ = list(_moved_to.__all__)

warnings.warn(
    "seannet.navigation.localize moved to seannet.navigation.map_localization",
    DeprecationWarning,
    stacklevel=2,
)


def __getattr__(name: str) -> Any:
    return getattr(_moved_to, name)
