"""The error hierarchy: every user-facing failure is an SgdataError with a one-line message."""

from __future__ import annotations

__all__ = [
    "WorkerError",
    "SgdataError",
    "ConfigError",
    "CatalogError",
    "SceneError",
    "UsdError",
    "RenderError",
    "DatasetError",
    "one_line",
]


def one_line(text: object) -> str:
    """``text`` (often a library's multi-line message) on one line, for an error message."""
    return " ".join(str(text).split())


class SgdataError(Exception):
    """Base of every error the CLI reports as one line (exit code 2) instead of a traceback."""


class ConfigError(SgdataError):
    """A config value or command-line argument is out of range or malformed."""


class CatalogError(SgdataError):
    """The object catalog or room recipes are malformed (names the class and field)."""


class SceneError(SgdataError):
    """A room or layout cannot be built or is physically invalid."""


class UsdError(SgdataError):
    """A USD stage or layer is missing, unreadable, or fails USD's validators."""


class RenderError(SgdataError):
    """The renderer cannot start (no EGL) or a view request is invalid."""


class DatasetError(SgdataError):
    """A dataset on disk is missing, malformed, or of an unsupported format version."""


class WorkerError(SgdataError):
    """A room task failed on every try, its worker died, or the executor could not start."""
