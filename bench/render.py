"""Views per second: bare pyrender passes (RGB, id) against the full view pipeline.

    python bench/render.py --synthetic            # the tests' tiny room, runs today
    python bench/render.py --rooms 2 --views 40   # generated rooms (sgdata.world.rooms + usd_io)
    LP_NUM_THREADS=1 python bench/render.py --synthetic

Prints frames per second of the RGB pass, the id pass, both (what the pipeline must do) and
the full pipeline (render -> annotate -> slots -> relations), and the pipeline's ratio to the
bare passes (target >= 0.85).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from sgdata.annotate.annotator import ViewAnnotator  # noqa: E402
from sgdata.annotate.records import ViewPose  # noqa: E402
from sgdata.annotate.slots import SlotTable  # noqa: E402
from sgdata.render.renderer import Renderer  # noqa: E402
from sgdata.usd.meshes import SceneGeometry  # noqa: E402
from sgdata.world.poses import pose_grid  # noqa: E402
from sgdata.world.scene import Room  # noqa: E402


def synthetic_scenes() -> list[tuple[Room, SceneGeometry]]:
    sys.path.insert(0, str(ROOT / "tests"))
    from conftest import build_tiny_room  # the tests' hand-built room

    tiny = build_tiny_room()
    return [(tiny.room, tiny.geometry)]


def generated_scenes(n: int, seed: int) -> list[tuple[Room, SceneGeometry]]:
    from sgdata.usd import room_io as usd_io
    from sgdata.usd.geometry import read_geometry
    from sgdata.world.catalog import load_catalog
    from sgdata.world.rooms import generate_room

    catalog = load_catalog()
    types = ["kitchen", "living_room", "bedroom", "bathroom"]
    out = []
    tmp = Path(tempfile.mkdtemp(prefix="sgdata-bench-"))
    for k in range(n):
        room = generate_room(types[k % len(types)], k // len(types), seed, catalog)
        path = tmp / f"{room.room_id}.usda"
        usd_io.write_room(room, path, geometry=usd_io.catalog_geometry(catalog))
        out.append((room, read_geometry(path)))
    return out


def sample_poses(room: Room, count: int, rng: np.random.Generator) -> list[ViewPose]:
    grid = pose_grid(room)
    if not grid.cells:
        return []
    picks = rng.integers(0, len(grid.cells), count)
    poses = []
    for p in picks:
        i, j = grid.cells[int(p)]
        h = int(rng.integers(0, 4))
        x, y, th = grid.pose_world(i, j, h)
        poses.append(ViewPose(x, y, th, i, j, h))
    return poses


def rate(fn: Callable[[ViewPose], object], poses: list[ViewPose]) -> float:
    fn(poses[0])  # warm-up: shader compilation, buffer upload
    t = time.perf_counter()
    for p in poses:
        fn(p)
    return len(poses) / (time.perf_counter() - t)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--synthetic", action="store_true", help="use the tests' tiny room")
    ap.add_argument("--rooms", type=int, default=1, help="generated rooms to bench")
    ap.add_argument("--views", type=int, default=40, help="views per room and measurement")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--id-pass", choices=["raster", "raycast"], default="raster")
    args = ap.parse_args()

    scenes = synthetic_scenes() if args.synthetic else generated_scenes(args.rooms, args.seed)
    classes = sorted({o.class_name for room, _ in scenes for o in room.objects})
    slots = SlotTable.from_counts([(c, 8) for c in classes], num_slots=max(256, 8 * len(classes)))
    renderer = Renderer(id_pass=args.id_pass)
    annotator = ViewAnnotator(renderer, slots)
    rng = np.random.default_rng(args.seed)
    totals: dict[str, list[float]] = {"rgb": [], "ids": [], "rgb+ids": [], "pipeline": []}
    for room, geometry in scenes:
        annotator.set_layout(room, geometry, 0)
        poses = sample_poses(room, args.views, rng)
        if not poses:
            print(f"{room.room_id}: no reachable cells, skipped")
            continue
        fps = {
            "rgb": rate(lambda p: renderer.render_rgb(p.x, p.y, p.theta), poses),
            "ids": rate(lambda p: renderer.render_ids(p.x, p.y, p.theta), poses),
            "rgb+ids": rate(lambda p: renderer.render(p.x, p.y, p.theta), poses),
            "pipeline": rate(lambda p: annotator.view(p), poses),
        }
        for key, value in fps.items():
            totals[key].append(value)
        objs = len(geometry.objects)
        tris = sum(len(o.mesh.faces) for o in geometry.objects)
        print(
            f"{room.room_id}: {objs} objects, {tris} triangles | "
            + " | ".join(f"{k} {v:.1f}/s" for k, v in fps.items())
        )
    if totals["pipeline"]:
        mean = {k: float(np.mean(v)) for k, v in totals.items()}
        print(
            "mean: "
            + " | ".join(f"{k} {v:.1f}/s" for k, v in mean.items())
            + f" | pipeline / (rgb+ids) = {mean['pipeline'] / mean['rgb+ids']:.2f}"
        )
    renderer.close()


if __name__ == "__main__":
    main()
