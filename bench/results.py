"""docs/results.md as code: run the measurements of the protocol, then write the tables.

    python bench/results.py run DATA RUNS [--steps headline,noise,ablations] [--budget 1200]
        [--doc docs/results.md]
    python bench/results.py tables DATA RUNS [-o docs/results.md]

``run`` appends what made the runs (commit at process start, command, dataset manifest sha256
and format version) to ``RUNS/provenance.jsonl`` (:mod:`seannet.provenance`), one record per
step and call, and runs each step:

- ``headline``: ``seannet compare`` of SeanNet (the ``cpu`` preset's network,
  ``seannet-fc512``), ``resnet18+boxes`` and ResNet-18, 3 seeds,
  lr from {0.003, 0.01} on val, ``--budget`` seconds of one thread's compute per run (300
  bought seannet-fc512 7 batches per epoch on the machine of 2026-12-02, 19 on that of
  2026-12-03, the old 150 had bought 35: docs/learning-curve.md says which budget val
  favours; the protocol: selection.json before test);
- ``noise``: the headline models' chosen runs evaluated on test under labeler / detector box
  noise (every choice, epsilon and lambda, re-read on val under the same noise);
- ``ablations``: the paper's SeanNet (``seannet``, GCN fc 4,096) against its image branch
  alone, its graph branch without the layout pathway and graph-only, under the same
  selection and the same budget rule: a network calibrated in an earlier step of ``RUNS``
  under the same budget and clock keeps its batches (``seannet``'s runs are then the fc
  step's), every other one is calibrated alike;
- ``boxes``: SeanNet plus the hand-made box overlap (lambda on val) against SeanNet: whether
  the overlap still adds what SeanNet's layout pathway should have learned; the lr is the
  headline SeanNet's (chosen on val there), so both rows are the headline's runs, evaluated
  again;
- ``kernel``: the box kernel learned on the train triplets (``+box-kernel``) on SeanNet and
  ResNet-18, against the hand-made overlap on each (evaluations only);
- ``fc``: SeanNet with a 512-wide GCN fc (``seannet-fc512``, the headline's runs) against
  the paper's 4,096 (``seannet``), under the same budget rule as ``ablations``: what the
  narrower fc, whose step is near ResNet-18's, costs or gains under the same budget;
- ``fullmap``: recall of the true pose among every sub-node of a test room's map at spacing 1
  (every reachable cell x 4 headings of layout 0, rendered live), queries from the other
  layouts, for the headline's SeanNet and ResNet-18 (seed 0's run: a map is rendered per run).

``tables`` writes every table of docs/results.md from those files and nothing else: no figure
in it is typed by hand. Each comparison's section says what every model's budget bought
(batches, triplets, the calibration: ``selection-<step>.json``) and which of its runs are
the headline's, computed from the run paths. Steps resume: a finished run is not trained
again. ``run --doc`` writes the tables after each step and each noise or full-map evaluation
once the headline exists: the runs live outside git and die with a machine, the doc does not.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from seannet.data.box_noise import BoxNoise  # noqa: E402
from seannet.data.datasets import open_dataset  # noqa: E402
from seannet.evaluation.compare import compare_models  # noqa: E402
from seannet.evaluation.compare import markdown as comparison_markdown  # noqa: E402
from seannet.evaluation.run_eval import eval_file, evaluate_run  # noqa: E402
from seannet.model.specs import scene_term  # noqa: E402
from seannet.navigation.localizer import load_localizer  # noqa: E402
from seannet.navigation.map_localization import run_localize  # noqa: E402
from seannet.navigation.maps import build_maps  # noqa: E402
from seannet.provenance import append_provenance, read_provenance, stamp  # noqa: E402
from seannet.training.config import TrainConfig, preset  # noqa: E402
from sgdata.fileio import atomic_write_text  # noqa: E402

SEEDS = (0, 1, 2)
LRS = (0.003, 0.01)
# SeanNet as the toolkit trains it on a CPU: the `cpu` preset's network (the paper's GCN fc
# 4,096 wide is `seannet`, measured against it in the fc step and ablated in its branches)
SEANNET = preset("cpu").model.name
HEADLINE = (SEANNET, "resnet18+boxes", "resnet18")
ABLATIONS = ("seannet", "seannet-image", "seannet-nolayout", "seannet-graph")
# does the hand-made overlap still add to SeanNet? (if so, its layout pathway has not learned
# what the boxes hold); the runs are the headline's: evaluations only
BOXES = (f"{SEANNET}+boxes", SEANNET)
# a learned scene term against the hand-made overlap, on both networks
KERNEL = (f"{SEANNET}+box-kernel", "resnet18+boxes", f"{SEANNET}+boxes", "resnet18+box-kernel")
# the paper's GCN fc (4,096 wide) against the cpu preset's 512 under the same budget rule
# (what each got: the fc section's budget table)
FC = (SEANNET, "seannet")
COMPARISONS = {
    "headline": HEADLINE,
    "ablations": ABLATIONS,
    "boxes": BOXES,
    "kernel": KERNEL,
    "fc": FC,
}
# the grid: S in {0, 0.02, 0.05, 0.1} at P = 0, P in {0.1, 0.25} at S = 0, and the
# aim's point S = 0.05, P = 0.1 (all seeds there; seed 0 elsewhere)
NOISE_GRID = ((0.02, 0.0), (0.05, 0.0), (0.1, 0.0), (0.0, 0.1), (0.0, 0.25), (0.05, 0.1))
AIM = (0.05, 0.1)
NOISE_MODELS = (SEANNET, "resnet18+boxes")
FULL_MAP_MODELS = (SEANNET, "resnet18")
FULL_MAP = "localize_test.json"  # what `seannet localize --split test` writes per run


def run(args: argparse.Namespace) -> None:
    runs: Path = args.runs
    runs.mkdir(parents=True, exist_ok=True)
    if args.doc:  # its folder now, not hours later when the headline is done
        args.doc.parent.mkdir(parents=True, exist_ok=True)

    def write_doc() -> None:
        # what is measured reaches the tree at once: a tracked file survives where a stopped
        # session loses its gitignored runs (a session's noise, kernel and full-map figures
        # were lost that way)
        if args.doc and (runs / "comparison-headline.json").exists():
            atomic_write_text(args.doc, tables(runs))

    for step in args.steps.split(","):
        append_provenance(runs, args.data, step=step)
        run_step(args.data, runs, step, budget_s=args.budget, progress=write_doc)
        write_doc()


def run_step(
    data: Path,
    runs: Path,
    step: str,
    *,
    budget_s: float | None,
    preset: str | TrainConfig = "cpu",
    seeds: Sequence[int] = SEEDS,
    lrs: Sequence[float] = LRS,
    models: Sequence[str] | None = None,
    progress: Callable[[], None] = lambda: None,
) -> None:
    """One step of ``run`` into ``runs`` (``models``: the comparison's, by default the step's
    own of :data:`COMPARISONS`; ``progress``: called after each evaluation of the noise and
    full-map steps). A network calibrated in an earlier step keeps its batches (compare
    reuses ``runs/calibrations.json``, kept for every step), and the ``boxes`` step trains at
    the headline SeanNet's lr, so its rows are the headline's runs."""
    if step in COMPARISONS:
        if step == "boxes":
            lrs = (_headline_lr(runs, SEANNET),)
        compare_models(
            data,
            runs,
            models or COMPARISONS[step],
            preset=preset,
            seeds=seeds,
            lrs=lrs,
            budget_s=budget_s,
            announce=print,
            tag=step,
        )
    elif step == "noise":
        noise_step(data, runs, progress=progress)
    elif step == "fullmap":
        full_map_step(data, runs, progress=progress)
    else:
        raise SystemExit(f"unknown step {step!r}: {', '.join(COMPARISONS)}, noise or fullmap")


def _headline_lr(runs: Path, model: str) -> float:
    """The lr the headline chose on val for ``model``."""
    path = runs / "selection-headline.json"
    if not path.exists():
        raise SystemExit(f"{path} missing: run the headline step first (--steps headline,...)")
    return next(m["lr"] for m in json.loads(path.read_text())["models"] if m["model"] == model)


def _selections(runs: Path) -> list[tuple[str, dict[str, Any]]]:
    """Every ``selection-<step>.json`` of ``runs``, by step name."""
    return [
        (path.stem.removeprefix("selection-"), json.loads(path.read_text()))
        for path in sorted(runs.glob("selection-*.json"))
    ]


def noise_step(
    data: Path,
    runs: Path,
    grid: tuple[tuple[float, float], ...] = NOISE_GRID,
    progress: Callable[[], None] = lambda: None,
) -> None:
    """The headline models' runs on test under each (S, P) of ``grid``; ``progress`` is called
    after each evaluation."""
    selection = json.loads((runs / "selection-headline.json").read_text())
    chosen = {m["model"]: m["runs"] for m in selection["models"]}
    for model in NOISE_MODELS:
        boxes = scene_term(model)
        for jitter, drop in grid:
            noise = BoxNoise(jitter=jitter, drop=drop)
            seeds = chosen[model] if (jitter, drop) == AIM else chosen[model][:1]
            for run_dir in map(Path, seeds):
                if eval_file(run_dir, "test", boxes=boxes, noise=noise).exists():
                    continue
                print(f"{model}: {noise.label()} on {run_dir}", flush=True)
                evaluate_run(run_dir, data, split="test", boxes=boxes, noise=noise)
                progress()


def full_map_step(
    data: Path, runs: Path, seeds: int = 1, progress: Callable[[], None] = lambda: None
) -> None:
    """Full-map recall of the first ``seeds`` chosen runs of each of :data:`FULL_MAP_MODELS`:
    maps at spacing 1 and the figures (:data:`FULL_MAP`) in ``runs/fullmap/<model>/seed<k>``;
    ``progress`` is called after each run's figures."""
    selection = json.loads((runs / "selection-headline.json").read_text())
    chosen = {m["model"]: m["runs"] for m in selection["models"]}
    rooms = list(open_dataset(data).rooms("test"))
    for model in FULL_MAP_MODELS:
        for k, run in enumerate(map(Path, chosen[model][:seeds])):
            out = _full_map_dir(runs, model, k)
            if (out / FULL_MAP).exists():
                continue
            print(f"{model}: full map of {len(rooms)} test rooms with {run}", flush=True)
            localizer = load_localizer(run, data, require_epsilon=False)
            build_maps(localizer, data, rooms, out / "maps", spacing=1)
            run_localize(run, out / "maps", data, split="test", out=out)
            progress()


