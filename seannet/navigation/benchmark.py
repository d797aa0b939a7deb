"""``seannet navigate``: the navigation benchmark (paper Table II) of localizers.

A localizer is a trained run, a method directory (every benchmark card's) or a method's
name (:func:`seannet.navigation.localizer.open_localizer`); "run" below means any of them.
Every localizer is tested on the same episodes: each is drawn from
:func:`seannet.seeds.episode_seed` (test seed, room, case, index) and from the map's structure,
which is the same whatever run embedded it. Maps are built once per run and room into
``<maps>/<run label>/<room>/`` and reused (:func:`seannet.navigation.maps.ensure_map`).

A run's label is the shortest tail of its path that tells it from the other runs
(``seed0``, or ``lr0.01_seed0`` next to ``lr0.003_seed0``); a method's name is its own label
(made a file name).

The work runs in spawned worker processes that die with their parent
(:func:`sgdata.pipeline.executors.run_tasks`), one task per map, then one per (run, room,
case), whatever ``workers`` is: every view is rasterised by a single-threaded llvmpipe and
every network runs on one thread, so the results do not depend on the worker count. Each task
writes its episodes atomically to ``<out>/parts/<run label>/<room>_<case>.json`` with the key
of everything they depend on; a run that was killed starts again where it stopped, and a part
whose key differs is run again. Wall times are the one thing that varies: they are written
to ``navigate_<split>_times.json``, beside ``navigate_<split>.json``, which holds the same
bytes for the same settings whatever the worker count or the interruptions.

With ``graphs`` (a detector, :mod:`seannet.detection.live_graphs`), every view the maps and
the episodes render gets the detector's scene graph instead of the generator's; a run's label
then ends in the graphs' (``seed0@detected-1a2b3c4d-t0.5``), so its maps and parts are its own.
"""

from __future__ import annotations

import dataclasses
import json
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from PIL import Image, ImageDraw, ImageFont

from seannet.data.datasets import dataset_identity, open_dataset
from seannet.data.live_views import LiveRooms
from seannet.data.opening import DataSource
from seannet.detection.live_graphs import LiveGraphs
from seannet.errors import NavigationError
from seannet.methods.cards import method_label
from seannet.navigation.config import MAP_SPACING, NavigationTestConfig
from seannet.navigation.episodes import CASES, EpisodeResult, run_episode, sample_episode
from seannet.navigation.localizer import AnyLocalizer, open_localizer
from seannet.navigation.maps import (
    MAP_META,
    check_map,
    current_map,
    derive_map,
    ensure_map,
    load_map,
    save_map,
)
from seannet.navigation.navigator import load_navigator, resize
from seannet.navigation.stopping import StopRule
from seannet.navigation.tables import markdown, write_results
from seannet.provenance import append_provenance
from seannet.seeds import episode_seed
from seannet.training.runs import BEST, check_same_dataset, load_checkpoint
from sgdata.fileio import atomic_write_text, save_png, sha256_file
from sgdata.pipeline.executors import executor_session, run_tasks
from sgdata.seeds import rng_for

__all__ = [
    "ORACLE",
    "NavigationTestConfig",
    "draw_strip",
    "results_path",
    "run_labels",
    "run_navigation",
    "seed_maps",
]

ORACLE = "oracle"  # the navigator that takes the right action from the true pose
STRIP_PANEL = 112  # pixels
STRIP_MAX_PANELS = 16
PARTS = "parts"


