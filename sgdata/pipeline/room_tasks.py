"""The two per-room tasks of ``sgdata generate``, importable by spawned workers and Ray actors.

Each task takes plain, picklable arguments, writes its outputs atomically, and records its
completion in the ledger last, so a task killed half-way leaves nothing that counts as done.
"""

from __future__ import annotations

import json
from collections import defaultdict
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from sgdata.dataset.paths import observations_path, scene_dir
from sgdata.errors import DatasetError
from sgdata.pipeline.ledger import read_record, scene_record, views_record, write_record
from sgdata.scene_files import layout_file, room_file
from sgdata.seeds import rng_for, view_seed

if TYPE_CHECKING:
    from sgdata.pipeline.config import GenerateConfig
    from sgdata.world.triplets import PoseKey

__all__ = ["RoomTask", "write_room_scenes", "render_room_views"]

# One renderer per worker process, kept alive across rooms (built on first use).
_worker: dict[str, Any] = {}


@dataclass(frozen=True)
class RoomTask:
    """One room of the dataset: the unit of parallel work."""

    room_type: str
    index: int  # procedural: the room's number in its type; user room: its rooms.files entry
    split: str
    name: str = ""  # a user room's id (its rooms.files entry's); empty for procedural rooms

    @property
    def room_id(self) -> str:
        return self.name or f"{self.room_type}_{self.index:03d}"


def write_room_scenes(task: RoomTask, config: GenerateConfig, root: Path) -> dict:
    """Phase 1 of a room: USD room and layouts, and the reachable cells of every layout."""
    from sgdata.pipeline.user_rooms import copy_user_room
    from sgdata.usd.room_io import catalog_geometry, read_room, write_room
    from sgdata.usd.scene_dirs import write_layouts
    from sgdata.world.rooms import generate_room

    catalog = config.catalog.load()
    room_dir = scene_dir(root, task.room_id)
    if task.name:  # a user's room: its stage copied in, tagged
        entry = config.rooms.files[task.index]
        room = _guarded(lambda: copy_user_room(entry, config, room_dir))
    else:
        room = generate_room(task.room_type, task.index, config.dataset.seed, catalog)
        _guarded(
            lambda: write_room(
                room,
                room_file(room_dir),
                geometry=catalog_geometry(catalog),
                appearance=config.appearance,
            )
        )
    layouts = _guarded(
        lambda: write_layouts(
            room_dir,
            count=config.layouts.count,
            seed=0,
            catalog=catalog,
            config=config.dynamics,
            poses=config.poses,
            appearance=config.appearance,
        )
    )
    reachable = {}
    for layout in layouts:
        # the grid of the room as stored, exactly what the renderer will load
        stored = read_room(layout_file(room_dir, layout.index))
        grid = config.poses.grid(stored)
        reachable[str(layout.index)] = [list(c) for c in grid.cells]
    record = {
        "room_id": task.room_id,
        "room_type": task.room_type,
        "split": task.split,
        "seed": room.seed,
        "reachable": reachable,
    }
    write_record(scene_record(root, task.room_id), record)
    return {"views": 0}


def render_room_views(
    task: RoomTask, poses: list[PoseKey], config: GenerateConfig, root: Path
) -> dict:
    """Phase 3 of a room: render the referenced views and write the room's shard."""
    from sgdata.annotate.records import ViewPose
    from sgdata.dataset.rows import observation_table, write_parquet
    from sgdata.usd.geometry import read_geometry
    from sgdata.usd.room_io import read_room

    annotator, class_ids = _annotator(config)
    room_dir = scene_dir(root, task.room_id)
    room_seed = read_record(scene_record(root, task.room_id))["seed"]
    by_layout: dict[int, list[PoseKey]] = defaultdict(list)
    for key in poses:
        by_layout[key.layout].append(key)
    records, scene_paths = [], []
    for layout in sorted(by_layout):
        path = layout_file(room_dir, layout)
        room = read_room(path)
        annotator.set_layout(room, read_geometry(path), layout)
        grid = config.poses.grid(room)
        for key in sorted(by_layout[layout]):
            seed = view_seed(room_seed, key.layout, key.i, key.j, key.heading)
            noise = rng_for(seed) if config.poses.noise else None
            x, y, theta = grid.pose_world(key.i, key.j, key.heading, rng=noise)
            records.append(
                annotator.view(ViewPose(x, y, theta, key.i, key.j, key.heading), seed=seed)
            )
            scene_paths.append(path.relative_to(root).as_posix())
    table = observation_table(
        records,
        room_type=task.room_type,
        split=task.split,
        scene_paths=scene_paths,
        image_format=config.images.format,
        jpeg_quality=config.images.jpeg_quality,
        class_ids=class_ids,
    )
    relative = observations_path(task.split, task.room_id)
    rows, sha256, size = _guarded(lambda: write_parquet(table, root / relative))
    record = {"path": relative, "rows": rows, "sha256": sha256, "bytes": size}
    write_record(views_record(root, task.room_id), record)
    return {"views": len(records)}


def _annotator(config: GenerateConfig) -> tuple[Any, dict[str, int]]:
    """This worker's view annotator, built once (its renderer stays alive)."""
    key = json.dumps(
        [
            config.camera.__dict__,
            config.annotation.min_visible_pixels,
            config.appearance.textures,
            config.outputs.__dict__,
        ],
        sort_keys=True,
    )
    if _worker.get("key") != key:
        from sgdata.annotate.annotator import ViewAnnotator
        from sgdata.dataset.vocabulary import class_vocabulary
        from sgdata.render.renderer import Renderer

        if "renderer" in _worker:
            _worker["renderer"].close()
        slots, classes = class_vocabulary(config.catalog.load())
        renderer = Renderer(config.camera, textures=config.appearance.textures)
        _worker.update(
            key=key,
            renderer=renderer,
            annotator=ViewAnnotator(
                renderer,
                slots,
                min_visible_pixels=config.annotation.min_visible_pixels,
                rules=config.annotation.relations,
                keep_depth=config.outputs.depth,
                keep_instances=config.outputs.instances,
            ),
            class_ids={c.name: c.id for c in classes},
        )
    return _worker["annotator"], _worker["class_ids"]


def _guarded(action):  # noqa: ANN001, ANN202
    """Run a write; an OS error becomes a one-line DatasetError naming the file."""
    try:
        return action()
    except OSError as exc:
        where = exc.filename or "output"
        raise DatasetError(
            f"{where}: cannot write ({exc.strerror}); fix it and rerun with --resume"
        ) from None