def _full_map_dir(runs: Path, model: str, seed_index: int) -> Path:
    return runs / "fullmap" / model / f"seed{seed_index}"


# ------------------------------------------------------------------------------ tables


def _pct(x: float) -> str:
    return "-" if x is None or x != x else f"{100 * x:.1f}"


def _pm(entry: dict[str, float]) -> str:
    half = entry.get("ci95", float("nan"))
    return f"{_pct(entry['mean'])} ± {_pct(half)}" if half == half else _pct(entry["mean"])


def _span(entry: dict[str, float], sign: bool = False) -> str:
    f = (lambda x: f"{100 * x:+.1f}") if sign else (lambda x: f"{100 * x:.1f}")
    return f"{f(entry['mean'])} [{f(entry['low'])}, {f(entry['high'])}]"


def _budget(result: dict[str, Any]) -> str:
    """What the comparison's budget meant, from its records."""
    seconds = result["budget_s"]
    if seconds is None:
        return "the preset's batches per epoch for every model"
    if any(_rule(e) not in (None, ("preset",)) for e in result["models"]):
        return (
            f"{seconds:g} s of one thread's compute per run (each network's batches per epoch "
            "from its timed steps; what each got: below)"
        )
    return (
        f"{seconds:g} s per run as budgets were timed before 2026-12-02 (process CPU over "
        "torch's threads, which load changes; what each got: not recorded)"
    )


