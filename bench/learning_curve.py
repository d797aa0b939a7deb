"""A learning curve: triplet accuracy on val and test against the training budget.

    python bench/learning_curve.py run DATA RUNS [--budgets 300:3,1200:3,4800:1]
        [--doc docs/learning-curve.md]
    python bench/learning_curve.py tables RUNS [-o docs/learning-curve.md]

Whether the results' aims are a matter of compute: SeanNet (``seannet-fc512``, the ``cpu``
preset's network), ``resnet18+boxes`` and ``seannet-fc512+box-kernel`` trained at growing
budgets (seconds of one thread's compute per run, :mod:`seannet.training.budget`: 300 bought
seannet-fc512 7 batches per epoch on the machine of 2026-12-02 and 19 on that of 2026-12-03;
the page's tables say what each network got). The protocol (DESIGN §12):

- the first budget is a ``seannet compare``: each network calibrated to it, the lr chosen on
  val among {0.003, 0.01} with the first seed, then its seeds;
- every larger budget trains each network ``budget / first`` times the first budget's
  batches per epoch (the same rule, no second timing: a timing taken on a busier machine would
  bend the curve), at the lr chosen on val at the first budget;
- ``+box-kernel`` and ``+boxes`` evaluate the same network's runs (trained once per lr and
  seed; each picks its lr on val with its scene term, lambda on val);
- every run is evaluated on val and on test; nothing is chosen on test.

Each budget's runs live under ``RUNS/b<budget>/`` (a run directory does not name its budget,
so budgets never share one); every call appends its provenance to ``RUNS/provenance.jsonl``.
``tables`` writes the page and its plot from the run files alone. Runs resume.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from PIL import Image, ImageDraw, ImageFont  # noqa: E402

from seannet.data.opening import open_dataset  # noqa: E402
from seannet.evaluation.compare import compare_models  # noqa: E402
from seannet.evaluation.intervals import t_interval  # noqa: E402
from seannet.evaluation.run_eval import evaluate_run  # noqa: E402
from seannet.model.specs import scene_term  # noqa: E402
from seannet.provenance import append_provenance, read_provenance, stamp  # noqa: E402
from seannet.training.config import TrainConfig  # noqa: E402
from sgdata.fileio import atomic_write_text, save_png  # noqa: E402

MODELS = ("seannet-fc512", "resnet18+boxes", "seannet-fc512+box-kernel")
LRS = (0.003, 0.01)
# the design: 3 seeds at the two smaller budgets, 1 at the largest
BUDGETS = ((300.0, 3), (1200.0, 3), (4800.0, 1))
STEP = "curve"
CURVE = "curve.json"  # per budget directory: val and test accuracy of every run


def parse_budgets(text: str) -> list[tuple[float, int]]:
    """``"300:3,1200:1"`` as [(300.0, 3), (1200.0, 1)], smallest first."""
    try:
        pairs = [(float(b), int(s)) for b, s in (item.split(":") for item in text.split(","))]
    except ValueError:
        raise SystemExit(
            f"--budgets {text!r}: expected BUDGET:SEEDS,... e.g. 300:3,1200:1"
        ) from None
    if not pairs or any(b <= 0 or s < 1 for b, s in pairs):
        raise SystemExit(f"--budgets {text!r}: budgets > 0 and seeds >= 1")
    return sorted(pairs)


def budget_dir(runs: Path, budget: float) -> Path:
    return runs / f"b{budget:g}"


def run(
    data: Path,
    runs: Path,
    budgets: list[tuple[float, int]],
    models: tuple[str, ...] = MODELS,
    *,
    preset: str | TrainConfig = "cpu",
    lrs: tuple[float, ...] = LRS,
    progress: Callable[[], None] = lambda: None,
) -> None:
    """Train and evaluate every budget of the curve into ``runs`` (resuming). Each model is
    its own comparison (``selection-curve-<model>.json``), so a later call may carry some
    models further: a network keeps the batches its first calibration gave it (compare keeps
    it in the budget's ``calibrations.json``). ``progress`` is called after each budget's
    evaluation."""
    runs.mkdir(parents=True, exist_ok=True)
    append_provenance(runs, data, step=STEP)
    ds = open_dataset(data)
    (first, first_seeds), *rest = budgets
    base = budget_dir(runs, first)
    chosen: dict[str, dict[str, Any]] = {}
    for name in models:
        got = compare_models(
            ds, base, (name,), preset=preset, seeds=tuple(range(first_seeds)), lrs=lrs,
            budget_s=first, announce=print, tag=_tag(name),
        )  # fmt: skip
        chosen[name] = got["models"][0]
    _evaluate(ds, base, list(chosen.values()))
    progress()
    for budget, seeds in rest:
        # the first budget's calibration, scaled: no second timing
        batches = {
            e["trained"]: max(1, round(e["batches_per_epoch"] * budget / first))
            for e in chosen.values()
        }
        directory = budget_dir(runs, budget)
        entries = []
        for name in models:
            got = compare_models(
                ds, directory, (name,), preset=preset, seeds=tuple(range(seeds)),
                lrs=(chosen[name]["lr"],), budget_s=None, announce=print, tag=_tag(name),
                batches=batches,
            )  # fmt: skip
            entries += got["models"]
        _evaluate(ds, directory, entries)
        progress()


def _tag(name: str) -> str:
    return f"{STEP}-{name.replace('+', '-')}"


def _evaluate(ds: Any, directory: Path, entries: list[dict[str, Any]]) -> None:
    """Val and test accuracy of every run of ``entries`` into ``directory/curve.json``,
    beside the rows of models evaluated there before."""
    path = directory / CURVE
    done = {e["model"] for e in entries}
    rows = [r for r in json.loads(path.read_text())["runs"] if r["model"] not in done] if (
        path.is_file()
    ) else []  # fmt: skip
    for entry in entries:
        boxes = scene_term(entry["model"])
        for got in entry["runs"]:
            run_dir = Path(got["run"])
            val = evaluate_run(run_dir, ds, split="val", boxes=boxes)
            rows.append({
                "model": entry["model"], "run": str(run_dir), "lr": entry["lr"],
                "batches_per_epoch": entry["batches_per_epoch"], "epochs": entry["epochs"],
                "examples": entry["examples"], "lrs_tried": list(entry["val_accuracy_by_lr"]),
                "val": val["accuracy"],
                "test": got["accuracy"],  # the comparison's test evaluation of this run
            })  # fmt: skip
    atomic_write_text(path, json.dumps({"runs": rows}, indent=2))


def read_curve(runs: Path) -> dict[str, list[dict[str, Any]]]:
    """Per model, one point per budget found under ``runs``: seeds, val and test intervals,
    what the budget bought; budgets ascending."""
    points: dict[str, list[dict[str, Any]]] = {}
    found = sorted(
        (float(d.name[1:]), d) for d in runs.glob("b*") if (d / CURVE).is_file()
    )  # fmt: skip
    for budget, directory in found:
        rows = json.loads((directory / CURVE).read_text())["runs"]
        for model in dict.fromkeys(r["model"] for r in rows):
            mine = [r for r in rows if r["model"] == model]
            points.setdefault(model, []).append({
                "budget_s": budget, "seeds": len(mine), "lr": mine[0]["lr"],
                "lrs_tried": mine[0].get("lrs_tried", []),
                "batches_per_epoch": mine[0]["batches_per_epoch"], "epochs": mine[0]["epochs"],
                "examples": mine[0]["examples"],
                "val": t_interval([r["val"] for r in mine]),
                "test": t_interval([r["test"] for r in mine]),
            })  # fmt: skip
    # the design's order, whichever call evaluated a model last
    order = {m: k for k, m in enumerate(MODELS)}
    return dict(sorted(points.items(), key=lambda item: order.get(item[0], len(order))))


def _cell(interval: dict[str, float]) -> str:
    if interval["n"] < 2:
        return f"{100 * interval['mean']:.1f} (1 seed)"
    return f"{100 * interval['mean']:.1f} ± {100 * interval['ci95']:.1f}"


def _lr(point: dict[str, Any], k: int) -> str:
    """The lr, and at the first budget how it was set: chosen on val, or the only one tried."""
    if k > 0:
        return f"{point['lr']:g}"
    tried = point["lrs_tried"]
    if len(tried) > 1:
        return f"{point['lr']:g} (val, of {' / '.join(tried)})"
    return f"{point['lr']:g} (the only one tried)"


def _flattens(points: list[dict[str, Any]]) -> str:
    """Where val accuracy stops gaining a point per budget step (read on val, not test), with
    each step's val gain in points."""
    if len(points) < 2:
        return "one budget only"
    pairs = list(zip(points, points[1:], strict=False))
    gains = [100 * (after["val"]["mean"] - before["val"]["mean"]) for before, after in pairs]
    steps = "; ".join(
        f"{before['budget_s']:g} to {after['budget_s']:g} s: {gain:+.1f}"
        for (before, after), gain in zip(pairs, gains, strict=True)
    )
    for (before, _), gain in zip(pairs, gains, strict=True):
        if gain < 1.0:
            return f"flat from {before['budget_s']:g} s (val gains, points: {steps})"
    return f"still rising at {points[-1]['budget_s']:g} s (val gains, points: {steps})"


def tables(runs: Path, plot: Path) -> str:
    """The page: a table per model, where each flattens, the plot and the stamp."""
    points = read_curve(runs)
    if not points:
        raise SystemExit(f"{runs}: no {CURVE} under b<budget>/: run the curve first")
    records = read_provenance(runs, STEP)
    lines = [
        "# Learning curve: accuracy against the training budget",
        "",
        "Written by `python bench/learning_curve.py tables RUNS` from the run files; no figure "
        "is typed. Budgets are seconds of one thread's compute per run "
        "(`seannet/training/budget.py`); the first budget's calibration sets each network's "
        "batches, larger budgets scale them and keep the first budget's lr (chosen on val "
        "when several were tried: the lr column says). Intervals: 95 % t over seeds (a "
        "budget with one seed shows its single run).",
        "",
        *([stamp(records), ""] if records else []),
        f"![accuracy against budget]({plot.name})",
        "",
    ]
    for model, series in points.items():
        lines += [
            f"## {model}",
            "",
            f"{_flattens(series)}.",
            "",
            "| budget (s) | seeds | batches x epochs | triplets | lr | val % | test % |",
            "|---|---|---|---|---|---|---|",
        ]
        lines += [
            f"| {p['budget_s']:g} | {p['seeds']} | {p['batches_per_epoch']} x {p['epochs']} | "
            f"{p['examples']:,} | {_lr(p, k)} | {_cell(p['val'])} | {_cell(p['test'])} |"
            for k, p in enumerate(series)
        ]
        lines.append("")
    missing = _missing(points)
    if missing:
        lines += [
            "## Not run for this page",
            "",
            "The default design (`bench/learning_curve.py run DATA RUNS`) and what these runs "
            "lack of it:",
            "",
            *[f"- {m}" for m in missing],
            "",
        ]
    save_png(draw_curve(points), plot)
    return "\n".join(lines)


def _missing(points: dict[str, list[dict[str, Any]]]) -> list[str]:
    """Each (model, budget) of the default design with fewer seeds here than it asks."""
    out = []
    for model in MODELS:
        have = {p["budget_s"]: p["seeds"] for p in points.get(model, [])}
        for budget, seeds in BUDGETS:
            got = have.get(budget, 0)
            if got < seeds:
                asked = "1 seed" if seeds == 1 else f"{seeds} seeds"
                out.append(f"{model} at {budget:g} s: {asked} asked, {got} run")
    return out


COLOURS = ((70, 110, 200), (200, 90, 60), (60, 160, 90), (140, 90, 170))


def draw_curve(points: dict[str, list[dict[str, Any]]]) -> Image.Image:
    """Test (solid) and val (thin) accuracy against budget on a log axis, one colour a model;
    a seed's spread as a vertical bar."""
    font = ImageFont.load_default(size=12)
    width, height, left, top = 560, 320, 50, 30
    image = Image.new("RGB", (left + width + 220, top + height + 50), "white")
    draw = ImageDraw.Draw(image)
    budgets = sorted({p["budget_s"] for series in points.values() for p in series})
    values = [p[s]["mean"] for series in points.values() for p in series for s in ("val", "test")]
    low = math.floor(20 * min(values) - 1) / 20
    high = math.ceil(20 * max(values) + 1) / 20
    span = math.log(budgets[-1] / budgets[0]) or 1.0

    def x(b: float) -> float:
        return (
            left
            + 20
            + (width - 40) * (math.log(b / budgets[0]) / span if len(budgets) > 1 else 0.5)
        )

    def y(v: float) -> float:
        return top + height * (high - v) / (high - low)

    draw.rectangle([left, top, left + width, top + height], outline="black")
    for k in range(round((high - low) * 20) + 1):
        v = low + k / 20
        draw.line([left, y(v), left + width, y(v)], fill=(225, 225, 225))
        draw.text((6, y(v) - 7), f"{100 * v:.0f} %", fill="black", font=font)
    for b in budgets:
        draw.text((x(b) - 14, top + height + 6), f"{b:g} s", fill="black", font=font)
    draw.text(
        (left, 8), "triplet accuracy (test solid, val thin) against budget", fill="black", font=font
    )
    for k, (model, series) in enumerate(points.items()):
        colour = COLOURS[k % len(COLOURS)]
        for split, line_width in (("test", 3), ("val", 1)):
            xy = [(x(p["budget_s"]), y(p[split]["mean"])) for p in series]
            if len(xy) > 1:
                draw.line(xy, fill=colour, width=line_width)
            for p, (px, py) in zip(series, xy, strict=True):
                draw.ellipse([px - 3, py - 3, px + 3, py + 3], fill=colour)
                half = p[split]["ci95"]
                if split == "test" and not math.isnan(half):
                    draw.line(
                        [px, y(p[split]["mean"] - half), px, y(p[split]["mean"] + half)],
                        fill=colour,
                    )
        draw.text((left + width + 14, top + 10 + 20 * k), model, fill=colour, font=font)
    return image


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="verb", required=True)
    go = sub.add_parser("run", help="train and evaluate the curve's runs")
    go.add_argument("data", type=Path)
    go.add_argument("runs", type=Path)
    go.add_argument("--budgets", default=",".join(f"{b:g}:{s}" for b, s in BUDGETS))
    go.add_argument("--models", default=",".join(MODELS))
    go.add_argument(
        "--lrs",
        default=",".join(f"{lr:g}" for lr in LRS),
        help="learning rates chosen from on val at the first budget (one: no choice)",
    )
    go.add_argument(
        "--doc",
        type=Path,
        help="write the page there (docs/learning-curve.md) after each budget's evaluation",
    )
    write = sub.add_parser("tables", help="write the page and its plot from the runs")
    write.add_argument("runs", type=Path)
    write.add_argument("-o", "--output", type=Path, default=ROOT / "docs" / "learning-curve.md")
    args = parser.parse_args()
    if args.verb == "run":
        models = tuple(m.strip() for m in args.models.split(",") if m.strip())
        lrs = tuple(float(lr) for lr in args.lrs.split(","))
        budgets = parse_budgets(args.budgets)
        # the runs are gitignored and die with the machine: each budget's figures reach a
        # tracked file as soon as they are measured
        progress = lambda: None  # noqa: E731
        if args.doc:  # its folder now, not after the first budget's runs
            args.doc.parent.mkdir(parents=True, exist_ok=True)
            progress = lambda: write_page(args.runs, args.doc)  # noqa: E731
        run(args.data, args.runs, budgets, models, lrs=lrs, progress=progress)
    else:
        write_page(args.runs, args.output)


def write_page(runs: Path, output: Path) -> None:
    """The page and its plot (beside it, ``.png``) from ``runs``, written atomically."""
    text = tables(runs, output.with_suffix(".png"))
    atomic_write_text(output, text)
    print(f"wrote {output} and {output.with_suffix('.png').name}")


if __name__ == "__main__":
    main()
