"""``sgdata generate``: a config in, a versioned Parquet triplet dataset out.

Three phases, each recorded in a ledger under ``<root>/.sgdata/`` so an interrupted run
resumes without redoing finished work:

1. scenes (per room, in the pool): room + layouts as USD, reachable pose grid per layout;
2. triplets (per split, in this process): cascaded triplets over the split's rooms, which
   fixes exactly which views must be rendered;
3. views (per room, in the pool, one renderer per worker): render and annotate the
   referenced views, write ``observations/<split>/<room>.parquet`` atomically.

Then the triplet tables and, last, ``dataset.json``. Every random draw derives from the
config seed and the room / layout / view keys, so the bytes do not depend on the worker count.
"""

from __future__ import annotations

import json
import shutil
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from sgdata.dataset.paths import MANIFEST, OUTPUTS, SCENE_TEXTURES, SPLITS, scene_dir
from sgdata.errors import ConfigError
from sgdata.fileio import atomic_write_text, prepare_output_dir, remove_stale_temps
from sgdata.pipeline.config import GenerateConfig, config_to_dict
from sgdata.pipeline.executors import executor_session, run_tasks
from sgdata.pipeline.ledger import (
    CONFIG_RECORD,
    LEDGER,
    read_record,
    scene_record,
    views_record,
)
from sgdata.pipeline.room_tasks import COMMAND, OUTSIDE, SCENES, VIEWS, RoomTask
from sgdata.seeds import split_triplets_seed
from sgdata.stage_clock import NO_CLOCK, OTHER, StageClock
from sgdata.world.room_recipes import ROOM_TYPES
from sgdata.world.triplets import RoomPoses, Triplet, referenced_poses_by_room, sample_triplets

__all__ = ["GenerateProgress", "generate_dataset", "plan_rooms"]


@dataclass(frozen=True)
class GenerateProgress:
    """What a progress callback is told after each finished room of a phase."""

    phase: str  # "scenes" | "views"
    done: int
    total: int
    views: int  # views rendered so far in this run
    elapsed: float  # seconds since the phase started
    # the worker that ran the room just finished: its peak resident memory so far (MiB), and
    # its threads when it finished (native ones included)
    worker_peak_mib: float = 0.0
    worker_threads: int = 0
    worker_pid: int = 0
    # its threads by origin (sgdata.pipeline.worker_state.threads_by_origin), and its context
    # switches so far: (voluntary, involuntary)
    worker_threads_by_origin: dict[str, int] = field(default_factory=dict)
    worker_context_switches: tuple[int, int] = (0, 0)


def plan_rooms(config: GenerateConfig) -> list[RoomTask]:
    """Procedural rooms of every type, numbered per type: train first, then val, then test;
    then the user's rooms in ``[rooms] files`` order, each to the split its entry names."""
    tasks = []
    for room_type in ROOM_TYPES:
        if room_type not in config.rooms.procedural_types:
            continue
        index = 0
        for split, count in config.rooms.per_split().items():
            for _ in range(count):
                tasks.append(RoomTask(room_type, index, split))
                index += 1
    for k, entry in enumerate(config.rooms.files):
        tasks.append(RoomTask(entry.type, k, entry.split, name=entry.id))
    return tasks


def generate_dataset(
    config: GenerateConfig,
    root: Path,
    *,
    workers: int = 1,
    executor: str = "local",
    address: str | None = None,
    resume: bool = False,
    force: bool = False,
    progress: Callable[[GenerateProgress], None] | None = None,
    clock: StageClock | None = None,
) -> dict:
    """Generate the dataset described by ``config`` into ``root``; returns the manifest dict.

    With a ``clock`` (``sgdata generate --profile``) the command times its own steps (phase
    ``command``: inputs, each task phase's wall, triplets, manifest, and what none claims),
    every room task times its stages (:func:`sgdata.pipeline.room_tasks.stage_order`) on a
    clock of its own, added to ``clock`` as it finishes, and each task phase books the
    worker time no task claimed (``outside the tasks``: workers x the phase's wall, less
    the tasks' stages); the bytes written are the same.

    ``executor`` is ``local`` (spawned processes) or ``ray`` (``address`` joins a cluster,
    without it a local instance); the bytes written are the same whatever runs them.

    The rooms of ``[rooms] files`` are checked and hashed first
    (:func:`sgdata.pipeline.user_rooms.resolve_user_rooms`): the manifest's config records each
    file's sha256 and room type; so are the files of ``[catalog] files``
    (:func:`sgdata.pipeline.user_assets.resolve_user_assets`).

    Raises:
        ConfigError: ``root`` is a file, holds a finished dataset (without ``force``), holds
            an unfinished run (without ``resume`` or ``force``), or was started with another
            config (on ``resume``); a ``[rooms] files`` entry or the class file is missing.
        UsdError: a user room has no ``sgdata:class`` prim, a class the catalog lacks (and
            the class file maps onto none), or cannot be read.
        CatalogError: a ``[catalog] files`` catalog is malformed or one of its mesh files is
            bad (:mod:`sgdata.world.mesh_assets`); nothing is written.
        DatasetError: a file cannot be written (the run can be resumed once fixed).
    """
    if workers < 1:
        raise ConfigError(f"--workers must be >= 1, got {workers}")
    timer = clock if clock is not None else NO_CLOCK
    with timer.phase(COMMAND), timer.stage(OTHER):  # OTHER: what no step below claims
        with timer.stage("inputs"):
            config = _resolve_inputs(config)
            _prepare_root(root, config, resume=resume, force=force)
        with executor_session(executor, workers=workers, address=address):
            engine = {"workers": workers, "executor": executor, "address": address}
            return _generate(config, root, engine, progress, clock)