def _budget_cell(entry: dict[str, Any], step: str) -> str:
    """How ``entry`` (of the comparison ``step``) got its batches, from its selection record
    (a calibration reused from ``calibrations.json`` names the step it was timed for)."""
    b = entry.get("budget")
    if not b:
        return "not recorded"
    if b["source"] == "preset":
        return "the preset's batches (no budget)"
    if b["source"] != "calibrated":  # batches handed to compare, no calibration behind them
        return "handed in (not calibrated)"
    timed_for = b.get("timed_for") or step  # unnamed (an untagged compare): this one
    where = "here" if timed_for == step else f"in `{timed_for}`"
    said = (
        f"calibrated {where}: {b['budget_s']:g} s, a step {b['step_s']:.3f} s, rounds "
        f"{100 * b['spread']:.0f} % apart"
    )
    by = b.get("converted_by")
    if by:  # timed on a later machine, in the first one's seconds
        said += (
            f" (timed {by['timed_s']:.3f} s on a later machine, put in the first one's seconds "
            f"by {by['reference']}'s step: {by['reference_then_s']:.3f} s there, "
            f"{by['reference_now_s']:.3f} s here)"
        )
    return said


def _rule(entry: dict[str, Any]) -> tuple | None:
    """The budget rule behind ``entry``'s batches: (seconds, clock), ("preset",), or None
    when no calibration is recorded."""
    b = entry.get("budget")
    if not b:
        return None
    if b["source"] == "preset":
        return ("preset",)
    return (b["budget_s"], b["clock"]) if b["source"] == "calibrated" and "clock" in b else None


