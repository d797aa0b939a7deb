"""Views per second of a room whose objects are users' mesh files against the same procedural room.

    python bench/assets.py                     # 30 mesh objects of ~20k triangles, 40 views
    LP_NUM_THREADS=1 python bench/assets.py --views 60 --json

A procedural kitchen is generated; then every object of as many of its classes as make 30
objects becomes a mesh class (a user catalog written to a temporary folder): each such class
gets its own file, an ellipsoid (an icosphere, 20,480 triangles) or a capsule of about 20k
triangles, stretched to the middle of the class's size bounds and written as PLY by trimesh.
The same room (same objects, placements and sizes) is written to USD with the shipped catalog
and with the mesh catalog (both textured, ``[appearance]`` defaults), read back and rendered
from the same reachable poses: RGB + ids (what the pipeline renders) and the full annotated
view, measured in turn (ABAB, ``--rounds``, the median), so a busy machine skews both alike;
``*_cpu`` figures divide by the process's CPU time instead of wall time (views per CPU
second: what a worker of its own would give, whatever else runs). Mesh classes
draw at most ``max_triangles`` per variant (the catalog's default; ``--max-triangles 0``: the
full 20k); ``meshes_usd_write_s`` includes simplifying them (once per process).
Prints each room's triangles, the views per second, the mesh room's ratio to the procedural
one (target >= 0.5) and the mesh files' read time: the first read of a file and a second call
(cached per process: a worker reads each file once).
"""

from __future__ import annotations

import argparse
import atexit
import json
import os
import shutil
import tempfile
import time
from pathlib import Path

import numpy as np

from sgdata.annotate.annotator import ViewAnnotator
from sgdata.annotate.slots import SlotTable
from sgdata.bench import sample_poses, views_per_second
from sgdata.render.renderer import Renderer
from sgdata.usd.geometry import read_geometry
from sgdata.usd.room_io import catalog_geometry, write_room
from sgdata.world.appearance import AppearanceConfig
from sgdata.world.catalog import Catalog, load_catalog
from sgdata.world.mesh_assets import class_assets
from sgdata.world.rooms import generate_room
from sgdata.world.scene import Room

MESH_OBJECTS = 30


