"""Scene directories on disk: ``<room>/room.usda`` and its ``<room>/layout_<k>.usda`` layers."""

from __future__ import annotations

from pathlib import Path

from sgdata.errors import ConfigError, SceneError
from sgdata.fileio import prepare_output_dir
from sgdata.scene_files import LAYOUT_FILE, ROOM_FILE, layout_file, room_file
from sgdata.seeds import appearance_seed, layouts_seed
from sgdata.usd.layout_layers import write_layout
from sgdata.usd.looks import read_room_parts
from sgdata.usd.room_io import catalog_geometry, read_room, write_room
from sgdata.usd.user_layouts import user_frame
from sgdata.world.appearance import AppearanceConfig, sample_appearance
from sgdata.world.catalog import Catalog, load_catalog
from sgdata.world.dynamics import DynamicsConfig, Layout, sample_layouts
from sgdata.world.poses import PosesConfig
from sgdata.world.room_checks import room_problems
from sgdata.world.rooms import generate_room
from sgdata.world.scene import Room

__all__ = [
    "write_rooms",
    "write_layouts",
    "load_base",
    "load_layout",
    "layout_indices",
    "layout_stage_file",
]


def write_rooms(
    out: Path,
    room_type: str,
    *,
    count: int,
    seed: int,
    first_index: int = 0,
    catalog: Catalog | None = None,
    appearance: AppearanceConfig | None = None,
) -> list[Room]:
    """Generate ``count`` rooms of ``room_type`` and write each as ``out/<room_id>/room.usda``.

    With ``appearance`` the rooms record their looks and (``appearance.textures``) are
    textured, their images shared in ``out/textures/``.

    Raises:
        ConfigError: bad count, room type or output directory (checked before any write).
    """
    if count < 1:
        raise ConfigError(f"--count must be >= 1, got {count}")
    catalog = catalog or load_catalog()
    rooms = [generate_room(room_type, first_index + i, seed, catalog) for i in range(count)]
    prepare_output_dir(out)
    geometry = catalog_geometry(catalog)
    for room in rooms:
        write_room(room, room_file(out / room.room_id), geometry=geometry, appearance=appearance)
    return rooms


def load_base(room_dir: Path) -> Room:
    """The base room of a room directory.

    Raises:
        ConfigError: ``room_dir`` is not a room directory.
    """
    if not room_dir.is_dir():
        raise ConfigError(
            f"{room_dir}: not a directory; expected a room directory holding {ROOM_FILE}"
        )
    if not room_file(room_dir).is_file():
        raise ConfigError(
            f"{room_dir}: no {ROOM_FILE}; expected a directory written by 'sgdata rooms'"
        )
    return read_room(room_file(room_dir))


def write_layouts(
    room_dir: Path,
    *,
    count: int,
    seed: int,
    catalog: Catalog | None = None,
    config: DynamicsConfig | None = None,
    poses: PosesConfig | None = None,
    appearance: AppearanceConfig | None = None,
) -> list[Layout]:
    """Sample ``count`` layouts of the room in ``room_dir`` and write ``layout_<k>.usda``.

    Layout 0 is the base arrangement (a layer with no moves). The layouts' seed is derived
    from the room's own seed and ``seed``, so two rooms given the same ``seed`` differ. With
    ``appearance.randomize`` every layout, 0 included, also draws its light and the looks of
    its low- and high-dynamic objects (:func:`sgdata.seeds.appearance_seed` of its seed); a
    room written without an appearance, or authored elsewhere, keeps its looks (only its
    light changes).
    """
    if count < 1:
        raise ConfigError(f"--count must be >= 1, got {count}")
    catalog = catalog or load_catalog()
    base = load_base(room_dir)
    layouts = sample_layouts(
        base, count, layouts_seed(base.seed, seed), catalog, config, poses=poses
    )
    user = user_frame(room_file(room_dir))  # None for rooms written by 'sgdata rooms'
    parts = None
    if appearance is not None and appearance.randomize:
        parts = read_room_parts(room_file(room_dir))
    for layout in layouts:
        drawn = None
        if parts is not None and appearance is not None:
            drawn = sample_appearance(base, appearance, appearance_seed(layout.seed))
        write_layout(
            base,
            layout.room,
            layout_file(room_dir, layout.index),
            index=layout.index,
            seed=layout.seed,
            moves=[m.as_dict() for m in layout.moves],
            user=user,
            appearance=drawn,
            parts=parts,
        )
    return layouts


def layout_indices(room_dir: Path) -> list[int]:
    """Indices of the layouts present in a room directory, ascending."""
    found = []
    for path in room_dir.glob(LAYOUT_FILE.format(index="*")):
        suffix = path.stem.removeprefix("layout_")
        if suffix.isdigit():
            found.append(int(suffix))
    return sorted(found)


def layout_stage_file(room_dir: Path, index: int) -> Path:
    """The file to read layout ``index`` from: its layer ``layout_<k>.usda``
    (:func:`sgdata.scene_files.layout_file`); for 0 without one, ``room.usda``.

    Layout 0 is the base arrangement, so a room tagged by ``sgdata tag`` renders before any
    ``sgdata layouts`` run.
    """
    path = layout_file(room_dir, index)
    if index == 0 and not path.is_file():
        return room_file(room_dir)
    return path


def load_layout(room_dir: Path, index: int, catalog: Catalog | None = None) -> Room:
    """The composed room of layout ``index``, checked to be physically valid.

    Raises:
        ConfigError: unknown room directory or layout index.
        SceneError: the layout is not physically valid (e.g. a layer edited by hand put an
            object inside a wall).
    """
    load_base(room_dir)
    path = layout_stage_file(room_dir, index)
    if not path.is_file():
        have = layout_indices(room_dir)
        raise ConfigError(
            f"{path}: no layout {index}; this room has layouts {have or 'none'} "
            f"(make them with 'sgdata layouts {room_dir}')"
        )
    room = read_room(path)
    problems = room_problems(room, catalog or load_catalog(), limit=1)
    if problems:
        raise SceneError(f"{path}: invalid layout: {problems[0]}")
    return room