def _budget_lines(result: dict[str, Any], step: str) -> list[str]:
    """What each model's budget bought (batches, triplets, the calibration), and whether the
    comparison is like for like: every network's batches set by one budget rule."""
    lines = [
        "What each model's budget bought (`selection.json`'s records; triplets per run: "
        "batches per epoch × batch size × epochs):",
        "",
        "| model | trained network | batches / epoch | epochs | triplets per run | budget |",
        "|---|---|---|---|---|---|",
    ]
    for e in result["models"]:
        examples = e.get("examples")
        lines.append(
            f"| {e['model']} | {e['trained']} | {e['batches_per_epoch']} | "
            f"{e.get('epochs', 'not recorded')} | "
            f"{'not recorded' if examples is None else f'{examples:,}'} | "
            f"{_budget_cell(e, step)} |"
        )
    rules = {e["model"]: _rule(e) for e in result["models"]}
    unknown = [m for m, r in rules.items() if r is None]
    if unknown:
        said = (
            f"Like for like not shown: {', '.join(unknown)} "
            f"{'has' if len(unknown) == 1 else 'have'} no budget record (runs made before "
            "budgets were recorded, 2026-12-02, or batches handed in), so the batches cannot be "
            "told to come from one rule."
        )
    elif len(set(rules.values())) == 1:
        rule = next(iter(rules.values()))
        said = (
            "Like for like: every model trains the preset's batches (no budget)."
            if rule == ("preset",)
            else f"Like for like: every network's batches fill the same {rule[0]:g} s, "
            f"calibrated by one rule ({rule[1]})."
        )
    else:
        said = (
            "Not like for like: the batches come from different budget rules ("
            + "; ".join(
                f"{m}: {'the preset' if r == ('preset',) else f'{r[0]:g} s, {r[1]}'}"
                for m, r in rules.items()
            )
            + ")."
        )
    return [*lines, "", said]


def _run_paths(entry: dict[str, Any]) -> list[str]:
    """The run directories of a comparison entry (evaluation results) or a selection's."""
    return [r["run"] if isinstance(r, dict) else r for r in entry["runs"]]


def _runs_sentence(runs: Path, result: dict[str, Any]) -> str:
    """Which of the comparison's rows are the headline's runs, computed from the run paths:
    no section says "the same runs" unless they are."""
    path = runs / "comparison-headline.json"
    if not path.exists():
        return ""
    head = json.loads(path.read_text())["models"]
    said = []
    for e in result["models"]:
        paths = _run_paths(e)
        same = next((h for h in head if _run_paths(h) == paths), None)
        if same is not None:
            said.append(f"{e['model']}: the headline {same['model']}'s runs")
            continue
        kin = next((h for h in head if h["trained"] == e["trained"]), None)
        if kin is None:
            said.append(f"{e['model']}: its own runs")
            continue
        differs = [f"lr {e['lr']:g} against {kin['lr']:g}"] if e["lr"] != kin["lr"] else []
        if e["batches_per_epoch"] != kin["batches_per_epoch"]:
            differs.append(
                f"{e['batches_per_epoch']} batches per epoch against {kin['batches_per_epoch']}"
            )
        differs = differs or ["other seeds or directories"]
        said.append(f"{e['model']}: not the headline {kin['model']}'s runs ({', '.join(differs)})")
    return "Runs: " + "; ".join(said) + "."


def _stamp(runs: Path, step: str) -> list[str]:
    """The stamp naming every call of ``step`` that wrote into ``runs``, and a blank line."""
    records = read_provenance(runs, step)
    return [stamp(records), ""] if records else []


def _comparison_tables(runs: Path, result: dict[str, Any], step: str) -> list[str]:
    lines = [
        f"Preset `{result['preset']}`, {_budget(result)}, learning rate of each "
        "model chosen on "
        f"the whole val split from {result['lrs']} with seed {result['seeds'][0]}, then seeds "
        f"{result['seeds']} at it; test read once, after `selection.json` was written.",
        "",
        # seannet compare's own tables (comparison-<step>.md), without their title
        *comparison_markdown(result).rstrip("\n").splitlines()[2:],
    ]
    tiers = sorted(result["models"][0]["summary"]["per_tier"], key=int)
    lines += [
        "",
        "By cascade tier (tier 0: same pose, another layout, against one step; mean over "
        "seeds, %):",
        "",
        "| model | " + " | ".join(f"tier {k}" for k in tiers) + " |",
        "|---|" + "---|" * len(tiers),
    ]
    for e in result["models"]:
        per = e["summary"]["per_tier"]
        lines.append(f"| {e['model']} | " + " | ".join(_pct(per[k]["mean"]) for k in tiers) + " |")
    boxes = [e for e in result["models"] if scene_term(e["model"])]
    for e in boxes:
        weights = [r["box_weight"]["lambda"] for r in e["runs"]]
        lines += ["", f"{e['model']}: lambda chosen on val per seed: {weights}."]
    return [*lines, "", *_budget_lines(result, step)]


