"""Where the time of ``sgdata generate`` goes, stage by stage, on one worker.

    LP_NUM_THREADS=1 python bench/stages.py                          # 4 rooms, 225 views each
    LP_NUM_THREADS=1 python bench/stages.py --rooms 1 --views 10    # a quick look
    LP_NUM_THREADS=1 python bench/stages.py --json                  # one JSON line

Runs the two per-room tasks a worker of ``sgdata generate`` runs, in this process and in the
pipeline's order: :func:`~sgdata.pipeline.room_tasks.write_room_scenes` (phase 1: the room and
its layouts as USD, the reachable cells) for ``--rooms`` generated rooms (the room types in
turn), then :func:`~sgdata.pipeline.room_tasks.render_room_views` (phase 3: USD load, render,
annotate, encode, write the shard) on ``--views`` distinct views of each, drawn uniformly from
the reachable (layout, cell, heading) keys, as triplets reference them. The config is
``--config`` (default the ``paper`` preset: 224 px, textured, 5 layouts; its ~225 views per
room weigh the per-room stages as a real run does). Nothing is re-implemented: every function
those tasks call is wrapped, for the run, in a timer (``time.perf_counter``) that books the time
spent in it, less that of the wrapped calls inside it, to its stage; what no stage claims is
``other``, so the stages add up to the wall time of the two phases. Phase 2 (triplet sampling,
per split, in the main process) and the manifest are not measured.

The renderer is started (EGL context) and draws one view (shader compilation, texture upload)
before the clock starts, as a worker does once for all its rooms; those costs are printed
apart. Each read-back is preceded by a ``glFinish``: GL queues the draws, so without it the
read-back would wait for the pass's rasterisation; with it a pass's row holds its own drawing.
It changes no pixel.

Run it on one llvmpipe thread (``LP_NUM_THREADS=1``, what every worker of ``sgdata generate``
uses) on a quiet machine; figures in docs/benchmarks.md. The image-encode stage is followed by a
side measurement of PNG compression levels on the run's own images (size and ms per image, each
checked lossless); it changes nothing the generator writes.
"""

from __future__ import annotations

import argparse
import dataclasses
import functools
import io
import json
import os
import sys
import tempfile
import time
from collections import defaultdict
from collections.abc import Callable, Iterator
from contextlib import ExitStack, contextmanager
from pathlib import Path
from typing import Any
from unittest import mock

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from sgdata.pipeline import room_tasks  # noqa: E402
from sgdata.pipeline.config import GenerateConfig, load_config  # noqa: E402
from sgdata.pipeline.ledger import read_record, scene_record  # noqa: E402
from sgdata.world.triplets import PoseKey  # noqa: E402

SCENES, VIEWS = "scenes", "views"
OTHER = "other"
# The stages, in pipeline order: (phase, key, label). The wrapped functions are in _targets.
STAGES: tuple[tuple[str, str, str], ...] = (
    (SCENES, "catalog", "catalog load (load_catalog)"),
    (SCENES, "generate_room", "room generation (generate_room)"),
    (SCENES, "catalog_geometry", "catalog geometry (catalog_geometry)"),
    (SCENES, "write_room", "room USD + textures (write_room)"),
    (SCENES, "sample_layouts", "layout sampling (sample_layouts)"),
    (SCENES, "write_layout", "layout USD layers (write_layout)"),
    (SCENES, "write_layouts", "layouts, rest (write_layouts)"),
    (SCENES, "read_room", "USD read (read_room)"),
    (SCENES, "usd_open", "USD open + compose (open_stage)"),
    (SCENES, "grid", "reachable pose grid (PosesConfig.grid)"),
    (SCENES, "ledger", "ledger record (write_record)"),
    (SCENES, OTHER, "other (write_room_scenes between the calls)"),
    (VIEWS, "read_room", "USD load: room (read_room)"),
    (VIEWS, "read_geometry", "USD load: geometry (read_geometry)"),
    (VIEWS, "usd_open", "USD load: open + compose (open_stage)"),
    (VIEWS, "scene_build", "renderer scene build (Renderer.load / update_poses)"),
    (VIEWS, "texture", "texture decode (Renderer._texture)"),
    (VIEWS, "object_table", "object table (ObjectTable.from_scene)"),
    (VIEWS, "grid", "pose grid (PosesConfig.grid)"),
    (VIEWS, "rgb_pass", "RGB pass (Renderer.render_rgb, drawing)"),
    (VIEWS, "rgb_readback", "RGB read-back (SingleSampleTarget.read)"),
    (VIEWS, "id_pass", "id pass (Renderer.render_ids: one draw, decode)"),
    (VIEWS, "id_readback", "id read-back (SingleSampleTarget.read)"),
    (VIEWS, "boxes", "visibility + boxes (annotate)"),
    (VIEWS, "slots", "slots (SlotTable.assign)"),
    (VIEWS, "relations", "relations (stored_precision, compute_relations)"),
    (VIEWS, "record", "view record (ViewAnnotator.view, rest)"),
    (VIEWS, "encode", "image encode (encode_image)"),
    (VIEWS, "rows", "rows (observation_table, rest)"),
    (VIEWS, "parquet", "Parquet write (write_parquet: zstd, fsync)"),
    (VIEWS, "sha256", "shard sha256 (sha256_file)"),
    (VIEWS, "ledger", "ledger record (write_record)"),
    (VIEWS, OTHER, "other (render_room_views between the calls)"),
)
PNG_LEVELS = (1, 3, 6, 9)


