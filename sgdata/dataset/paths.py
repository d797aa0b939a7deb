"""Where things live in a dataset directory: path templates and observation ids.

All paths are relative to the dataset root and use ``/`` on every platform (they are also the
``files[].path`` entries of ``dataset.json``)::

    dataset.json                              the manifest
    README.md                                 the dataset card (Hugging Face front matter)
    croissant.json                            MLCommons Croissant metadata
    scenes/<room_id>/room.usda                the base room
    scenes/<room_id>/layout_<k>.usda          layout k as a USD layer over the base
    scenes/<room_id>/source.usda              a user's room ([rooms] files), flattened
    scenes/textures/<kind>_<v>_<size>px.png   texture images the textured rooms share
    observations/<split>/<room_id>.parquet    one row per view of the room
    triplets/<split>.parquet                  one row per triplet of the split
"""

from __future__ import annotations

from pathlib import Path
from typing import NamedTuple

from sgdata.errors import DatasetError
from sgdata.scene_files import LAYOUT_FILE, ROOM_FILE, TEXTURES_DIR

__all__ = [
    "MANIFEST",
    "CARD",
    "CROISSANT",
    "OBSERVATIONS",
    "TRIPLETS",
    "SCENES",
    "SCENE_ROOM",
    "SCENE_LAYER",
    "SCENE_TEXTURES",
    "SPLITS",
    "OUTPUTS",
    "ObsKey",
    "obs_id",
    "parse_obs_id",
    "observations_path",
    "triplets_path",
    "scene_dir",
]

MANIFEST = "dataset.json"
CARD = "README.md"
CROISSANT = "croissant.json"
OBSERVATIONS = "observations/{split}/{room_id}.parquet"
TRIPLETS = "triplets/{split}.parquet"
SCENES = "scenes/{room_id}"
SCENE_ROOM = SCENES + "/" + ROOM_FILE
SCENE_LAYER = SCENES + "/" + LAYOUT_FILE.replace("{index}", "{layout}")
SCENE_TEXTURES = SCENES.split("/")[0] + "/" + TEXTURES_DIR  # beside the room directories
SPLITS = ("train", "val", "test")  # the split names a dataset may hold, in this order
# What a generation writes at the top of a dataset directory (``--force`` removes exactly these).
OUTPUTS = (MANIFEST, CARD, CROISSANT, *(t.split("/")[0] for t in (SCENES, OBSERVATIONS, TRIPLETS)))

_FORBIDDEN_IN_ROOM_ID = ("/", "\\", "..")


class ObsKey(NamedTuple):
    """The parts of a synthetic observation id."""

    room_id: str
    layout: int
    i: int
    j: int
    heading: int


def _check_room_id(room_id: str) -> None:
    if not room_id or any(s in room_id for s in _FORBIDDEN_IN_ROOM_ID):
        raise DatasetError(
            f"room id {room_id!r}: expected a non-empty name without '/', '\\' or '..'"
        )


def obs_id(room_id: str, layout: int, i: int, j: int, heading: int) -> str:
    """The id of a synthetic view: ``<room_id>/<layout>/<grid_i>/<grid_j>/<heading>``."""
    _check_room_id(room_id)
    return f"{room_id}/{int(layout)}/{int(i)}/{int(j)}/{int(heading)}"


def parse_obs_id(value: str) -> ObsKey:
    """The inverse of :func:`obs_id`.

    Raises:
        DatasetError: ``value`` is not of the form ``<room_id>/<layout>/<i>/<j>/<heading>``.
    """
    parts = value.split("/")
    try:
        if len(parts) != 5 or not parts[0]:
            raise ValueError
        layout, i, j, heading = (int(p) for p in parts[1:])
    except ValueError:
        raise DatasetError(
            f"observation id {value!r}: expected <room_id>/<layout>/<grid_i>/<grid_j>/<heading>"
        ) from None
    return ObsKey(parts[0], layout, i, j, heading)


def _check_split(split: str) -> None:
    if split not in SPLITS:
        raise DatasetError(f"split {split!r}: expected one of {', '.join(SPLITS)}")


def observations_path(split: str, room_id: str) -> str:
    """Relative path of a room's observation shard."""
    _check_split(split)
    _check_room_id(room_id)
    return OBSERVATIONS.format(split=split, room_id=room_id)


def triplets_path(split: str) -> str:
    """Relative path of a split's triplet table."""
    _check_split(split)
    return TRIPLETS.format(split=split)


def scene_dir(root: Path, room_id: str) -> Path:
    """A room's scene directory under a dataset root."""
    _check_room_id(room_id)
    return root / SCENES.format(room_id=room_id)
