"""User rooms of ``[rooms] files``: checked and hashed before a run writes anything, then copied in.

:func:`resolve_user_rooms` runs in the main process before the output directory is touched: every
listed file must exist and be a USD stage with at least one ``sgdata:class`` prim, every class
must be a catalog class or an alias of one in the ``[rooms] classes`` file, and the room must be
measurable (:func:`sgdata.usd.user_rooms.measure_stage`). It fills in what the config left open
(each file's SHA-256 and room type), so the resolved config in the ledger and the manifest
records exactly which bytes the dataset was made from.

:func:`copy_user_room` is the scene step of such a room (in a worker): the user's stage flattened
into ``scenes/<room>/source.usda``, so the dataset points at no file outside itself, and the tag
layer ``room.usda`` over it (:func:`sgdata.usd.tagging.tag_stage`) naming the room's id, type and
seed. The user's file is only ever read.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Collection
from pathlib import Path

from sgdata.errors import ConfigError, SgdataError, UsdError
from sgdata.fileio import sha256_file
from sgdata.pipeline.config import ROOM_TYPE_NAME, GenerateConfig, RoomFile, RoomsConfig
from sgdata.scene_files import SOURCE_FILE, room_file
from sgdata.seeds import user_room_seed
from sgdata.world.catalog import Catalog
from sgdata.world.scene import Room
from sgdata.world.user_classes import UserClasses, read_class_file

__all__ = ["resolve_user_rooms", "copy_user_room"]


def resolve_user_rooms(config: GenerateConfig, *, taken: Collection[str] = ()) -> GenerateConfig:
    """``config`` with every ``[rooms] files`` entry checked, hashed and typed.

    Args:
        config: the config as loaded; ``rooms.base_dir`` empty means the working directory.
        taken: room ids already used by procedural rooms.

    Raises:
        ConfigError: a file or the class file is missing, a pinned sha256 differs, a room id is
            taken, the file's ``sgdata:roomType`` is no type name; naming the entry
            (``rooms.files[k]``) and the file.
        UsdError: a file is not a readable stage, has no ``sgdata:class`` prim, uses a class
            that is neither in the catalog nor an alias, cannot be measured, or measures larger
            than ``[rooms] max_room_size`` / ``max_object_size`` (likely other units).
    """
    rooms = config.rooms
    if not rooms.files:
        return config
    base = str(Path(rooms.base_dir or ".").resolve())
    rooms = dataclasses.replace(rooms, base_dir=base)
    catalog = config.catalog.load()
    classes = _class_file(rooms, catalog)
    resolved = []
    for k, entry in enumerate(rooms.files):
        where = f"rooms.files[{k}] {entry.path!r}"
        if entry.id in taken:
            raise ConfigError(
                f"{where}: room id {entry.id!r} is a procedural room's; give the entry another id"
            )
        path = rooms.resolve(entry.path)
        if not path.is_file():
            raise ConfigError(
                f"{where}: no such file {path} (paths are relative to the config file's folder)"
            )
        digest, _ = sha256_file(path)
        if entry.sha256 and entry.sha256 != digest:
            raise ConfigError(
                f"{where}: the file's sha256 is {digest}, not the {entry.sha256} the config pins"
            )
        try:
            room = _inspect(path, classes, catalog, rooms)
        except SgdataError as exc:
            raise type(exc)(f"rooms.files[{k}]: {exc}") from None
        room_type = entry.type or room.room_type  # measure_stage's default: "custom"
        if not ROOM_TYPE_NAME.fullmatch(room_type):
            raise ConfigError(
                f"{where}: the file's sgdata:roomType {room_type!r} is not a type name "
                '(lower-case letters, digits, "_"); give the entry a type = "..."'
            )
        resolved.append(dataclasses.replace(entry, sha256=digest, type=room_type))
    rooms = dataclasses.replace(rooms, files=tuple(resolved))
    return dataclasses.replace(config, rooms=rooms)


def copy_user_room(entry: RoomFile, config: GenerateConfig, room_dir: Path) -> Room:
    """Write ``source.usda`` (the user's stage, flattened) and ``room.usda`` (the tag layer).

    ``entry`` comes from a config resolved by :func:`resolve_user_rooms`.

    Raises:
        UsdError: the user's file changed since the run started (its sha256), or cannot be
            read; ``room.usda`` cannot be written.
    """
    from sgdata.usd.tagging import RoomNames, tag_stage, write_flattened

    rooms = config.rooms
    path = rooms.resolve(entry.path)
    digest, _ = sha256_file(path)
    if digest != entry.sha256:
        raise UsdError(
            f"{path}: changed since this generation started (sha256 {digest}, was "
            f"{entry.sha256}); rerun with --force to start over from the new file"
        )
    source = room_dir / SOURCE_FILE
    write_flattened(path, source, doc=f"sgdata: {entry.path} flattened (sha256 {entry.sha256})")
    names = RoomNames(entry.id, entry.type, user_room_seed(config.dataset.seed, entry.id))
    report = tag_stage(
        source,
        classes=rooms.resolve(rooms.classes) if rooms.classes else None,
        output=room_file(room_dir),
        names=names,
        checks=False,
    )
    return report.room


def _class_file(rooms: RoomsConfig, catalog: Catalog) -> UserClasses:
    if not rooms.classes:
        return UserClasses()
    try:
        return read_class_file(rooms.resolve(rooms.classes), catalog)
    except ConfigError as exc:
        raise ConfigError(f"rooms.classes: {exc}") from None


def _inspect(path: Path, classes: UserClasses, catalog: Catalog, rooms: RoomsConfig) -> Room:
    """The room of a user's file, measured; every class a catalog class or an alias of one, and
    every size one a home holds."""
    from sgdata.usd.object_prims import object_prims
    from sgdata.usd.room_sizes import check_sizes
    from sgdata.usd.stage import open_stage
    from sgdata.usd.user_rooms import measure_stage

    stage = open_stage(path)
    prims = [p for p in object_prims(stage) if p.HasAttribute("sgdata:class")]
    if not prims:
        raise UsdError(
            f"{path}: no prim carries sgdata:class; give each object prim its catalog class "
            "(docs/rooms.md, 'Bring your own room')"
        )
    for prim in prims:
        name = str(prim.GetAttribute("sgdata:class").Get() or "")
        if name not in catalog and name not in classes.aliases:
            raise UsdError(
                f"{path}: {prim.GetPath()} sgdata:class {name!r} is not a catalog class; "
                f'map it onto one in the [rooms] classes file, e.g. {name} = "Mug"'
            )
    measured = measure_stage(stage, path, classes=classes.dynamics, catalog=catalog)
    check_sizes(
        stage, path, measured, max_room=rooms.max_room_size, max_object=rooms.max_object_size
    )
    return measured.room