class StageClock:
    """Exclusive time per (phase, stage): a call's time less that of the timed calls inside."""

    def __init__(self) -> None:
        self.phase = SCENES
        self.seconds: dict[tuple[str, str], float] = defaultdict(float)
        self.calls: dict[tuple[str, str], int] = defaultdict(int)
        self._stack: list[list[Any]] = []  # [stage, seconds of timed calls inside]

    @property
    def current(self) -> str | None:
        """The stage being timed now (the innermost), if any."""
        return self._stack[-1][0] if self._stack else None

    @contextmanager
    def stage(self, name: str) -> Iterator[None]:
        start = time.perf_counter()
        self._stack.append([name, 0.0])
        try:
            yield
        finally:
            elapsed = time.perf_counter() - start
            _, inner = self._stack.pop()
            self.seconds[(self.phase, name)] += elapsed - inner
            self.calls[(self.phase, name)] += 1
            if self._stack:
                self._stack[-1][1] += elapsed

    def wrap(self, name: str, fn: Callable[..., Any]) -> Callable[..., Any]:
        @functools.wraps(fn)
        def timed(*args: Any, **kwargs: Any) -> Any:
            with self.stage(name):
                return fn(*args, **kwargs)

        return timed


def _targets() -> list[tuple[Any, str, str]]:
    """(owner, attribute, stage): the functions the two room tasks call, where they look them
    up (a name imported inside a task's body is read from its module at call time; one
    imported at a module's top from that module)."""
    from sgdata.annotate import annotator
    from sgdata.annotate.slots import SlotTable
    from sgdata.dataset import rows
    from sgdata.render.renderer import Renderer
    from sgdata.usd import geometry, looks, own_layouts, room_io, scene_dirs
    from sgdata.world import poses, rooms

    return [
        (room_tasks, "load_catalog", "catalog"),
        (rooms, "generate_room", "generate_room"),
        (room_io, "catalog_geometry", "catalog_geometry"),
        (room_io, "write_room", "write_room"),
        (scene_dirs, "write_layouts", "write_layouts"),
        (scene_dirs, "sample_layouts", "sample_layouts"),
        (scene_dirs, "write_layout", "write_layout"),
        (room_io, "read_room", "read_room"),
        (scene_dirs, "read_room", "read_room"),
        (poses.PosesConfig, "grid", "grid"),
        (room_tasks, "write_record", "ledger"),
        (geometry, "read_geometry", "read_geometry"),
        *((module, "open_stage", "usd_open") for module in (room_io, geometry, looks, own_layouts)),
        (Renderer, "load", "scene_build"),
        (Renderer, "update_poses", "scene_build"),
        (Renderer, "_texture", "texture"),
        (Renderer, "render_rgb", "rgb_pass"),
        (Renderer, "render_ids", "id_pass"),
        (annotator.ViewAnnotator, "view", "record"),
        (annotator, "annotate", "boxes"),
        (SlotTable, "assign", "slots"),
        (annotator, "stored_precision", "relations"),
        (annotator, "compute_relations", "relations"),
        (rows, "observation_table", "rows"),
        (rows, "encode_image", "encode"),
        (rows, "write_parquet", "parquet"),
        (rows, "sha256_file", "sha256"),
    ]


