"""End-to-end `sgdata generate` throughput and memory.

    .venv/bin/python bench/generate.py                 # 1 vs 2 workers, 2 / 4 / 8 rooms
    .venv/bin/python bench/generate.py --rooms 2 4 8 16
    .venv/bin/python bench/generate.py --preset medium --workers 8 16   # a preset, whole
    .venv/bin/python bench/generate.py --one 24 2 --profile   # one run, where its time went

For each room count it runs a fresh process that generates a dataset of that many rooms
(kitchens and bathrooms, 3 layouts, 24 triplets per room, 224 x 224) and prints views/s of
the whole run and of the render phase, and the peak resident memory of the main process and
of the largest worker (of any phase; and of the rendering workers once 3 rooms were rendered
and at the end). Peak worker memory must stay flat as rooms grow: each worker renders one
room at a time and writes its shard before taking the next.

With ``--profile`` the run is ``sgdata generate --profile``'s: its JSON line also holds the
stage table (:func:`sgdata.pipeline.room_tasks.stage_order`: the command's wall time by step,
then each task phase's worker time by stage, with the time outside the tasks) and
``pipeline_share``: the workers' time (wall x workers) spent in the views' own pipeline, what
``bench/render.py`` times, on the same views. Profiling
times every stage, so its views/s are not the plain run's.
"""

from __future__ import annotations

import argparse
import json
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from sgdata.markdown import table

CONFIG = """
[dataset]
name = "bench"
seed = 1
[rooms]
types = ["kitchen", "bathroom"]
train = {per_type}
val = 0
test = 0
[layouts]
count = 3
[triplets]
train = {triplets}
val = 0
test = 0
"""


def run_one(
    rooms: int,
    workers: int,
    executor: str = "local",
    preset: str | None = None,
    profile: bool = False,
) -> dict:
    """Generate in this process (``preset`` whole, or ``rooms`` rooms of the bench config);
    report counts, times and peak memory (MiB), and with ``profile`` the stage table."""
    from sgdata.pipeline.config import load_config
    from sgdata.pipeline.generate import generate_dataset
    from sgdata.pipeline.room_tasks import stage_order
    from sgdata.stage_clock import StageClock

    with tempfile.TemporaryDirectory() as tmp:
        config_path = Path(tmp) / "bench.toml"
        config_path.write_text(CONFIG.format(per_type=rooms // 2, triplets=24 * rooms))
        config = load_config(preset or config_path)
        phases: dict[str, float] = {}
        peaks: list[float] = []  # the views phase's worker peaks, room by room
        last: dict[int, object] = {}  # each worker's last report of the views phase

        def progress(step) -> None:  # noqa: ANN001
            phases[step.phase] = step.elapsed
            phases[f"{step.phase}_views"] = step.views
            if step.phase == "views":
                peaks.append(step.worker_peak_mib)
                last[step.worker_pid] = step

        clock = StageClock() if profile else None
        start = time.perf_counter()
        manifest = generate_dataset(
            config,
            Path(tmp) / "data",
            workers=workers,
            executor=executor,
            progress=progress,
            clock=clock,
        )
        wall = time.perf_counter() - start
    views = sum(manifest["counts"]["observations"].values())
    stages = {}
    if clock is not None:
        from sgdata.annotate.annotator import VIEW_STEPS

        # what bench/render.py times of a view (the annotator's steps and the rest of its
        # record), here on the very views generated: its share of the workers' time says how
        # near the command runs to its renderer's speed, with no other rooms in the ratio
        pipeline = sum(clock.seconds[("views", s)] for s in (*VIEW_STEPS, "view record"))
        stages = {
            "profile": clock.rows(stage_order()),
            "pipeline_share": round(pipeline / (wall * workers), 4),
        }
    return {
        "rooms": sum(len(r) for r in manifest["splits"].values()),
        "workers": workers,
        "executor": executor,
        "views": views,
        "wall_s": round(wall, 2),
        "views_per_s": round(views / wall, 2),
        "render_views_per_s": round(views / phases["views"], 2),
        "main_peak_mib": round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, 1),
        "worker_peak_mib": round(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024, 1),
        # the largest worker's peak once 3 rooms were rendered, and once all were: flat if equal
        "worker_peak_after_3_mib": round(max(peaks[:3]), 1),
        "worker_peak_after_all_mib": round(max(peaks), 1),
        # contention (issue 55): each worker's threads by origin at its end, and the context
        # switches of all workers (both phases, start-up included) per view
        "worker_threads_by_origin": [step.worker_threads_by_origin for step in last.values()],
        "context_switches_per_view": [
            round(sum(step.worker_context_switches[k] for step in last.values()) / views, 1)
            for k in (0, 1)
        ],
    } | stages


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rooms", type=int, nargs="+", default=[2, 4, 8])
    parser.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    parser.add_argument("--executor", default="local", choices=["local", "ray"])
    parser.add_argument("--preset", help="generate this preset whole (--rooms is then ignored)")
    parser.add_argument("--one", nargs=2, type=int, help="ROOMS WORKERS: one run, one JSON line")
    parser.add_argument("--profile", action="store_true", help="with --one: the stage table")
    args = parser.parse_args()
    if args.one:
        one = run_one(*args.one, executor=args.executor, preset=args.preset, profile=args.profile)
        print(json.dumps(one))
        return
    rows = []
    for rooms in [0] if args.preset else args.rooms:
        for workers in args.workers:
            # a fresh process per measurement, so peak memory is that run's alone
            out = subprocess.run(
                [
                    sys.executable,
                    __file__,
                    "--one",
                    str(rooms),
                    str(workers),
                    "--executor",
                    args.executor,
                    *(["--preset", args.preset] if args.preset else []),
                ],
                capture_output=True,
                text=True,
                check=True,
            )
            rows.append(json.loads(out.stdout.strip().splitlines()[-1]))
            print(rows[-1], flush=True)
    print()
    header = ("rooms", "workers", "views", "wall (s)", "views/s", "render views/s",
              "main peak (MiB)", "worker peak (MiB)", "switches / view (vol, invol)")  # fmt: skip
    keys = ("rooms", "workers", "views", "wall_s", "views_per_s", "render_views_per_s",
            "main_peak_mib", "worker_peak_mib", "context_switches_per_view")  # fmt: skip
    print("\n".join(table(header, ([r[k] for k in keys] for r in rows))))
    for r in rows:
        origins = "; ".join(
            ", ".join(f"{n} {c}" for n, c in worker.items())
            for worker in r["worker_threads_by_origin"]
        )
        print(
            f"{r['rooms']} rooms, {r['workers']} worker(s): threads by origin per worker: {origins}"
        )
    for rooms in sorted({r["rooms"] for r in rows}):
        by_workers = {r["workers"]: r for r in rows if r["rooms"] == rooms}
        if 1 in by_workers and 2 in by_workers:
            ratio = by_workers[2]["views_per_s"] / by_workers[1]["views_per_s"]
            print(f"{rooms} rooms: 2 workers / 1 worker = {ratio:.2f}x views/s")


if __name__ == "__main__":
    main()
