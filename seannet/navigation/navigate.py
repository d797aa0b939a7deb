"""A moved module, kept as an alias for one release (CHANGELOG 2026-12-02)."""

import warnings
from typing import Any

from seannet.navigation import benchmark as _moved_to

__all__ = list(_moved_to.__all__)

warnings.warn(
    "seannet.navigation.navigate moved to seannet.navigation.benchmark",
    DeprecationWarning,
    stacklevel=2,
)


def __getattr__(name: str) -> Any:
    return getattr(_moved_to, name)