def run_navigation(
    runs: list[Path | str],
    navigator: Path | None,
    data: DataSource,
    config: NavigationTestConfig | None = None,
    *,
    epsilon: float | dict[Path, tuple[float, str]] | None = None,
    workers: int = 1,
    out: Path | None = None,
    maps: Path | None = None,
    strips: Path | None = None,
    stop_rules: dict[Path | str, StopRule] | None = None,
    graphs: LiveGraphs | None = None,
    progress: Callable[[str], None] | None = None,
) -> dict[str, Any]:
    """Run the navigation test of every localizer run on the rooms of ``config.split``.

    Args:
        runs: the localizers: run directories, method directories or method names.
        navigator: a ``train-navigator`` run; None for the oracle (:data:`ORACLE`).
        config: the test's settings (default :class:`NavigationTestConfig`'s); with
            ``replan`` every episode runs under bump and replan and its paper-rule outcome is
            read off the same run (see :mod:`seannet.navigation.episodes`).
        workers: processes running maps and episodes in parallel.
        epsilon: one threshold for every run, or per run ``(epsilon, where it comes from)``
            (a run left out reads its eval files); None: each run's eval files.
        stop_rules: beyond the paper, per run the rule its live episodes stop by instead of
            the paper's (its ending is read as the paper row's); with ``config.map_memory``
            the map learns the layout (:func:`seannet.navigation.episodes.run_episode`).
        graphs: the detector whose scene graphs every rendered view gets; None: the
            generator's.

    Writes ``navigate_<split>.json`` and ``.md`` into ``out`` (default: the navigator run),
    maps under ``maps`` (default: ``out/maps``), and under ``strips`` when given, per run,
    room and case, the first episode of each outcome (and cause or kind) as a strip; appends
    what made them to ``out``'s provenance (:mod:`seannet.provenance`).

    Raises:
        CheckpointError: a run or the navigator was trained on another dataset.
        MethodError: a method that cannot be opened or breaks a check.
        NavigationError: bad counts, no epsilon for a run, a split without rooms, a room
            without an episode, no ``out`` for the oracle, stop rules not one per run or
            with ``trace`` or ``replan``, a map memory without them.
    """
    config = config if config is not None else NavigationTestConfig()
    if workers < 1:
        raise NavigationError(f"--workers {workers}: expected >= 1")
    _check_stop_rules(runs, stop_rules, config)
    out = out if out is not None else navigator
    if out is None:
        raise NavigationError("the oracle navigator has no run directory: pass --out")
    maps = maps or out / "maps"
    ds = open_dataset(data)  # the manifest read once for the whole command
    identity = dataset_identity(ds)
    if navigator is not None:
        state = load_checkpoint(navigator / BEST)
        check_same_dataset(navigator / BEST, state["dataset"], identity)
        load_navigator(navigator)  # refuses a localizer run given as the navigator, here
    rooms = list(ds.rooms(config.split)) if config.split in ds.splits else []
    if not rooms:
        raise NavigationError(f"{ds.root}: split {config.split!r} has no room to navigate in")
    say = progress or (lambda _: None)
    localizers = [_localizer(run, ds, epsilon) for run in runs]
    settings = {
        **config.settings(),
        "navigator": str(navigator) if navigator is not None else ORACLE,
        "navigator_sha256": sha256_file(navigator / BEST)[0] if navigator is not None else ORACLE,
        "dataset": identity,
        **({"graphs": dataclasses.asdict(graphs)} if graphs is not None else {}),
    }
    suffix = f"@{graphs.label}" if graphs is not None else ""
    labels = {run: label + suffix for run, label in zip(runs, run_labels(runs), strict=True)}
    named = dict(zip(runs, localizers, strict=True))
    with executor_session(workers=workers):  # one pool for the maps and the episodes
        _build_maps(
            named, ds.root, rooms, {r: maps / labels[r] for r in runs}, config, graphs, workers, say
        )
        rules = stop_rules or {}
        jobs = {
            (run, room_id, case): _job(
                settings, run, loc, labels[run], room_id, case, maps, strips, rules.get(run)
            )
            for run, loc in named.items()
            for room_id in rooms
            for case in CASES
        }
        todo = [(job, str(ds.root), str(out)) for job in jobs.values() if _part(job, out) is None]
        for done in run_tasks(_case_task, todo, workers=workers):
            say(f"{done['label']}: {done['room_id']} {done['case']} done")
    results: dict[str, Any] = {**settings, "config": dataclasses.asdict(config), "runs": []}
    for run, loc in named.items():
        records = [
            episode for room_id in rooms for case in CASES
            for episode in _finished_part(jobs[run, room_id, case], out)
        ]  # fmt: skip
        results["runs"].append(_run_entry(run, loc, labels[run], records, rules.get(run)))
    out.mkdir(parents=True, exist_ok=True)
    append_provenance(out, ds, step=results_path(out, config.split).stem)
    write_results(results, results_path(out, config.split))
    written = results_path(out, config.split).with_suffix(".md")
    atomic_write_text(written, markdown(results))
    results["written"] = str(written)
    return results


