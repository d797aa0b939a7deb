"""docs/results.md as code: run the measurements of the protocol, then write the tables.

    python bench/results.py run DATA RUNS [--steps headline,noise,ablations] [--budget 150]
    python bench/results.py tables DATA RUNS [-o docs/results.md]

``run`` records what made the runs (commit, command, dataset manifest sha256 and format
version) in ``RUNS/provenance-<step>.json`` and runs each step:

- ``headline``: ``seannet compare`` of SeanNet, ``resnet18+boxes`` and ResNet-18, 3 seeds,
  lr from {0.003, 0.01} on val, 150 s per run (the protocol: selection.json before test);
- ``noise``: the headline models' chosen runs evaluated on test under labeler / detector box
  noise (every choice, epsilon and lambda, re-read on val under the same noise);
- ``ablations``: SeanNet's image branch alone, the paper's graph branch (no layout pathway)
  and graph-only, under the same selection, sharing SeanNet's runs.

``tables`` writes every table of docs/results.md from those files and nothing else: no figure
in it is typed by hand. Steps resume: a finished run is not trained again.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import seannet  # noqa: E402,F401  (imports torch's compiler stack first: see tests/conftest.py)
from seannet.data.box_noise import BoxNoise  # noqa: E402
from seannet.evaluation.compare import compare_models  # noqa: E402
from seannet.evaluation.eval import eval_file, evaluate_run  # noqa: E402
from sgdata.dataset.rows import sha256_file  # noqa: E402
from sgdata.fileio import atomic_write_text  # noqa: E402

SEEDS = (0, 1, 2)
LRS = (0.003, 0.01)
HEADLINE = ("seannet", "resnet18+boxes", "resnet18")
ABLATIONS = ("seannet", "seannet-image", "seannet-nolayout", "seannet-graph")
# the grid: S in {0, 0.02, 0.05, 0.1} at P = 0, P in {0.1, 0.25} at S = 0, and the
# aim's point S = 0.05, P = 0.1 (all seeds there; seed 0 elsewhere)
NOISE_GRID = ((0.02, 0.0), (0.05, 0.0), (0.1, 0.0), (0.0, 0.1), (0.0, 0.25), (0.05, 0.1))
AIM = (0.05, 0.1)
NOISE_MODELS = ("seannet", "resnet18+boxes")


def provenance(data: Path, command: list[str]) -> dict[str, Any]:
    """What made a set of runs: the code's commit, the command, the data's fingerprint."""
    commit = subprocess.run(
        ["git", "rev-parse", "HEAD"], capture_output=True, text=True, cwd=ROOT, check=False
    ).stdout.strip()
    dirty = subprocess.run(
        ["git", "status", "--porcelain", "--untracked-files=no"],
        capture_output=True,
        text=True,
        cwd=ROOT,
        check=False,
    ).stdout.strip()
    manifest = json.loads((data / "dataset.json").read_text())
    return {
        "commit": commit,
        "dirty": bool(dirty),
        "command": " ".join(command),
        "started": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
        "data": str(data),
        "manifest_sha256": sha256_file(data / "dataset.json")[0],
        "format_version": manifest["format_version"],
        "dataset_seed": manifest["config"]["dataset"]["seed"],
    }


def run(args: argparse.Namespace) -> None:
    runs: Path = args.runs
    runs.mkdir(parents=True, exist_ok=True)
    for step in args.steps.split(","):
        record = provenance(args.data, sys.argv)
        atomic_write_text(runs / f"provenance-{step}.json", json.dumps(record, indent=2))
        if step in ("headline", "ablations"):
            models = HEADLINE if step == "headline" else ABLATIONS
            compare_models(
                args.data,
                runs,
                models,
                preset="cpu",
                seeds=SEEDS,
                lrs=LRS,
                budget_s=args.budget,
                announce=print,
                tag=step,
            )
        elif step == "noise":
            noise_step(args.data, runs)
        else:
            raise SystemExit(f"unknown step {step!r}: headline, noise or ablations")


def noise_step(data: Path, runs: Path) -> None:
    selection = json.loads((runs / "selection-headline.json").read_text())
    chosen = {m["model"]: m["runs"] for m in selection["models"]}
    for model in NOISE_MODELS:
        boxes = model.endswith("+boxes")
        for jitter, drop in NOISE_GRID:
            noise = BoxNoise(jitter=jitter, drop=drop)
            seeds = chosen[model] if (jitter, drop) == AIM else chosen[model][:1]
            for run_dir in map(Path, seeds):
                if eval_file(run_dir, "test", boxes=boxes, noise=noise).exists():
                    continue
                print(f"{model}: {noise.label()} on {run_dir}", flush=True)
                evaluate_run(run_dir, data, split="test", boxes=boxes, noise=noise)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="verb", required=True)
    go = sub.add_parser("run", help="make the runs")
    go.add_argument("data", type=Path)
    go.add_argument("runs", type=Path)
    go.add_argument("--steps", default="headline,noise,ablations")
    go.add_argument("--budget", type=float, default=150.0)
    tables = sub.add_parser("tables", help="write docs/results.md from the runs")
    tables.add_argument("data", type=Path)
    tables.add_argument("runs", type=Path)
    tables.add_argument("-o", "--output", type=Path, default=ROOT / "docs" / "results.md")
    args = parser.parse_args()
    if args.verb == "run":
        run(args)
    else:
        from results_tables import write_tables  # noqa: PLC0415  (bench/results_tables.py)

        write_tables(args.data, args.runs, args.output)


if __name__ == "__main__":
    main()
