"""File names inside a scene directory: the base ``room.usda`` and its ``layout_<k>.usda`` layers.

A room a user brought (``[rooms] files``) also holds ``source.usda``, the flattened copy of the
user's stage that its ``room.usda`` (the tag layer) sublayers.

Textured rooms share their texture images in ``textures/`` beside the room directories
(``<scenes>/textures/<kind>_<variant>_<size>px.png``): every room of a dataset uses the same
images, so they are written once, and a room's stages refer to them as ``../textures/...``.

Shared by the USD writer (``sgdata rooms`` / ``sgdata layouts``) and the dataset's path
templates, so neither stage imports the other.
"""

from __future__ import annotations

from pathlib import Path

__all__ = [
    "ROOM_FILE",
    "LAYOUT_FILE",
    "SOURCE_FILE",
    "TEXTURES_DIR",
    "room_file",
    "layout_file",
    "textures_dir",
]

ROOM_FILE = "room.usda"  # a room's base layer; layouts sublayer it as "./room.usda"
LAYOUT_FILE = "layout_{index}.usda"  # layout k, next to its room.usda
SOURCE_FILE = "source.usda"  # a user room's stage, flattened; its room.usda sublayers it
TEXTURES_DIR = "textures"  # shared texture images, beside the room directories


def room_file(room_dir: Path) -> Path:
    """The base stage of a room directory."""
    return room_dir / ROOM_FILE


def layout_file(room_dir: Path, index: int) -> Path:
    """The layer of layout ``index`` in a room directory."""
    return room_dir / LAYOUT_FILE.format(index=index)


def textures_dir(room_dir: Path) -> Path:
    """The texture folder a room directory's stages refer to: ``<room_dir>/../textures``."""
    return room_dir.parent / TEXTURES_DIR