def _noise_table(runs: Path, result: dict[str, Any]) -> list[str]:
    grid = [(0.0, 0.0), *NOISE_GRID]
    header = " | ".join(f"S {s:g}, P {p:g}" for s, p in grid)
    lines = [
        "Triplet accuracy (%) on test with the boxes a labeler or detector would give: "
        "corners jittered by S × the box's size (normal std), objects missed with "
        "probability P; epsilon and lambda re-chosen on val under the same noise. Mean over "
        "the seeds evaluated (n); S 0.05, P 0.1 (the aim's point) on every seed.",
        "",
        f"| model | {header} | loss at S 0.05, P 0.1 |",
        "|---|" + "---|" * (len(grid) + 1),
    ]
    chosen = {e["model"]: e for e in result["models"]}
    for model in NOISE_MODELS:
        if model not in chosen:
            continue
        boxes = scene_term(model)
        cells, at = [], {}
        for jitter, drop in grid:
            noise = BoxNoise(jitter=jitter, drop=drop)
            found = [
                json.loads(path.read_text())["accuracy"]
                for r in chosen[model]["runs"]
                if (path := eval_file(Path(r["run"]), "test", boxes=boxes, noise=noise)).exists()
            ]
            at[(jitter, drop)] = found
            cells.append(f"{_pct(sum(found) / len(found))} (n={len(found)})" if found else "-")
        clean, aim = at[(0.0, 0.0)], at[AIM]
        loss = "-"
        if aim and len(aim) == len(clean):
            loss = f"{100 * (sum(clean) - sum(aim)) / len(aim):.1f} points"
        lines.append(f"| {model} | " + " | ".join(cells) + f" | {loss} |")
    return lines


def _aim_losses(runs: Path, result: dict[str, Any], model: str) -> list[float]:
    """Per seed: clean test accuracy minus accuracy at the aim's noise (seeds that have it)."""
    entry = next(e for e in result["models"] if e["model"] == model)
    noise, boxes = BoxNoise(jitter=AIM[0], drop=AIM[1]), scene_term(model)
    out = []
    for r in entry["runs"]:
        path = eval_file(Path(r["run"]), "test", boxes=boxes, noise=noise)
        if path.exists():
            out.append(r["accuracy"] - json.loads(path.read_text())["accuracy"])
    return out


def _noise_loss(runs: Path, result: dict[str, Any], model: str) -> str:
    losses = _aim_losses(runs, result, model)
    if not losses:
        return "not measured"
    seeds = "1 seed" if len(losses) == 1 else f"{len(losses)} seeds"
    return f"{100 * sum(losses) / len(losses):.1f} points ({seeds})"


def _noise_met(runs: Path, result: dict[str, Any], model: str) -> str:
    losses = _aim_losses(runs, result, model)
    return "-" if not losses else ("yes" if sum(losses) / len(losses) <= 0.03 else "no")


def _reading(runs: Path, result: dict[str, Any]) -> list[str]:
    """Computed statements about the headline: each number from the run files."""
    by = {e["model"]: e for e in result["models"]}
    lines = []
    for name, e in by.items():
        if name == SEANNET:
            continue
        d = e["difference_to_first"]
        lines.append(
            f"- SeanNet minus {name}: {_span(d, True)} points on the same rooms (rooms × "
            f"seeds): {_verdict(d, 'SeanNet')}."
        )
    stds = ", ".join(
        f"{name} {100 * e['summary']['accuracy']['std']:.1f}" for name, e in by.items()
    )
    seeds = by[SEANNET]["summary"]["accuracy"]["n"]
    lines.append(f"- Seed-to-seed spread (std over {seeds} seeds, points): {stds}.")
    for name in NOISE_MODELS:
        if name in by and _aim_losses(runs, result, name):
            lines.append(f"- {name} at S = 0.05, P = 0.1 loses {_noise_loss(runs, result, name)}.")
    boxes = runs / "comparison-boxes.json"
    if boxes.exists():
        plain = json.loads(boxes.read_text())["models"][1]["difference_to_first"]
        lines.append(
            f"- The hand-made overlap added to SeanNet: {_span(plain, True)} points (rooms × "
            "seeds; section below): "
            + (
                "SeanNet's layout pathway has not learned all the boxes hold."
                if plain["low"] > 0
                else "not clearly more than SeanNet learned."
            )
        )
    return lines


def _full_map_results(runs: Path) -> dict[str, list[dict[str, Any]]]:
    found: dict[str, list[dict[str, Any]]] = {}
    for model in FULL_MAP_MODELS:
        for path in sorted((runs / "fullmap" / model).glob(f"seed*/{FULL_MAP}")):
            found.setdefault(model, []).append(json.loads(path.read_text()))
    return found


