"""The SeanNet error hierarchy: each user-facing failure is a one-line SeannetError."""

from __future__ import annotations

__all__ = [
    "SeannetError",
    "ModelError",
    "CheckpointError",
    "DataError",
    "MapError",
    "NavigationError",
    "MethodError",
]


class SeannetError(Exception):
    """Base of every error the CLI reports as one line instead of a traceback."""


class ModelError(SeannetError):
    """A model cannot be built: a bad hyper-parameter, or pretrained weights that do not fit."""


class CheckpointError(SeannetError):
    """A training checkpoint is missing, malformed or from an incompatible model."""


class DataError(SeannetError):
    """Model input is malformed: a batch, a dataset record or the word-vector table."""


class MapError(SeannetError):
    """A topological map is missing, malformed, or belongs to another run or dataset."""


class NavigationError(SeannetError):
    """A localization or navigation request cannot run: no threshold, no room, no episode."""


class MethodError(SeannetError):
    """A localization method (``seannet.methods``) cannot be loaded, or broke a check of the
    interface: the message names the method and the check."""