def _resolve_inputs(config: GenerateConfig) -> GenerateConfig:
    """The config with the user's catalogs (their meshes checked and hashed) and rooms
    (checked and hashed before anything is written) resolved."""
    if config.catalog.files:
        from sgdata.pipeline.user_assets import resolve_user_assets

        config = resolve_user_assets(config)
    if config.rooms.files:
        from sgdata.pipeline.user_rooms import resolve_user_rooms

        procedural = {t.room_id for t in plan_rooms(config) if not t.name}
        config = resolve_user_rooms(config, taken=procedural)
    return config


def _generate(
    config: GenerateConfig,
    root: Path,
    engine: dict,
    progress: Callable[[GenerateProgress], None] | None,
    clock: StageClock | None,
) -> dict:
    timer = clock if clock is not None else NO_CLOCK
    tasks = plan_rooms(config)
    scene_jobs = [t for t in tasks if not scene_record(root, t.room_id).exists()]
    with timer.stage(SCENES):
        _run_phase(SCENES, scene_jobs, len(tasks), config, root, engine, progress, clock)
    with timer.stage("triplets"):
        grids = {t.room_id: read_record(scene_record(root, t.room_id)) for t in tasks}
        triplets = {split: _split_triplets(config, split, tasks, grids) for split in SPLITS}
        poses = referenced_poses_by_room(t for split in SPLITS for t in triplets[split])
    view_jobs = [
        (t, poses.get(t.room_id, [])) for t in tasks if not views_record(root, t.room_id).exists()
    ]
    with timer.stage(VIEWS):
        _run_phase(VIEWS, view_jobs, len(tasks), config, root, engine, progress, clock)
    with timer.stage("manifest"):
        shards = [read_record(views_record(root, t.room_id)) for t in tasks]
        return _finish(root, config, tasks, shards, triplets)


def _finish(
    root: Path,
    config: GenerateConfig,
    tasks: list[RoomTask],
    shards: list[dict],
    triplets: dict[str, list[Triplet]],
) -> dict:
    """Write the triplet tables, then the manifest (last: its presence means finished)."""
    from sgdata import __version__
    from sgdata.dataset.manifest import (
        Counts,
        FileEntry,
        Generator,
        ImageInfo,
        Manifest,
        file_entry,
    )
    from sgdata.dataset.paths import obs_id, triplets_path
    from sgdata.dataset.publish import write_manifest
    from sgdata.dataset.rows import triplet_table, write_parquet
    from sgdata.dataset.vocabulary import class_vocabulary

    splits = [s for s in SPLITS if any(t.split == s for t in tasks)]
    files = [FileEntry(r["path"], r["rows"], r["sha256"], r["bytes"]) for r in shards]
    for split in splits:
        ids = {
            obs_id(t.room_id, k.layout, k.i, k.j, k.heading)
            for t in triplets[split]
            for k in (t.anchor, t.positive, t.negative)
        }
        relative = triplets_path(split)
        info = write_parquet(triplet_table(triplets[split], ids), root / relative)
        files.append(FileEntry(relative, info.rows, info.sha256, info.bytes))
    for task in tasks:
        for usd in sorted(scene_dir(root, task.room_id).glob("*.usda")):
            files.append(file_entry(root, usd.relative_to(root).as_posix(), rows=None))
    for image in sorted((root / SCENE_TEXTURES).glob("*.png")):  # shared by textured rooms
        files.append(file_entry(root, image.relative_to(root).as_posix(), rows=None))
    slots, classes = class_vocabulary(config.catalog.load())
    manifest = Manifest(
        name=config.dataset.name,
        version=config.dataset.version,
        generator=Generator("sgdata", __version__),
        seed=config.dataset.seed,
        config=config_to_dict(config),
        classes=classes,
        num_slots=slots.num_slots,
        relation_rules=config.annotation.relations.to_dict(),
        image=ImageInfo(config.images.format, config.camera.width, config.camera.height),
        splits={s: tuple(t.room_id for t in tasks if t.split == s) for s in splits},
        counts=Counts(
            rooms=len(tasks),
            observations={
                s: sum(r["rows"] for r, t in zip(shards, tasks, strict=True) if t.split == s)
                for s in splits
            },
            triplets={s: len(triplets[s]) for s in splits},
            tiers={s: [sum(t.tier == k for t in triplets[s]) for k in range(5)] for s in splits},
        ),
        files=tuple(sorted(files, key=lambda f: f.path)),
    )
    write_manifest(manifest, root)
    return manifest.to_dict()