def results_path(out: Path, split: str) -> Path:
    """Where :func:`run_navigation` writes its results JSON for ``split`` (markdown beside)."""
    return out / f"navigate_{split}.json"


def _build_maps(
    localizers: dict[Path | str, AnyLocalizer],
    data: Path,
    rooms: list[str],
    directories: dict[Path | str, Path],
    config: NavigationTestConfig,
    graphs: LiveGraphs | None,
    workers: int,
    say: Callable[[str], None],
) -> None:
    """Build the maps of every run and room that are missing or stale (in workers)."""
    jobs = [
        (str(run), data, room_id, directories[run] / room_id, config.spacing, graphs)
        for run, loc in localizers.items()
        for room_id in rooms
        if current_map(loc, room_id, directories[run] / room_id, spacing=config.spacing) is None
    ]
    for done in run_tasks(_map_task, jobs, workers=workers):
        say(f"map of {done['room_id']} by {done['run']}")


def _job(
    settings: dict[str, Any],
    run: Path | str,
    loc: AnyLocalizer,
    label: str,
    room_id: str,
    case: str,
    maps: Path,
    strips: Path | None,
    rule: StopRule | None,
) -> dict[str, Any]:
    """One task: the episodes of one (run, room, case); its key fields say what they depend on."""
    return {
        **settings,
        **({"stop_rule": dataclasses.asdict(rule)} if rule is not None else {}),
        "run": str(run),
        "checkpoint_sha256": loc.digest,
        "epsilon": loc.epsilon,
        "room_id": room_id,
        "case": case,
        "label": label,
        "map": str(maps / label / room_id),
        "strips": str(strips / label) if strips is not None else None,
    }


def _run_entry(
    run: Path | str,
    loc: AnyLocalizer,
    label: str,
    records: list[dict[str, Any]],
    rule: StopRule | None,
) -> dict[str, Any]:
    """A run's entry of the results: what it is, its threshold (or stop rule), its episodes."""
    return {
        "run": str(run),
        "label": label,
        "model": loc.name,
        "epsilon": loc.epsilon,
        "epsilon_source": loc.epsilon_source,
        **({"stop_rule": dataclasses.asdict(rule)} if rule is not None else {}),
        "checkpoint_sha256": loc.digest,
        "episodes": records,
    }


def _check_stop_rules(
    runs: list[Path | str],
    stop_rules: dict[Path | str, StopRule] | None,
    config: NavigationTestConfig,
) -> None:
    if stop_rules is None:
        if config.map_memory != "off":
            raise NavigationError(
                f"--map-memory {config.map_memory}: the map learns its layout under a chosen "
                "stop rule only (--stop-policy); the paper's rule keeps the map it was given"
            )
        return
    if set(stop_rules) != set(runs):
        raise NavigationError("stop rules: expected one for each localizer run")
    if config.trace or config.replan:
        raise NavigationError("episodes stopped by a chosen rule are neither traced nor replanned")


def _finished_part(job: dict[str, Any], out: Path) -> list[dict[str, Any]]:
    part = _part(job, out)
    if part is None:
        raise NavigationError(f"{_part_path(job, out)}: missing after its task ran")
    return part


