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
room weigh the per-room stages as a real run does). The tasks time themselves: they are given
a :class:`sgdata.stage_clock.StageClock` (what ``sgdata generate --profile`` gives each task),
which books each stage's exclusive time; ``other`` is what no stage claims, so the stages add
up to the wall time of the two phases. Phase 2 (triplet sampling, per split, in the main
process) and the manifest are not measured.

A worker's first room (imports, the renderer's EGL context, shader compilation) runs before
the clock starts, as a worker pays it once for all its rooms; those costs are printed apart.
The ``render`` stage is the RGB and id passes with their read-backs (GL queues the draws, so a
pass's drawing is paid where its pixels are read).

Run it on one llvmpipe thread (``LP_NUM_THREADS=1``, what every worker of ``sgdata generate``
uses) on a quiet machine; figures in docs/benchmarks.md. The run is followed by a side
measurement of PNG compression levels on the run's own images (read back from its shards; size
and ms per image, each checked lossless); it changes nothing the generator writes.
"""

from __future__ import annotations

import argparse
import dataclasses
import io
import json
import os
import sys
import tempfile
import time
from collections import defaultdict
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq

from sgdata import markdown
from sgdata.dataset import decode_image
from sgdata.dataset.paths import observations_path
from sgdata.pipeline import room_tasks
from sgdata.pipeline.config import GenerateConfig, load_config
from sgdata.pipeline.ledger import read_record, scene_record
from sgdata.stage_clock import OTHER, StageClock
from sgdata.world.poses import HEADINGS_DEG
from sgdata.world.triplets import PoseKey

PNG_LEVELS = (1, 3, 6, 9)


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
        for heading in range(len(HEADINGS_DEG))
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
    clock = StageClock()
    room_tasks.write_room_scenes(task, config, root, clock)
    views = sample_views(read_record(scene_record(root, task.room_id)), WARM_UP_VIEWS, rng)
    room_tasks.render_room_views(task, views, config, root, clock)
    phase = defaultdict(float)
    for (name, _), seconds in clock.seconds.items():
        phase[name] += seconds
    renderer = clock.seconds[("views", "renderer start")]
    return {
        "warm_up_scenes_s": phase["scenes"],
        "renderer_start_s": renderer,
        "warm_up_views_s": phase["views"] - renderer,
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


def shard_images(root: Path, tasks: list[room_tasks.RoomTask], keep: int) -> list[np.ndarray]:
    """The first ``keep`` images the run wrote, decoded from its shards (PNG: lossless)."""
    images: list[np.ndarray] = []
    for task in tasks:
        path = root / observations_path(task.split, task.room_id)
        for cell in pq.read_table(path, columns=["image"]).column("image").to_pylist():
            if len(images) == keep:
                return images
            images.append(decode_image(cell))
    return images


def measure(args: argparse.Namespace) -> dict:
    config = load_config(args.config)
    config = dataclasses.replace(
        config, dataset=dataclasses.replace(config.dataset, seed=args.seed)
    )
    rng = np.random.default_rng(args.seed)
    *tasks, spare = room_tasks_for(config, args.rooms + 1)  # the last one warms up
    clock = StageClock()
    with tempfile.TemporaryDirectory(prefix="sgdata-stages-") as tmp:
        root = Path(tmp)
        startup = warm_up(config, root, spare, rng)
        start = time.perf_counter()
        for task in tasks:
            room_tasks.write_room_scenes(task, config, root, clock)
        scenes_wall = time.perf_counter() - start
        picks = {
            t.room_id: sample_views(read_record(scene_record(root, t.room_id)), args.views, rng)
            for t in tasks
        }
        start = time.perf_counter()
        views = 0
        for task in tasks:
            views += room_tasks.render_room_views(task, picks[task.room_id], config, root, clock)[
                "views"
            ]
        views_wall = time.perf_counter() - start
        images = shard_images(root, tasks, args.png_sample)
    wall = scenes_wall + views_wall
    stages = [
        {
            **row,
            "ms_per_view": 1000 * row["seconds"] / max(views, 1),
            "share": row["seconds"] / wall,
        }
        for row in clock.rows(room_tasks.stage_order())
    ]
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
    views = max(result["views"], 1)
    rows = [
        [
            s["stage"],
            s["phase"],
            s["calls"],
            f"{s['seconds']:.3f}",
            f"{s['ms_per_view']:.2f}",
            f"{100 * s['share']:.1f} %",
        ]
        for s in result["stages"]
    ]
    rows.append(
        ["**wall time**", "", "", f"**{result['wall_s']:.3f}**",
         f"**{1000 * result['wall_s'] / views:.2f}**", "100 %"]
    )  # fmt: skip
    lines = [
        f"`sgdata generate`, one worker: {result['rooms']} room(s) of `{result['config']}` "
        f"({result['camera'][0]} x {result['camera'][1]}, textures "
        f"{'on' if result['textures'] else 'off'}), {result['views']} views, "
        f"LP_NUM_THREADS={result['lp_num_threads']}",
        "",
        *markdown.table(
            ("stage", "phase", "calls", "total s", "ms per view", "share"), rows, right=range(2, 6)
        ),
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
    ]
    generator = result["png"][0]
    levels = [
        [
            p["encoder"] + (" (the generator's)" if p["same_as_generator"] else ""),
            f"{p['bytes']:,.0f}",
            f"{p['ms']:.2f}",
            f"{p['bytes'] / generator['bytes']:.2f}",
            f"{p['ms'] / generator['ms']:.2f}",
            "yes" if p["lossless"] else "NO",
        ]
        for p in (result["png"][1:] if result["png"] and generator["bytes"] else [])
    ]
    header = (
        "PNG",
        "bytes per image",
        "ms per image",
        "bytes / generator's",
        "time / generator's",
        "lossless",
    )
    lines += markdown.table(header, levels)
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