def _full_map_aim(runs: Path) -> str:
    seannet = _full_map_results(runs).get(SEANNET)
    if not seannet:
        return "| full-map recall@1 >= 90 % | not measured (below) | - |"
    recall = sum(r["recall@1"] for r in seannet) / len(seannet)
    return (
        f"| full-map recall@1 >= 90 % | {_pct(recall)} % "
        f"({len(seannet)} seed{'' if len(seannet) == 1 else 's'}) | "
        f"{'yes' if recall >= 0.9 else 'no'} |"
    )


def _full_map_section(runs: Path) -> list[str]:
    found = _full_map_results(runs)
    if not found:
        return []
    bins = list(next(iter(found.values()))[0]["by_moved"])
    lines = [
        "",
        "## Full-map recall",
        "",
        "Each test query (a view of a layout other than 0) ranked against every sub-node of "
        "its room's map: every reachable cell of layout 0 × 4 headings, rendered live and "
        "embedded by the run (`seannet map --spacing 1`, `seannet localize --split test`). "
        "Queries whose pose is blocked in layout 0 have no true sub-node and are left out. "
        "One seed per model (a map is rendered per run): no interval over seeds.",
        "",
        *_stamp(runs, "fullmap"),
        "| model | queries | recall@1 | recall@5 | "
        + " | ".join(f"recall@1, {b} moved" for b in bins)
        + " |",
        "|---|---|---|---|" + "---|" * len(bins),
    ]
    for model, results in found.items():
        for r in results:
            lines.append(
                f"| {model} | {r['queries']} | {_pct(r['recall@1'])} | {_pct(r['recall@5'])} | "
                + " | ".join(_pct(r["by_moved"][b]["recall@1"]) for b in bins)
                + " |"
            )
    return lines


def _verdict(difference: dict[str, Any], first: str) -> str:
    """What an interval of "first minus another" says."""
    if difference["low"] > 0:
        return f"{first} is above it"
    if difference["high"] < 0:
        return f"{first} is below it"
    return "the two are not apart (the interval holds 0)"


def _comparison_section(
    runs: Path,
    step: str,
    title: str,
    intro: str,
    reading: Callable[[dict[str, Any]], list[str]] | None = None,
) -> list[str]:
    """A comparison step's section (nothing when the step was not run): title, what it asks,
    its stamp, computed statements, its tables."""
    path = runs / f"comparison-{step}.json"
    if not path.exists():
        return []
    result = json.loads(path.read_text())
    said = [*reading(result), ""] if reading else []
    return [
        "",
        f"## {title}",
        "",
        f"{intro} {_runs_sentence(runs, result)}".rstrip(),
        "",
        *_stamp(runs, step),
        *said,
        *_comparison_tables(runs, result, step),
    ]


def _kernel_aims(runs: Path) -> list[str]:
    """The first two aims again for SeanNet with the learned kernel (a design chosen on val),
    against the hand-made baseline of the same comparison."""
    path = runs / "comparison-kernel.json"
    if not path.exists():
        return []
    by = {e["model"]: e for e in json.loads(path.read_text())["models"]}
    ours, gap = by[KERNEL[0]]["summary"]["accuracy"], by[KERNEL[1]]["difference_to_first"]
    return [
        f"| {KERNEL[0]} (the learned scene term, below) >= 90 % | {_pct(ours['mean'])} % | "
        f"{'yes' if ours['mean'] >= 0.9 else 'no'} |",
        f"| {KERNEL[0]} >= +3 points over {KERNEL[1]}, interval clear of 0 | "
        f"{_span(gap, True)} | {'yes' if gap['mean'] >= 0.03 and gap['low'] > 0 else 'no'} |",
    ]


def _kernel_reading(result: dict[str, Any]) -> list[str]:
    """Computed statements about the learned scene term against the hand-made overlap."""
    lines = []
    for e in result["models"][1:]:
        d = e["difference_to_first"]
        lines.append(
            f"- {result['models'][0]['model']} minus {e['model']}: {_span(d, True)} points "
            f"(rooms × seeds): {_verdict(d, result['models'][0]['model'])}."
        )
    return lines


def _val_accuracy(entry: dict[str, Any]) -> float:
    """A model's val accuracy at its chosen learning rate (what it is chosen by)."""
    return entry["val_accuracy_by_lr"][f"{entry['lr']:g}"]


