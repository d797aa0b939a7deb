"""Every benchmark of the pipeline in one run, as one table (docs/benchmarks.md).

    .venv/bin/python bench/suite.py                      # ~10 min on 2 cores
    .venv/bin/python bench/suite.py --rooms 24 --views 30 --validate out/medium

Rows, each measured in a fresh process on this machine, one after the other:

- render: annotated views/s of the pipeline (merged RGB mesh + id pass + boxes, slots,
  relations) against plain pyrender (one node per object, an RGB and a SEG pass) on the same
  views of 4 generated rooms, both on one llvmpipe thread (``LP_NUM_THREADS=1``);
- generate: ``sgdata generate`` end to end on ``--rooms`` rooms with 1 and 2 local workers
  and with Ray (a local instance, 2 workers);
- loader: ``bench/loader.py`` on the ``tiny`` preset (its own table follows);
- validate: ``sgdata validate`` on a dataset (``--validate``, default the tiny one).

The ratios the project holds itself to: pipeline >= 2x plain pyrender on textured views (issue
25; >= 1.3x flat before); textured pipeline >= 0.8x the flat one; 2 workers >= 1.8x one; Ray
local within 0.8x of the local pool.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

BENCH = Path(__file__).resolve().parent
PY = sys.executable


def _json_line(command: list[str], env: dict | None = None) -> dict:
    out = subprocess.run(command, capture_output=True, text=True, env=env, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rooms", type=int, default=24, help="rooms of the generate runs")
    parser.add_argument("--views", type=int, default=30, help="views per room of the render run")
    parser.add_argument("--validate", type=Path, help="dataset to validate (default: tiny)")
    args = parser.parse_args()
    rows: list[tuple[str, str, str]] = []

    env = {**os.environ, "LP_NUM_THREADS": "1"}
    render = _json_line(
        [PY, str(BENCH / "render.py"), "--rooms", "4", "--views", str(args.views), "--json"], env
    )
    rows += [
        ("render, 1 thread", "pipeline (annotated views/s)", f"{render['pipeline']:.1f}"),
        ("render, 1 thread", "plain pyrender RGB + SEG (views/s)", f"{render['naive']:.1f}"),
        ("render, 1 thread", "pipeline / plain pyrender", f"{render['pipeline/naive']:.2f}x"),
        (
            "render, 1 thread",
            "pipeline with textures (annotated views/s)",
            f"{render['pipeline_textured']:.1f}",
        ),
        (
            "render, 1 thread",
            "plain pyrender with textures (views/s)",
            f"{render['naive_textured']:.1f}",
        ),
        (
            "render, 1 thread",
            "textured: pipeline / plain pyrender",
            f"{render['textured: pipeline/naive']:.2f}x",
        ),
        ("render, 1 thread", "pipeline textured / flat", f"{render['textured/flat']:.2f}x"),
    ]

    runs = {}
    for workers, executor in ((1, "local"), (2, "local"), (2, "ray")):
        command = [PY, str(BENCH / "generate.py"), "--one", str(args.rooms), str(workers)]
        runs[(workers, executor)] = run = _json_line([*command, "--executor", executor])
        rows.append(
            (
                f"generate {args.rooms} rooms",
                f"{executor}, {workers} worker(s): {run['views']} views in {run['wall_s']} s",
                f"{run['views_per_s']:.2f} views/s",
            )
        )
    one, two, ray = runs[(1, "local")], runs[(2, "local")], runs[(2, "ray")]
    rows.append(("generate", "2 workers / 1", f"{two['views_per_s'] / one['views_per_s']:.2f}x"))
    rows.append(
        ("generate", "Ray local / local pool", f"{ray['views_per_s'] / two['views_per_s']:.2f}x")
    )

    with tempfile.TemporaryDirectory() as tmp:
        tiny = Path(tmp) / "tiny"
        subprocess.run(
            [PY, "-m", "sgdata_cli.sgdata_app", "generate", "tiny", str(tiny)],
            check=True,
            capture_output=True,
        )
        loader = subprocess.run(
            [PY, str(BENCH / "loader.py"), "--data", str(tiny)],
            capture_output=True,
            text=True,
            check=True,
        ).stdout
        target = args.validate or tiny
        start = time.perf_counter()
        subprocess.run(
            [PY, "-m", "sgdata_cli.sgdata_app", "validate", str(target)],
            check=True,
            capture_output=True,
        )
        rows.append(("validate", f"{target.name}", f"{time.perf_counter() - start:.1f} s"))

    commit = subprocess.run(
        ["git", "-C", str(BENCH), "describe", "--always", "--dirty"], capture_output=True, text=True
    ).stdout.strip()
    print(f"commit {commit or 'unknown'}, {time.strftime('%Y-%m-%d')}, {os.cpu_count()} CPUs\n")
    print("| benchmark | measurement | figure |")
    print("|---|---|---|")
    for row in rows:
        print("| " + " | ".join(row) + " |")
    print("\nloader (bench/loader.py on tiny):\n")
    print(loader)


if __name__ == "__main__":
    main()
