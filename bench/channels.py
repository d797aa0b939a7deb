"""Views per second with the depth and instance channels on against RGB only, and PNG bytes
per view per channel, on the same views of a generated room, in one run (ABAB).

    python bench/channels.py out/tiny        # a dataset with scenes/ (sgdata generate tiny)
    LP_NUM_THREADS=1 python bench/channels.py ROOT --views 60 --json

A view is what generation does per view: render, annotate, and encode the row's PNGs (RGB,
plus depth and mask when on). Aim (issue 33): channels on >= 0.85x the views/s of RGB only.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from sgdata.annotate.annotator import ViewAnnotator
from sgdata.annotate.records import ViewPose
from sgdata.dataset.channels import encode_depth, encode_mask
from sgdata.dataset.rows import encode_image
from sgdata.dataset.vocabulary import class_vocabulary
from sgdata.render.renderer import Renderer
from sgdata.usd.geometry import read_geometry
from sgdata.usd.room_io import read_room
from sgdata.world.poses import HEADINGS_DEG, PosesConfig

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("root", type=Path, help="a dataset root holding scenes/")
    parser.add_argument("--views", type=int, default=60)
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    layout = sorted((args.root / "scenes").glob("*/layout_0.usda"))[0]
    room, geometry = read_room(layout), read_geometry(layout)
    grid = PosesConfig().grid(room)
    headings = len(HEADINGS_DEG)
    cells = grid.cells[:: max(1, len(grid.cells) // max(1, args.views // headings))]
    poses = [
        ViewPose(*grid.pose_world(i, j, h), i, j, h) for i, j in cells for h in range(headings)
    ][: args.views]
    slots, _ = class_vocabulary()
    renderer = Renderer()
    runs = {
        "rgb": ViewAnnotator(renderer, slots),
        "channels": ViewAnnotator(renderer, slots, keep_depth=True, keep_instances=True),
    }
    for a in runs.values():
        a.set_layout(room, geometry, 0)
    seconds = {k: 0.0 for k in runs}
    sizes: dict[str, list[int]] = {"image": [], "depth": [], "instances": []}
    for name in [*runs, *runs]:  # ABAB: a busy machine skews both alike
        start = time.perf_counter()
        for pose in poses:
            rec = runs[name].view(pose)
            rgb = encode_image(rec.rgb)
            if rec.depth is not None and rec.instances is not None:
                depth, mask = encode_depth(rec.depth), encode_mask(rec.instances)
                if len(sizes["depth"]) < len(poses):
                    sizes["image"].append(len(rgb))
                    sizes["depth"].append(len(depth))
                    sizes["instances"].append(len(mask))
        seconds[name] += time.perf_counter() - start
    renderer.close()
    rate = {k: 2 * len(poses) / s for k, s in seconds.items()}
    out = {
        "room": layout.parent.name,
        "views": len(poses),
        "views_per_s": {k: round(v, 2) for k, v in rate.items()},
        "ratio": round(rate["channels"] / rate["rgb"], 3),
        "bytes_per_view": {k: int(np.mean(v)) for k, v in sizes.items()},
    }
    if args.json:
        print(json.dumps(out))
        return
    print(f"{out['room']}, {out['views']} views, each twice (ABAB)")
    print(f"views/s RGB only {rate['rgb']:.1f}, with depth + instances {rate['channels']:.1f}")
    print(f"ratio {out['ratio']:.3f} (aim >= 0.85)")
    print("PNG bytes per view: " + ", ".join(f"{k} {v}" for k, v in out["bytes_per_view"].items()))


if __name__ == "__main__":
    main()
