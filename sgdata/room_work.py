"""The two per-room tasks of ``sgdata generate``, importable by spawned workers.

Each task takes plain, picklable arguments, writes its outputs atomically, and records its
completion in the ledger last, so a task killed half-way leaves nothing that counts as done.
"""

from __future__ import annotations

import json
from collections import defaultdict
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .catalog import load_catalog
from .errors import DatasetError
from .fileio import atomic_write_text
from .poses import pose_grid
from .seeds import derive_seed, rng_for

if TYPE_CHECKING:
    from .config import GenerateConfig
    from .generate import RoomTask
    from .triplets import PoseKey

__all__ = ["write_room_scenes", "render_room_views", "view_seed"]

LEDGER = ".sgdata"  # progress records of a generation: what is done, and with which config

# One renderer per worker process, kept alive across rooms (built on first use).
_worker: dict[str, Any] = {}


def view_seed(room_seed: int, key: PoseKey) -> int:
    """The seed of one view, derived from its room's seed and its pose key."""
    return derive_seed(room_seed, key.layout, key.i, key.j, key.heading)


def write_room_scenes(task: RoomTask, config: GenerateConfig, root: Path) -> dict:
    """Phase 1 of a room: USD room and layouts, and the reachable cells of every layout."""
    from .rooms import generate_room
    from .scenes import layout_file, room_file, write_layouts
    from .usd_io import catalog_geometry, read_room, write_room

    catalog = load_catalog()
    room = generate_room(task.room_type, task.index, config.dataset.seed, catalog)
    room_dir = root / "scenes" / task.room_id
    _guarded(lambda: write_room(room, room_file(room_dir), geometry=catalog_geometry(catalog)))
    layouts = _guarded(
        lambda: write_layouts(
            room_dir, count=config.layouts.count, seed=0, catalog=catalog, config=config.dynamics
        )
    )
    reachable = {}
    for layout in layouts:
        # the grid of the room as stored, exactly what the renderer will load
        stored = read_room(layout_file(room_dir, layout.index))
        grid = pose_grid(stored, cell=config.poses.cell, radius=config.poses.robot_radius)
        reachable[str(layout.index)] = [list(c) for c in grid.cells]
    record = {
        "room_id": task.room_id,
        "room_type": task.room_type,
        "split": task.split,
        "seed": room.seed,
        "reachable": reachable,
    }
    _record(root, f"scene-{task.room_id}.json", record)
    return {"views": 0}


def render_room_views(
    task: RoomTask, poses: list[PoseKey], config: GenerateConfig, root: Path
) -> dict:
    """Phase 3 of a room: render the referenced views and write the room's shard."""
    from .dataset.layout import OBSERVATIONS
    from .dataset.rows import observation_table, write_parquet
    from .scenes import layout_file
    from .usd_geometry import read_geometry
    from .usd_io import read_room
    from .views import ViewPose

    annotator, class_ids = _annotator(config)
    room_dir = root / "scenes" / task.room_id
    room_seed = json.loads((root / LEDGER / f"scene-{task.room_id}.json").read_text())["seed"]
    by_layout: dict[int, list[PoseKey]] = defaultdict(list)
    for key in poses:
        by_layout[key.layout].append(key)
    records, scene_paths = [], []
    for layout in sorted(by_layout):
        path = layout_file(room_dir, layout)
        room = read_room(path)
        annotator.set_layout(room, read_geometry(path), layout)
        grid = pose_grid(room, cell=config.poses.cell, radius=config.poses.robot_radius)
        for key in sorted(by_layout[layout]):
            seed = view_seed(room_seed, key)
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
    relative = OBSERVATIONS.format(split=task.split, room_id=task.room_id)
    rows, sha256, size = _guarded(lambda: write_parquet(table, root / relative))
    record = {"path": relative, "rows": rows, "sha256": sha256, "bytes": size}
    _record(root, f"views-{task.room_id}.json", record)
    return {"views": len(records)}


def _annotator(config: GenerateConfig) -> tuple[Any, dict[str, int]]:
    """This worker's view annotator, built once (its renderer stays alive)."""
    key = json.dumps([config.camera.__dict__, config.annotation.min_visible_pixels], sort_keys=True)
    if _worker.get("key") != key:
        from .render import Renderer
        from .views import ViewAnnotator
        from .vocabulary import class_vocabulary

        if "renderer" in _worker:
            _worker["renderer"].close()
        slots, classes = class_vocabulary()
        renderer = Renderer(config.camera)
        _worker.update(
            key=key,
            renderer=renderer,
            annotator=ViewAnnotator(
                renderer,
                slots,
                min_visible_pixels=config.annotation.min_visible_pixels,
                rules=config.annotation.relations,
            ),
            class_ids={c.name: c.id for c in classes},
        )
    return _worker["annotator"], _worker["class_ids"]


def _record(root: Path, name: str, record: dict) -> None:
    path = root / LEDGER / name
    _guarded(lambda: atomic_write_text(path, json.dumps(record, sort_keys=True)))


def _guarded(action):  # noqa: ANN001, ANN202
    """Run a write; an OS error becomes a one-line DatasetError naming the file."""
    try:
        return action()
    except OSError as exc:
        where = exc.filename or "output"
        raise DatasetError(
            f"{where}: cannot write ({exc.strerror}); fix it and rerun with --resume"
        ) from None
