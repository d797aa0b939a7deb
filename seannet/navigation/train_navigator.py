"""A moved module, kept as an alias for one release (CHANGELOG 2026-12-02)."""

import warnings
from typing import Any

from seannet.navigation import navigator_training as _moved_to

__all__ = list(_moved_to.__all__)

warnings.warn(
    "seannet.navigation.train_navigator moved to seannet.navigation.navigator_training",
    DeprecationWarning,
    stacklevel=2,
)


def __getattr__(name: str) -> Any:
    return getattr(_moved_to, name)
