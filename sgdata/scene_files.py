"""File names inside a scene directory: the base ``room.usda`` and its ``layout_<k>.usda`` layers.

Shared by the USD writer (``sgdata rooms`` / ``sgdata layouts``) and the dataset's path
templates, so neither stage imports the other.
"""

from __future__ import annotations

from pathlib import Path

__all__ = ["ROOM_FILE", "LAYOUT_FILE", "room_file", "layout_file"]

ROOM_FILE = "room.usda"  # a room's base layer; layouts sublayer it as "./room.usda"
LAYOUT_FILE = "layout_{index}.usda"  # layout k, next to its room.usda


def room_file(room_dir: Path) -> Path:
    """The base stage of a room directory."""
    return room_dir / ROOM_FILE


def layout_file(room_dir: Path, index: int) -> Path:
    """The layer of layout ``index`` in a room directory."""
    return room_dir / LAYOUT_FILE.format(index=index)