def tables(runs: Path) -> str:
    """docs/results.md from the run files under ``runs``."""
    head = json.loads((runs / "comparison-headline.json").read_text())
    models = {e["model"]: e for e in head["models"]}
    ours = models[SEANNET]["summary"]
    baselines = [e for e in head["models"] if e["model"] != SEANNET]
    strongest = max(baselines, key=_val_accuracy)  # chosen on val, as every choice
    gap = strongest["difference_to_first"]
    out = [
        "# Results: SeanNet against the strongest simple baselines",
        "",
        "Written by `python bench/results.py tables DATA RUNS` from the run files; no figure "
        "here is typed by hand. The protocol (DESIGN §12, `seannet compare`): every choice on "
        "the validation rooms, the test rooms read once per chosen configuration, "
        f"{len(head['seeds'])} seeds per "
        "row, intervals over rooms and seeds. The data is `medium` of today's generator "
        "(textures, per-layout light and looks, lived-in layouts) drawn with a dataset seed "
        "no earlier figure or design choice used (`configs/results.toml`): its "
        f"{ours['rooms']} test rooms never informed the model. SeanNet here is `{SEANNET}`, "
        "the network the `cpu` preset trains (the paper's GCN fc, 4,096 wide, is `seannet`: "
        "the fc section below).",
        "",
        *_stamp(runs, "headline"),
        "## Headline",
        "",
        f"- SeanNet: **{_pm(ours['accuracy'])} %** triplet accuracy on {ours['rooms']} unseen "
        "rooms "
        f"(rooms × seeds 95 %: [{_pct(ours['two_level']['low'])}, "
        f"{_pct(ours['two_level']['high'])}]).",
        f"- The strongest baseline, {strongest['model']}: "
        f"{_pm(strongest['summary']['accuracy'])} %; SeanNet minus it "
        f"{_span(gap, True)} points (rooms × seeds), {_span(gap['seeds_t'], True)} (seeds, "
        "Welch).",
        "",
        "Aims of the results issue, as measured:",
        "",
        "| aim | measured | met |",
        "|---|---|---|",
        f"| SeanNet >= 90 % (3-seed mean) | {_pct(ours['accuracy']['mean'])} % | "
        f"{'yes' if ours['accuracy']['mean'] >= 0.9 else 'no'} |",
        f"| >= +3 points over the strongest baseline ({strongest['model']}), interval clear "
        f"of 0 | {_span(gap, True)} | "
        f"{'yes' if gap['mean'] >= 0.03 and gap['low'] > 0 else 'no'} |",
        f"| loses <= 3 points at S = 0.05, P = 0.1 | {_noise_loss(runs, head, SEANNET)} | "
        f"{_noise_met(runs, head, SEANNET)} |",
        _full_map_aim(runs),
        *_kernel_aims(runs),
        "",
        "What the figures say:",
        "",
        *_reading(runs, head),
    ]
    out += [
        "",
        "## SeanNet, the box-overlap baseline and ResNet-18",
        "",
        *_comparison_tables(runs, head, "headline"),
        "",
        "## Under labeler / detector box noise",
        "",
        *_stamp(runs, "noise"),
        *_noise_table(runs, head),
    ]
    out += _comparison_section(
        runs,
        "boxes",
        "SeanNet plus the hand-made overlap",
        "Whether the box overlap still adds to SeanNet (lambda chosen on val): if it does, "
        "SeanNet's layout pathway has not learned what the boxes hold. Both rows train at "
        "the headline SeanNet's lr.",
    )
    out += _full_map_section(runs)
    out += _comparison_section(
        runs,
        "kernel",
        "A learned scene term: the box kernel",
        "`+box-kernel` scores `S + lambda * S_kernel`: the box overlap with a weight per "
        "slot learned on the train triplets' boxes (a chair that moves counts less than a "
        "fridge that does not; `seannet/evaluation/box_kernel.py`), lambda chosen on val "
        "as for `+boxes`, lr chosen on val per model.",
        reading=_kernel_reading,
    )
    out += _comparison_section(
        runs,
        "ablations",
        "Ablations: what each branch adds, under the same selection",
        "On the paper's SeanNet (`seannet`, GCN fc 4,096). "
        "`seannet-image`: the image branch alone; `seannet-nolayout`: the paper's graph "
        "branch (GCN pathways, no layout pathway); `seannet-graph`: no image vector in "
        "the fusion. The same budget rule as the headline's: a network calibrated in an earlier "
        "step under the same budget keeps its batches, the others are calibrated alike.",
    )
    out += _comparison_section(
        runs,
        "fc",
        "A narrower GCN fc",
        "`seannet-fc512`: the GCN's fc 6,144 -> 512 -> 2,048 instead of the paper's "
        "6,144 -> 4,096 -> 2,048; its CPU step is near ResNet-18's "
        '(docs/benchmarks-2026-12-02.md, "A training step"). '
        "The batch counts below say how far the budget's calibrations put the two apart.",
    )
    out += CURVE_SECTION
    out += [
        "",
        "## Not measured in this set of runs",
        "",
        *_steps_not_run(runs, head),
        *_not_on_gpu(runs),
        *NOT_MEASURED,
        "",
        "Older figures (data of earlier generators, selection partly on test) are kept, dated "
        "and fingerprinted, in [results-2026-11-26.md](results-2026-11-26.md); none of them "
        "is used above.",
    ]
    return "\n".join(out) + "\n"


