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
from sgdata.pipeline.worker_state import worker_state
from sgdata.scene_files import layout_file, room_file
from sgdata.seeds import rng_for, view_seed
from sgdata.stage_clock import NO_CLOCK, OTHER, Clock, StageClock

if TYPE_CHECKING:
    from sgdata.pipeline.config import GenerateConfig
    from sgdata.world.triplets import PoseKey

__all__ = [
    "COMMAND",
    "OUTSIDE",
    "RoomTask",
    "render_room_views",
    "stage_order",
    "write_room_scenes",
]

SCENES, VIEWS = "scenes", "views"  # the phases of generate that run room tasks
# The main process of generate: its own steps and the wall time of each task phase
COMMAND = "command"
COMMAND_STAGES = ("inputs", SCENES, "triplets", VIEWS, "manifest", OTHER)
# A task phase's worker time that no task's stage claims: workers starting (spawn, imports,
# EGL), idle while the last rooms finish, results coming back
OUTSIDE = "outside the tasks"
# The stages each task books to its clock, in pipeline order; the annotator's own steps come
# in the views phase before "view record" (the rest of a view).
SCENE_STAGES = ("catalog", "room", "room USD", "layouts", "USD read", "pose grid", "ledger", OTHER)
VIEW_STAGES = ("renderer start", "USD load", "scene build", "pose grid", "view record")
VIEW_TAIL = ("rows + image encode", "Parquet write", "ledger", OTHER)


def stage_order() -> dict[str, tuple[str, ...]]:
    """The phases of a profiled run and their stages in pipeline order (for its table): the
    command's wall time, then each task phase's worker time."""
    from sgdata.annotate.annotator import VIEW_STEPS  # late: it loads the renderer

    return {
        COMMAND: COMMAND_STAGES,
        SCENES: (*SCENE_STAGES, OUTSIDE),
        VIEWS: (*VIEW_STAGES[:-1], *VIEW_STEPS, VIEW_STAGES[-1], *VIEW_TAIL, OUTSIDE),
    }


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


def write_room_scenes(
    task: RoomTask, config: GenerateConfig, root: Path, clock: Clock | None = None
) -> dict:
    """Phase 1 of a room: USD room and layouts, and the reachable cells of every layout.

    The result holds the views rendered (none here), the worker's peak memory so far
    (``peak_rss_mib``), its threads now (``threads``, ``threads_by_origin``) and context
    switches so far (:func:`sgdata.pipeline.worker_state.worker_state`).

    With a ``clock`` (:class:`sgdata.stage_clock.StageClock`) its steps are timed as
    :func:`stage_order` and the result carries the clock's totals under ``"stages"``.
    """
    clock = clock or NO_CLOCK
    with clock.phase(SCENES), clock.stage(OTHER):
        _write_room_scenes(task, config, root, clock)
    return {"views": 0, **worker_state(), **_stages(clock)}


def _write_room_scenes(task: RoomTask, config: GenerateConfig, root: Path, clock: Clock) -> None:
    from sgdata.pipeline.user_rooms import copy_user_room
    from sgdata.usd.room_io import catalog_geometry, read_room, write_room
    from sgdata.usd.scene_dirs import write_layouts
    from sgdata.usd.stage import open_layer
    from sgdata.world.rooms import generate_room

    with clock.stage("catalog"):
        catalog = config.catalog.load()
    room_dir = scene_dir(root, task.room_id)
    if task.name:  # a user's room: its stage copied in, tagged
        entry = config.rooms.files[task.index]
        with clock.stage("room USD"):
            room = _guarded(lambda: copy_user_room(entry, config, room_dir))
    else:
        with clock.stage("room"):
            room = generate_room(task.room_type, task.index, config.dataset.seed, catalog)
        with clock.stage("room USD"):
            _guarded(
                lambda: write_room(
                    room,
                    room_file(room_dir),
                    geometry=catalog_geometry(catalog),
                    appearance=config.appearance,
                )
            )
    # held until the layouts are read back: USD drops a layer no stage holds, and every
    # read of a layout would parse the room's again
    _room_layer = open_layer(room_file(room_dir))
    with clock.stage("layouts"):
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
        with clock.stage("USD read"):
            stored = read_room(layout_file(room_dir, layout.index))
        with clock.stage("pose grid"):
            grid = config.poses.grid(stored)
        reachable[str(layout.index)] = [list(c) for c in grid.cells]
    record = {
        "room_id": task.room_id,
        "room_type": task.room_type,
        "split": task.split,
        "seed": room.seed,
        "reachable": reachable,
    }
    with clock.stage("ledger"):
        write_record(scene_record(root, task.room_id), record)