def seed_maps(
    runs: list[Path],
    full_maps: dict[Path, Path],
    rooms: list[str],
    maps: Path,
    *,
    spacing: int = MAP_SPACING,
) -> list[Path]:
    """Put into :func:`run_navigation`'s map cache ``maps``, for each run of ``full_maps``
    and each room, the map it would build, derived from that run's spacing-1 map in
    ``full_maps[run]/<room>`` (e.g. a full-map recall's): the same views and embeddings, not
    rendered again. Maps already there are kept; a derived map of another checkpoint is found
    stale by :func:`run_navigation` and built anew. Returns the maps written."""
    written = []
    for run, label in zip(runs, run_labels(runs), strict=True):
        source = full_maps.get(run)
        if source is None:
            continue
        for room_id in rooms:
            target = maps / label / room_id
            if not (target / MAP_META).is_file() and (source / room_id / MAP_META).is_file():
                save_map(derive_map(load_map(source / room_id), spacing), target)
                written.append(target)
    return written


def _localizer(
    run: Path | str, data: DataSource, epsilon: float | dict[Path, tuple[float, str]] | None
) -> AnyLocalizer:
    if isinstance(epsilon, dict):
        given, source = epsilon.get(run, (None, ""))  # type: ignore[call-overload]
        return open_localizer(run, data, epsilon=given, source=source)
    return open_localizer(run, data, epsilon=epsilon)


def _label_parts(run: Path | str) -> tuple[str, ...]:
    """A path's (or a directory's) resolved parts; a method's name made one file name."""
    if isinstance(run, Path) or Path(run).is_dir():
        return Path(run).resolve().parts
    return (method_label(str(run)),)


def run_labels(runs: list[Path | str]) -> list[str]:
    """The shortest tails of the runs' paths (parts joined by ``_``) that are all different;
    a method's name (made a file name) is one part.

    Raises:
        NavigationError: a run given twice.
    """
    paths = [_label_parts(run) for run in runs]
    if len(set(paths)) < len(paths):
        raise NavigationError("a localizer run is given twice; give each once")
    for k in range(1, max(len(p) for p in paths) + 1):
        labels = ["_".join(p[-k:]).lstrip("/_") for p in paths]
        if len(set(labels)) == len(labels):
            return labels
    raise NavigationError("localizer runs cannot be told apart by their paths")  # unreachable


# What a part depends on: the test's settings, the run and its threshold, the room and case.
_KEY_FIELDS = (
    "split", "episodes_per_case_and_room", "seed", "k_max", "spacing", "replan", "trace",
    "navigator_sha256", "dataset", "run", "checkpoint_sha256", "epsilon", "room_id", "case",
    "stop_rule", "map_memory", "graphs",
)  # fmt: skip


def _key(job: dict[str, Any]) -> dict[str, Any]:
    return {k: job[k] for k in _KEY_FIELDS if k in job}  # settings name some only when set


def _part_path(job: dict[str, Any], out: Path) -> Path:
    return out / PARTS / job["label"] / f"{job['room_id']}_{job['case']}.json"


def _part(job: dict[str, Any], out: Path) -> list[dict[str, Any]] | None:
    """The episodes of a finished task whose key matches ``job``'s, else None."""
    path = _part_path(job, out)
    try:
        part = json.loads(path.read_text())
    except (OSError, ValueError):
        return None
    if not isinstance(part, dict) or part.get("key") != json.loads(json.dumps(_key(job))):
        return None
    return part.get("episodes")


def _one_thread() -> None:
    """Every network of a task on one thread: results then do not depend on the machine."""
    import torch

    torch.set_num_threads(1)


def _live_rooms(ds: Any, graphs: LiveGraphs | None) -> LiveRooms:
    """The task's renderer, its views given the detector's graphs when ``graphs`` says so."""
    return LiveRooms(ds, regraph=graphs.regraph(ds) if graphs is not None else None)