# The learning curve has its own runs and page (bench/learning_curve.py); shown here as its plot
CURVE_SECTION = [
    "",
    "## Accuracy against the training budget",
    "",
    "Whether the aims above are a matter of compute: accuracy on val and test against the "
    "training budget. Its page, [learning-curve.md](learning-curve.md) "
    "(`bench/learning_curve.py`), holds the runs' tables and stamp, and says which networks, "
    "seeds and budgets of its design were run and which were not.",
    "",
    "![accuracy against budget](learning-curve.png)",
]

# What the runs above do not cover, and why; printed under the tables.
NOT_MEASURED = [
    "- The recall@1 of the comparison tables ranks a query among the views its room's "
    "dataset holds, which says little; the full-map recall above (when run: `python "
    "bench/results.py run DATA RUNS --steps fullmap`) ranks it among every sub-node.",
    "- `+box-kernel` under box noise (the noise table holds the headline's models only), and "
    "full-map recall with a scene term (the fullmap step maps the headline's SeanNet and "
    "ResNet-18 only).",
]


# what each step after the headline measures, for the list of steps a set of runs lacks
LATER_STEPS = {
    "noise": "The headline's models under labeler / detector box noise",
    "boxes": "SeanNet plus the hand-made overlap",
    "fullmap": "Full-map recall",
    "kernel": "The learned box kernel",
    "fc": "The paper's GCN fc (4,096 wide) against the cpu preset's",
    "ablations": "The ablations (image branch alone, the paper's graph branch, graph-only)",
}


def _step_progress(runs: Path, step: str, head: dict[str, Any]) -> tuple[int, int]:
    """(done, asked) of ``step``'s measurements under ``runs``: its evaluations (noise), its
    maps (fullmap), or its one comparison."""
    if step == "noise":
        chosen = {e["model"]: e["runs"] for e in head["models"]}
        asked = [
            (model, point, Path(r["run"]))
            for model in NOISE_MODELS
            if model in chosen
            for point in NOISE_GRID
            for r in (chosen[model] if point == AIM else chosen[model][:1])
        ]
        done = sum(
            eval_file(run, "test", boxes=scene_term(m), noise=BoxNoise(jitter=s, drop=p)).exists()
            for m, (s, p), run in asked
        )
        return done, len(asked)
    if step == "fullmap":
        found = _full_map_results(runs)
        return sum(model in found for model in FULL_MAP_MODELS), len(FULL_MAP_MODELS)
    return int((runs / f"comparison-{step}.json").exists()), 1


def _steps_not_run(runs: Path, head: dict[str, Any]) -> list[str]:
    """A line per step of :data:`LATER_STEPS` without all its results under ``runs`` (read
    from the files, so a set run in parts says what it still lacks)."""
    lines = []
    for step, what in LATER_STEPS.items():
        done, asked = _step_progress(runs, step, head)
        if done == asked:
            continue
        said = "not run for this set" if not done else f"{done} of {asked} measured"
        lines.append(f"- {what}: `python bench/results.py run DATA RUNS --steps {step}`; {said}.")
    return lines


def _not_on_gpu(runs: Path) -> list[str]:
    """The paper's scale is missing when no comparison ran a GPU preset (read from the
    selections, not typed)."""
    presets = {selection["preset"] for _, selection in _selections(runs)}
    if presets & {"paper", "gpu"}:
        return []
    return [
        "- The `paper` preset on a GPU (ResNet-50 at 224 px, the four paper baselines): these "
        f"runs used the {', '.join(f'`{p}`' for p in sorted(presets))} preset only."
    ]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="verb", required=True)
    go = sub.add_parser("run", help="make the runs")
    go.add_argument("data", type=Path)
    go.add_argument("runs", type=Path)
    go.add_argument("--steps", default="headline,noise,ablations")
    go.add_argument(
        "--budget",
        type=float,
        default=1200.0,
        help="seconds of one thread's compute per run (1200: about the old 150's batches)",
    )
    go.add_argument(
        "--doc",
        type=Path,
        help="write the tables there (docs/results.md) after each step and evaluation",
    )
    write = sub.add_parser("tables", help="write docs/results.md from the runs")
    write.add_argument("data", type=Path)
    write.add_argument("runs", type=Path)
    write.add_argument("-o", "--output", type=Path, default=ROOT / "docs" / "results.md")
    args = parser.parse_args()
    if args.verb == "run":
        run(args)
    else:
        atomic_write_text(args.output, tables(args.runs))
        print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