def _prepare_root(root: Path, config: GenerateConfig, *, resume: bool, force: bool) -> None:
    if root.exists() and not root.is_dir():
        raise ConfigError(f"{root}: is a file; expected a directory for the dataset")
    ledger = root / LEDGER
    if (root / MANIFEST).exists() and not force:
        raise ConfigError(f"{root}: holds a finished dataset; pass --force to overwrite it")
    if ledger.exists() and not (resume or force):
        raise ConfigError(
            f"{root}: holds an unfinished generation; pass --resume to continue it "
            "or --force to start over"
        )
    if force:
        _remove_outputs(root)
    prepare_output_dir(root)
    remove_stale_temps(root)  # a killed run may have left half-written temporaries
    record = ledger / CONFIG_RECORD
    wanted = json.dumps(config_to_dict(config), sort_keys=True, indent=2)
    if record.exists():
        started = record.read_text(encoding="utf-8")
        if started != wanted:
            raise ConfigError(
                f"{root}: was started with another config{_changed_files(started, config)}; "
                "rerun with that config or pass --force to start over"
            )
    else:
        ledger.mkdir(parents=True, exist_ok=True)
        atomic_write_text(record, wanted)


def _changed_files(started: str, config: GenerateConfig) -> str:
    """`` (rooms.files[k] 'a.usda' changed since)`` when a user room's file is what differs."""
    try:
        before = {f["id"]: f["sha256"] for f in json.loads(started)["rooms"]["files"]}
    except (ValueError, KeyError, TypeError):
        return ""
    for k, entry in enumerate(config.rooms.files):
        if entry.id in before and before[entry.id] != entry.sha256:
            return f" (rooms.files[{k}] {entry.path!r} changed since: sha256 {entry.sha256})"
    return ""


def _remove_outputs(root: Path) -> None:
    """Delete what a generation writes (and nothing else the user may keep there)."""
    for name in (*OUTPUTS, LEDGER):
        target = root / name
        if target.is_dir():
            shutil.rmtree(target)
        elif target.exists():
            target.unlink()


def _run_phase(
    phase: str,
    jobs: list,
    total: int,
    config: GenerateConfig,
    root: Path,
    engine: dict,
    progress: Callable[[GenerateProgress], None] | None,
    clock: StageClock | None,
) -> None:
    from sgdata.pipeline.room_tasks import render_room_views, write_room_scenes

    start = time.perf_counter()
    done = total - len(jobs)
    views = 0
    if phase == SCENES:
        payloads = [(task, config, root, _task_clock(clock)) for task in jobs]
        fn = write_room_scenes
    else:
        payloads = [(task, list(poses), config, root, _task_clock(clock)) for task, poses in jobs]
        fn = render_room_views
    booked = 0.0  # seconds the phase's tasks booked to their stages
    for result in run_tasks(fn, payloads, **engine):
        done += 1
        views += int(result.get("views", 0))
        if clock is not None:
            stages = result.get("stages", {})
            clock.add(stages)
            booked += sum(seconds for seconds, _ in stages.values())
        if progress is not None:
            progress(
                GenerateProgress(
                    phase, done, total, views, time.perf_counter() - start,
                    worker_peak_mib=float(result.get("peak_rss_mib", 0.0)),
                    worker_threads=int(result.get("threads", 0)),
                    worker_pid=int(result.get("pid", 0)),
                    worker_threads_by_origin=dict(result.get("threads_by_origin", {})),
                    worker_context_switches=tuple(result.get("context_switches", (0, 0))),
                )
            )  # fmt: skip
    if clock is not None and jobs:  # the workers' time no task claimed
        busy = min(engine["workers"], len(jobs)) * (time.perf_counter() - start)
        clock.book(phase, OUTSIDE, max(0.0, busy - booked))


def _task_clock(clock: StageClock | None) -> StageClock | None:
    """A fresh clock for one task of a profiled run (it travels to the worker and back)."""
    return None if clock is None else StageClock()


def _split_triplets(
    config: GenerateConfig, split: str, tasks: list[RoomTask], grids: dict[str, dict]
) -> list[Triplet]:
    total = config.triplets.per_split()[split]
    rooms = [
        RoomPoses(
            t.room_id,
            split,
            {
                int(k): frozenset(tuple(c) for c in cells)
                for k, cells in grids[t.room_id]["reachable"].items()
            },
        )
        for t in tasks
        if t.split == split
    ]
    if total == 0:
        return []
    if not rooms:
        raise ConfigError(
            f"triplets.{split} = {total} but no room is in split {split} (rooms.{split} = "
            f"{config.rooms.per_split()[split]} per type for {len(config.rooms.procedural_types)} "
            f'type(s), no rooms.files entry with split = "{split}"): set triplets.{split} = 0 '
            "or add rooms"
        )
    seed = split_triplets_seed(config.dataset.seed, SPLITS.index(split))
    return sample_triplets(rooms, total, seed, shares=config.triplets.shares)