@contextmanager
def instrumented(
    clock: StageClock, images: list[np.ndarray], keep: int, renderer: Any
) -> Iterator[None]:
    """Every stage's function wrapped in ``clock`` for the block, and the read-backs of the
    worker's ``renderer``; the first ``keep`` images handed to the encoder are kept in
    ``images`` (for the PNG side measurement)."""
    from OpenGL.GL import glFinish

    from sgdata.annotate.boxes import ObjectTable
    from sgdata.dataset import rows

    with ExitStack() as stack:
        for owner, name, stage in _targets():
            stack.enter_context(
                mock.patch.object(owner, name, clock.wrap(stage, getattr(owner, name)))
            )
        from_scene = ObjectTable.from_scene.__func__
        stack.enter_context(
            mock.patch.object(
                ObjectTable, "from_scene", classmethod(clock.wrap("object_table", from_scene))
            )
        )
        # both passes read through the renderer's target: the RGB pass as pyrender's
        # _read_main_framebuffer (bound when the renderer was built), the id pass directly
        target, read = renderer._target, renderer._target.read

        def read_back(*args: Any, **kwargs: Any) -> Any:
            glFinish()  # the queued drawing finishes here, booked to the pass that queued it
            where = {"rgb_pass": "rgb_readback", "id_pass": "id_readback"}
            with clock.stage(where.get(clock.current or "", "rgb_readback")):
                return read(*args, **kwargs)

        stack.enter_context(mock.patch.object(target, "read", read_back))
        stack.enter_context(
            mock.patch.object(renderer._gl._renderer, "_read_main_framebuffer", read_back)
        )
        encode = rows.encode_image  # the timed one, patched above

        def kept(rgb: np.ndarray, *args: Any, **kwargs: Any) -> bytes:
            if len(images) < keep:
                images.append(rgb)
            return encode(rgb, *args, **kwargs)

        stack.enter_context(mock.patch.object(rows, "encode_image", kept))
        yield