def render_room_views(
    task: RoomTask,
    poses: list[PoseKey],
    config: GenerateConfig,
    root: Path,
    clock: Clock | None = None,
) -> dict:
    """Phase 3 of a room: render the referenced views and write the room's shard.

    The result holds the views rendered and what the worker says of itself
    (:func:`sgdata.pipeline.worker_state.worker_state`: peak memory, threads, context
    switches). With a ``clock`` its steps are timed as
    :func:`stage_order` (the annotator's too) and the result carries the clock's totals under
    ``"stages"``.
    """
    clock = clock or NO_CLOCK
    with clock.phase(VIEWS), clock.stage(OTHER):
        views = _render_room_views(task, poses, config, root, clock)
    return {"views": views, **worker_state(), **_stages(clock)}


def _render_room_views(
    task: RoomTask, poses: list[PoseKey], config: GenerateConfig, root: Path, clock: Clock
) -> int:
    from sgdata.annotate.records import ViewPose
    from sgdata.dataset.rows import write_parquet
    from sgdata.pipeline.layout_reader import LayoutReader
    from sgdata.pipeline.view_encoder import ViewEncoder

    with clock.stage("renderer start"):
        annotator, class_ids = _annotator(config)
    annotator.clock = clock
    room_dir = scene_dir(root, task.room_id)
    room_seed = read_record(scene_record(root, task.room_id))["seed"]
    by_layout: dict[int, list[PoseKey]] = defaultdict(list)
    for key in poses:
        by_layout[key.layout].append(key)
    layouts = sorted(by_layout)
    paths = [layout_file(room_dir, layout) for layout in layouts]
    scene_paths = []
    try:
        with (
            ViewEncoder(
                config.images.format,
                jpeg_quality=config.images.jpeg_quality,
                pool=_worker_pool("encoding"),
            ) as encoder,
            LayoutReader(paths, _worker_pool("reading")) as reader,
        ):
            for layout, path in zip(layouts, paths, strict=True):
                with clock.stage("USD load"):  # the wait: read while the layout before rendered
                    room, geometry = reader.next()
                with clock.stage("scene build"):
                    annotator.set_layout(room, geometry, layout)
                with clock.stage("pose grid"):
                    grid = config.poses.grid(room)
                for key in sorted(by_layout[layout]):
                    seed = view_seed(room_seed, key.layout, key.i, key.j, key.heading)
                    noise = rng_for(seed) if config.poses.noise else None
                    x, y, theta = grid.pose_world(key.i, key.j, key.heading, rng=noise)
                    with clock.stage("view record"):
                        pose = ViewPose(x, y, theta, key.i, key.j, key.heading)
                        encoder.add(annotator.view(pose, seed=seed))
                    scene_paths.append(path.relative_to(root).as_posix())
            # what is left: the encodes still running, then the rows
            with clock.stage("rows + image encode"):
                table = encoder.table(
                    room_type=task.room_type,
                    split=task.split,
                    scene_paths=scene_paths,
                    class_ids=class_ids,
                )
    finally:
        annotator.clock = NO_CLOCK  # the worker's annotator outlives this task
    relative = observations_path(task.split, task.room_id)
    with clock.stage("Parquet write"):
        rows, sha256, size = _guarded(lambda: write_parquet(table, root / relative))
    record = {"path": relative, "rows": rows, "sha256": sha256, "bytes": size}
    with clock.stage("ledger"):
        write_record(views_record(root, task.room_id), record)
    return len(encoder)


def _worker_pool(name: str) -> Any:
    """This worker's ``encoding`` (views) or ``reading`` (layouts) thread, started once: it
    outlives each room task, so the worker's threads do not grow with its rooms."""
    if name not in _worker:
        from sgdata.pipeline.layout_reader import reading_pool
        from sgdata.pipeline.view_encoder import encoding_pool

        _worker[name] = {"encoding": encoding_pool, "reading": reading_pool}[name]()
    return _worker[name]


def _stages(clock: Clock) -> dict:
    """A result's ``"stages"`` entry: the clock's totals, if it keeps any."""
    return {"stages": clock.totals()} if isinstance(clock, StageClock) else {}


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