def _map_task(
    run: str, data: Path, room_id: str, directory: Path, spacing: int, graphs: LiveGraphs | None
) -> dict:
    """Build (or reuse) one room's map by one run (in a worker)."""
    _one_thread()
    ds = open_dataset(data)  # once per task: a worker has no handle of the command's
    localizer = open_localizer(run, ds, require_epsilon=False)
    with _live_rooms(ds, graphs) as live:
        ensure_map(localizer, live, room_id, directory, spacing=spacing)
    return {"run": str(run), "room_id": room_id}


def _case_task(job: dict[str, Any], data: str, out: str) -> dict:
    """Every episode of one (run, room, case), written as one part file (in a worker)."""
    _one_thread()
    ds = open_dataset(data)  # once per task: a worker has no handle of the command's
    localizer = open_localizer(job["run"], ds, epsilon=job["epsilon"])
    navigator = job["navigator"]
    policy = None if navigator == ORACLE else load_navigator(Path(navigator))
    directory = Path(job["map"])
    topo = load_map(directory)
    check_map(topo, localizer, directory)
    room_id, case = job["room_id"], job["case"]
    rule = StopRule(**job["stop_rule"]) if "stop_rule" in job else None
    scope = job.get("map_memory", "off")
    learned: dict[int, np.ndarray] = {}  # map_memory "layout": the map as each layout taught it
    records = []
    drawn: set[str] = set()  # the outcome kinds drawn as strips already
    graphs = LiveGraphs(**job["graphs"]) if "graphs" in job else None
    with _live_rooms(ds, graphs) as live:
        for index in range(job["episodes_per_case_and_room"]):
            rng = rng_for(episode_seed(job["seed"], room_id, case, index))
            episode = sample_episode(topo, live, case, rng, index=index)
            memory = None
            if scope == "episode":
                memory = topo.embeddings.copy()
            elif scope == "layout":
                memory = learned.setdefault(episode.layout, topo.embeddings.copy())
            keep = job["strips"] is not None
            started = time.perf_counter()
            result = run_episode(
                episode, topo, live, localizer, policy,
                k_max=job["k_max"], replan=job["replan"], keep_frames=keep, trace=job["trace"],
                rule=rule, memory=memory,
            )  # fmt: skip
            record = result.to_dict()
            record["seconds"]["total"] = time.perf_counter() - started
            records.append(record)
            kind = "_".join(str(k).replace(" ", "-") for k in (result.outcome, result.detail) if k)
            if keep and kind not in drawn:  # the first episode of each kind (the paper's Fig. 9)
                drawn.add(kind)
                strip = draw_strip(result, topo.image(episode.path[-1]))
                save_png(strip, Path(job["strips"]) / f"{room_id}_{case}_{index}_{kind}.png")
    path = _part_path(job, Path(out))
    atomic_write_text(path, json.dumps({"key": _key(job), "episodes": records}))
    return {"label": job["label"], "room_id": room_id, "case": case}


def draw_strip(result: EpisodeResult, goal: np.ndarray) -> Image.Image:
    """An episode as a strip (the paper's Fig. 9): start, each step's view with its action
    and S, then the goal view; the outcome in the title."""
    e = result.episode
    labels = ["start"]
    for _, steps in result.segments:
        labels += [f"{s.action} S={s.similarity:.2f}" for s in steps if not s.collided]
    frames = list(zip(result.frames, labels, strict=False))[: STRIP_MAX_PANELS - 1]
    frames.append((goal, "goal"))
    size, top = STRIP_PANEL, 34
    image = Image.new("RGB", (len(frames) * (size + 4) + 4, size + top + 18), "white")
    draw = ImageDraw.Draw(image)
    font = ImageFont.load_default(size=11)
    title = (
        f"{e.room_id} layout {e.layout} case {e.case} #{e.index}: {result.outcome} "
        f"({len(e.path) - 1} segments)"
    )
    draw.text((4, 4), title, fill="black", font=font)
    for k, (rgb, label) in enumerate(frames):
        x = 4 + k * (size + 4)
        image.paste(Image.fromarray(resize(rgb, size)), (x, top))
        draw.text((x, top + size + 3), label, fill="black", font=font)
    return image