def room_tasks_for(config: GenerateConfig, count: int) -> list[room_tasks.RoomTask]:
    """``count`` procedural rooms of the config's types in turn (kitchen 0, living room 0, ...)."""
    types = config.rooms.procedural_types
    return [
        room_tasks.RoomTask(types[k % len(types)], k // len(types), "train") for k in range(count)
    ]


def sample_views(record: dict, count: int, rng: np.random.Generator) -> list[PoseKey]:
    """``count`` distinct reachable (layout, cell, heading) keys of a room's scene record."""
    keys = [
        PoseKey(int(layout), int(i), int(j), heading)
        for layout, cells in sorted(record["reachable"].items(), key=lambda kv: int(kv[0]))
        for i, j in cells
        for heading in range(4)
    ]
    if len(keys) <= count:
        return keys
    return [keys[k] for k in sorted(rng.choice(len(keys), size=count, replace=False))]


WARM_UP_VIEWS = 3


def warm_up(
    config: GenerateConfig, root: Path, task: room_tasks.RoomTask, rng: np.random.Generator
) -> dict[str, float]:
    """A worker's first room, outside the clock: both room tasks on a room of their own.

    It pays what a worker pays once, not per room: imports on first use (USD, Pillow's
    plugins, pyarrow's writer), the renderer (EGL context), shader compilation."""
    start = time.perf_counter()
    room_tasks.write_room_scenes(task, config, root)
    scenes = time.perf_counter()
    room_tasks._annotator(config)  # the worker's annotator, built once and cached (real path)
    renderer = time.perf_counter()
    views = sample_views(read_record(scene_record(root, task.room_id)), WARM_UP_VIEWS, rng)
    room_tasks.render_room_views(task, views, config, root)
    return {
        "warm_up_scenes_s": scenes - start,
        "renderer_start_s": renderer - scenes,
        "warm_up_views_s": time.perf_counter() - renderer,
    }


def png_levels(images: list[np.ndarray], levels: tuple[int, ...], repeats: int = 3) -> list[dict]:
    """Size and encoding time per image of the generator's encoder and of PNG at ``levels``
    (Pillow, the generator's other settings), each decoded and compared with its pixels. An
    image's time is the least of ``repeats`` encodings (a busy machine only adds time)."""
    from PIL import Image

    from sgdata.dataset.rows import encode_image

    def pillow(level: int) -> Callable[[np.ndarray], bytes]:
        def encode(rgb: np.ndarray) -> bytes:
            buffer = io.BytesIO()
            Image.fromarray(rgb, mode="RGB").save(
                buffer, format="PNG", optimize=False, compress_level=level
            )
            return buffer.getvalue()

        return encode

    encoders = {"generator": encode_image, **{str(k): pillow(k) for k in levels}}
    size: dict[str, int] = defaultdict(int)
    seconds: dict[str, float] = defaultdict(float)
    lossless = dict.fromkeys(encoders, True)
    same = dict.fromkeys(encoders, True)  # bytes identical to the generator's
    for rgb in images:  # levels in turn on each image: a busy machine skews them alike
        reference = b""
        for name, encode in encoders.items():
            best = float("inf")
            for _ in range(repeats):
                start = time.perf_counter()
                data = encode(rgb)
                best = min(best, time.perf_counter() - start)
            seconds[name] += best
            size[name] += len(data)
            reference = reference or data
            same[name] &= data == reference
            with Image.open(io.BytesIO(data)) as back:
                lossless[name] &= bool(np.array_equal(np.asarray(back.convert("RGB")), rgb))
    n = max(len(images), 1)
    return [
        {
            "encoder": "encode_image" if name == "generator" else f"level {name}",
            "level": None if name == "generator" else int(name),
            "same_as_generator": same[name],  # the generator's own setting (bytes identical)
            "bytes": size[name] / n,
            "ms": 1000 * seconds[name] / n,
            "lossless": lossless[name],
        }
        for name in encoders
    ]


def measure(args: argparse.Namespace) -> dict:
    config = load_config(args.config)
    config = dataclasses.replace(
        config, dataset=dataclasses.replace(config.dataset, seed=args.seed)
    )
    rng = np.random.default_rng(args.seed)
    *tasks, spare = room_tasks_for(config, args.rooms + 1)  # the last one warms up
    clock = StageClock()
    images: list[np.ndarray] = []
    with tempfile.TemporaryDirectory(prefix="sgdata-stages-") as tmp:
        root = Path(tmp)
        startup = warm_up(config, root, spare, rng)
        renderer = room_tasks._annotator(config)[0].renderer  # the worker's, cached
        with instrumented(clock, images, args.png_sample, renderer):
            clock.phase = SCENES
            start = time.perf_counter()
            for task in tasks:
                with clock.stage(OTHER):
                    room_tasks.write_room_scenes(task, config, root)
            scenes_wall = time.perf_counter() - start
            picks = {
                t.room_id: sample_views(read_record(scene_record(root, t.room_id)), args.views, rng)
                for t in tasks
            }
            clock.phase = VIEWS
            start = time.perf_counter()
            views = 0
            for task in tasks:
                with clock.stage(OTHER):
                    done = room_tasks.render_room_views(task, picks[task.room_id], config, root)
                views += done["views"]
            views_wall = time.perf_counter() - start
    wall = scenes_wall + views_wall
    stages = []
    for phase, key, label in STAGES:
        seconds = clock.seconds.get((phase, key), 0.0)
        stages.append(
            {
                "phase": phase,
                "stage": key,
                "label": label,
                "calls": clock.calls.get((phase, key), 0),
                "seconds": seconds,
                "ms_per_view": 1000 * seconds / max(views, 1),
                "share": seconds / wall,
            }
        )
    named = sum(s["seconds"] for s in stages if s["stage"] != OTHER)
    return {
        "config": args.config,
        "rooms": len(tasks),
        "views": views,
        "lp_num_threads": os.environ.get("LP_NUM_THREADS"),
        "camera": [config.camera.width, config.camera.height],
        "textures": config.appearance.textures,
        "scenes_wall_s": scenes_wall,
        "views_wall_s": views_wall,
        "wall_s": wall,
        "views_per_s": views / views_wall,
        "views_per_s_with_scenes": views / wall,
        "stages_s": sum(s["seconds"] for s in stages),
        "coverage": named / wall,
        **startup,
        "stages": stages,
        "png_images": len(images),
        "png": png_levels(images, tuple(args.png_levels)),
    }


def report(result: dict) -> str:
    lines = [
        f"`sgdata generate`, one worker: {result['rooms']} room(s) of `{result['config']}` "
        f"({result['camera'][0]} x {result['camera'][1]}, textures "
        f"{'on' if result['textures'] else 'off'}), {result['views']} views, "
        f"LP_NUM_THREADS={result['lp_num_threads']}",
        "",
        "| stage | phase | total s | ms per view | share |",
        "|---|---|---|---|---|",
    ]
    for s in result["stages"]:
        lines.append(
            f"| {s['label']} | {s['phase']} | {s['seconds']:.3f} | {s['ms_per_view']:.2f} "
            f"| {100 * s['share']:.1f} % |"
        )
    lines.append(
        f"| **wall time** | | **{result['wall_s']:.3f}** | "
        f"**{1000 * result['wall_s'] / max(result['views'], 1):.2f}** | 100 % |"
    )
    lines += [
        "",
        f"views phase: {result['views_per_s']:.1f} views/s; with the scenes phase: "
        f"{result['views_per_s_with_scenes']:.1f} views/s (phase 2 and the manifest not included)",
        f"named stages cover {100 * result['coverage']:.1f} % of the wall time; all rows "
        f"{100 * result['stages_s'] / result['wall_s']:.1f} %",
        f"before the clock, a worker's first room ({WARM_UP_VIEWS} views; imports, shaders): "
        f"scenes {result['warm_up_scenes_s']:.2f} s, renderer start "
        f"{result['renderer_start_s']:.2f} s, views {result['warm_up_views_s']:.2f} s",
        "",
        f"PNG compression levels on {result['png_images']} of the run's images, against "
        f"`encode_image` ({result['png'][0]['ms']:.2f} ms, {result['png'][0]['bytes']:,.0f} "
        "bytes per image); a measurement only, the generator's output is unchanged:",
        "",
        "| PNG | bytes per image | ms per image | bytes / generator's | time / generator's "
        "| lossless |",
        "|---|---|---|---|---|---|",
    ]
    generator = result["png"][0]
    for p in result["png"][1:] if result["png"] and generator["bytes"] else []:
        setting = " (the generator's)" if p["same_as_generator"] else ""
        lines.append(
            f"| {p['encoder']}{setting} | {p['bytes']:,.0f} | {p['ms']:.2f} | "
            f"{p['bytes'] / generator['bytes']:.2f} | {p['ms'] / generator['ms']:.2f} | "
            f"{'yes' if p['lossless'] else 'NO'} |"
        )
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--config", default="paper", help="preset or TOML file (default paper)")
    parser.add_argument("--rooms", type=int, default=4, help="generated rooms (types in turn)")
    parser.add_argument("--views", type=int, default=225, help="views per room")
    parser.add_argument("--seed", type=int, default=0, help="dataset seed and view draw")
    parser.add_argument("--png-sample", type=int, default=40, help="images for the PNG levels")
    parser.add_argument(
        "--png-levels", type=int, nargs="+", default=list(PNG_LEVELS), help="zlib levels 0-9"
    )
    parser.add_argument("--json", action="store_true", help="print one JSON line")
    args = parser.parse_args(argv)
    if args.rooms < 1 or args.views < 1:
        parser.error("--rooms and --views must be >= 1")
    if os.environ.get("LP_NUM_THREADS") != "1":
        print(
            "note: LP_NUM_THREADS is not 1; every worker of `sgdata generate` renders on one "
            "llvmpipe thread: rerun as LP_NUM_THREADS=1 python bench/stages.py",
            file=sys.stderr,
        )
    result = measure(args)
    print(json.dumps(result) if args.json else report(result))


if __name__ == "__main__":
    main()