def write_meshes(
    room: Room, catalog: Catalog, folder: Path, max_triangles: int | None = None
) -> list[str]:
    """Mesh files and a user catalog turning the classes of ``MESH_OBJECTS`` of ``room``'s
    objects into mesh classes; returns those classes."""
    import trimesh

    counts: dict[str, int] = {}
    for obj in room.objects:
        if obj.attached_to is None:
            counts[obj.class_name] = counts.get(obj.class_name, 0) + 1
    chosen, total = [], 0
    for name, n in sorted(counts.items(), key=lambda kv: (-kv[1], kv[0])):
        if total + n <= MESH_OBJECTS:
            chosen.append(name)
            total += n
    entries = []
    for k, name in enumerate(chosen):
        spec = catalog[name]
        size = (np.array(spec.size_min) + np.array(spec.size_max)) / 2
        if k % 2 == 0:
            mesh = trimesh.creation.icosphere(subdivisions=5, radius=0.5)  # 20,480 triangles
        else:
            mesh = trimesh.creation.capsule(height=1.0, radius=0.5, count=[101, 101])
        mesh.apply_scale(size / mesh.extents)
        mesh.apply_translation(-mesh.bounds[0] * [0, 0, 1])
        mesh.visual.vertex_colors = [60 + 7 * k, 120, 200 - 5 * k, 255]
        (folder / f"{name}.ply").write_bytes(mesh.export(file_type="ply"))
        entry = f'[classes.{name}]\nmesh = "{name}.ply"\nunits = "m"\nup = "z"\n'
        if max_triangles is not None:
            entry += f"max_triangles = {max_triangles}\n"
        entries.append(entry)
    (folder / "catalog.toml").write_text("\n".join(entries), encoding="utf-8")
    return chosen


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--views", type=int, default=40, help="views per measurement")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--rounds", type=int, default=3, help="ABAB rounds (median reported)")
    ap.add_argument(
        "--max-triangles",
        type=int,
        default=None,
        help="the mesh classes' max_triangles (default: the catalog's; 0: every triangle)",
    )
    ap.add_argument("--json", action="store_true", help="print one JSON line of the figures")
    args = ap.parse_args()

    shipped = load_catalog()
    room = generate_room("kitchen", 0, args.seed, shipped)
    tmp = Path(tempfile.mkdtemp(prefix="sgdata-bench-assets-"))
    atexit.register(shutil.rmtree, tmp, ignore_errors=True)  # read until the bench ends
    chosen = write_meshes(room, shipped, tmp, args.max_triangles)
    meshes = load_catalog(extra=[tmp / "catalog.toml"])
    start = time.perf_counter()
    for name in chosen:
        class_assets(meshes[name])
    first_read = time.perf_counter() - start
    start = time.perf_counter()
    for name in chosen:
        class_assets(meshes[name])
    cached_read = time.perf_counter() - start

    scenes = {}
    for label, catalog in (("procedural", shipped), ("meshes", meshes)):
        path = tmp / label / room.room_id / "room.usda"
        start = time.perf_counter()
        write_room(room, path, geometry=catalog_geometry(catalog), appearance=AppearanceConfig())
        written = time.perf_counter() - start
        scenes[label] = (read_geometry(path), written, path.stat().st_size)

    slots = SlotTable.from_counts(
        [(c, 8) for c in shipped.names()], num_slots=max(256, 8 * len(shipped.names()))
    )
    renderer = Renderer()
    annotator = ViewAnnotator(renderer, slots)
    poses = sample_poses(room, args.views, np.random.default_rng(args.seed))
    kinds = ("rgb+ids", "view", "rgb+ids_cpu", "view_cpu")
    fps: dict[str, dict[str, list[float]]] = {k: {kind: [] for kind in kinds} for k in scenes}
    for label in ("procedural", "meshes") * args.rounds:  # ABAB...: load hits both alike
        annotator.set_layout(room, scenes[label][0], 0)
        for key, fn in (
            ("rgb+ids", lambda p: renderer.render(p.x, p.y, p.theta)),
            ("view", lambda p: annotator.view(p)),
        ):
            cpu = time.process_time()
            fps[label][key].append(views_per_second(fn, poses))
            fps[label][f"{key}_cpu"].append(len(poses) / (time.process_time() - cpu))
    renderer.close()

    out: dict[str, object] = {
        "mesh_objects": sum(1 for o in room.objects if o.class_name in chosen),
        "mesh_classes": len(chosen),
        "views": len(poses),
        "LP_NUM_THREADS": os.environ.get("LP_NUM_THREADS", "(all cores)"),
        "load_average": os.getloadavg()[0],
        "max_triangles": meshes[chosen[0]].mesh.max_triangles,  # type: ignore[union-attr]
        "first_read_s": round(first_read, 3),
        "cached_read_ms": round(cached_read * 1000, 3),
    }
    shutil.rmtree(tmp, ignore_errors=True)
    for label, (geometry, written, size) in scenes.items():
        out[f"{label}_triangles"] = sum(len(o.mesh.faces) for o in geometry.objects)
        out[f"{label}_usd_write_s"] = round(written, 2)
        out[f"{label}_usd_mb"] = round(size / 1e6, 1)
        for key, runs in fps[label].items():
            out[f"{label}_{key}_per_s"] = round(float(np.median(runs)), 2)
    for key in kinds:
        out[f"ratio_{key}"] = round(
            float(out[f"meshes_{key}_per_s"]) / float(out[f"procedural_{key}_per_s"]), 3
        )
    if args.json:
        print(json.dumps(out))
    else:
        for key, value in out.items():
            print(f"{key:>28}: {value}")


if __name__ == "__main__":
    main()
