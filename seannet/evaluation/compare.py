"""``seannet compare``: every model under one budget rule, every choice on the validation
rooms, the test rooms read once, and intervals over rooms and seeds.

The protocol (DESIGN §12), in the order it runs:

1. **Budget.** Every model gets the same *seconds* of one thread's compute (not the same
   number of batches), calibrated once per trained network by timing a few steps on one
   thread (:mod:`seannet.training.budget`: the machine's load does not change it); what the
   budget bought (batches, triplets, the timing's spread) is recorded in the selection, a
   spread above :data:`~seannet.training.budget.SPREAD_WARNING` is announced as a warning,
   and a rerun with the recorded figures trains exactly the same. Each calibration is kept
   in ``calibrations.json`` before any run trains, so a comparison resumed (on this machine
   or another) trains the batches its runs began with.
2. **Selection, on val only.** For each learning rate of ``lrs``, seed 0 is trained and its
   best epoch (per-epoch val) is evaluated on the *whole* val split; the lr with the best val
   accuracy is chosen (ties: the smaller), and the other seeds are trained at it. A
   ``+boxes`` or ``+box-kernel`` spec chooses its lambda on val in the same evaluation.
3. ``selection.json`` is written: each model's chosen lr, its val accuracy by lr, its runs.
   No test row has been read until then (``on_selected`` is called at that point).
4. **Test, once.** Each chosen run is evaluated on the test split.
5. **Intervals.** Per model, the two-level interval over rooms and seeds (variance
   components: a room bootstrap's variance plus the seeds' over their number, t on seeds - 1
   dof) and the seed-level t-interval; for the first model minus each other, the same with
   one room draw for both (paired) and Welch's seed-level interval
   (:mod:`seannet.evaluation.intervals`).

A model is named by a spec ``NAME[@net][+imagenet][+boxes|+box-kernel]``
(:mod:`seannet.model.specs`): ``NAME`` a model or ablation (``seannet``, ``seannet-graph``,
``resnet18``, ``efficientnet_lite0``, ...), ``@net`` puts SeanNet on another image network of
the registry (``@lite0``, ``@resnet18``), ``+imagenet`` starts that network from the ImageNet
weights that install offline (the `lite` extra), ``+boxes`` adds the
hand-made box overlap to the similarity (:mod:`seannet.evaluation.box_overlap`) and
``+box-kernel`` the box kernel learned on train (:mod:`seannet.evaluation.box_kernel`); their
runs are ``NAME``'s: ``resnet18``, ``resnet18+boxes`` and ``resnet18+box-kernel`` train once.
"""

from __future__ import annotations

import json
import math
import os
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from seannet.data.opening import DataSource, open_dataset
from seannet.errors import ModelError
from seannet.evaluation.intervals import (
    per_room_matrix,
    t_interval,
    two_level_difference,
    two_level_interval,
    welch_difference,
)
from seannet.evaluation.run_eval import evaluate_run
from seannet.markdown import table
from seannet.model.specs import ResolvedSpec, parse_spec
from seannet.provenance import PROCESS, provenance_record
from seannet.training.budget import Calibration, calibrate
from seannet.training.config import DEFAULT_PRESET, TrainConfig
from seannet.training.config import preset as load_preset
from seannet.training.runs import LAST, device_for_run
from seannet.training.train import train
from sgdata.dataset import Dataset
from sgdata.fileio import atomic_write_text

__all__ = [
    "CALIBRATIONS",
    "COMPARISON",
    "SELECTION",
    "ModelSpec",
    "compare_models",
    "model_spec",
    "summarize",
    "triplets_per_room",
]

COMPARISON = "comparison"  # comparison.json and comparison.md under the output directory
CALIBRATIONS = "calibrations.json"  # the budget's calibrations of the runs under it, reused
SELECTION = "selection.json"  # every choice, written before any test row is read


@dataclass(frozen=True)
class ModelSpec:
    """What a spec names: the network trained, its weights, how its pairs are scored."""

    spec: str  # as given, e.g. "resnet18+boxes"
    trained: str  # the trained network's spec (its run directory), e.g. "resnet18"
    config: TrainConfig
    pretrained: Path | None
    boxes: str  # the scene term added to the similarity (specs.SCENE_TERMS), or ""


def model_spec(spec: str | ResolvedSpec, base: TrainConfig) -> ModelSpec:
    """What a spec ``NAME[@net][+imagenet][+boxes|+box-kernel]`` names, set on ``base``: a
    resolved spec as it is, a spec's text resolved here, where it comes in
    (:func:`seannet.model.specs.parse_spec`).

    Raises:
        ModelError: an unknown name or network, or ``+imagenet`` asking for weights the spec's
            image network has none of offline; the message lists the choices.
    """
    parsed = spec if isinstance(spec, ResolvedSpec) else parse_spec(spec)
    config = base.replace(**parsed.model_fields())
    pretrained = Path(parsed.pretrained) if parsed.pretrained else None
    return ModelSpec(parsed.spec, parsed.trained, config, pretrained, parsed.scene)


def compare_models(
    data: DataSource,
    out: Path,
    models: Sequence[str],
    *,
    preset: str | TrainConfig = DEFAULT_PRESET,
    seeds: Sequence[int] = (0,),
    lrs: Sequence[float] = (),
    budget_s: float | None = None,
    announce: Callable[[str], None] | None = None,
    on_selected: Callable[[Path], None] | None = None,
    tag: str = "",
    batches: dict[str, int] | None = None,
) -> dict[str, Any]:
    """Select on val, test once; write ``out/selection.json`` then ``out/comparison.{json,md}``.

    ``data`` (the dataset's root, or the dataset opened already) is opened once, here, and
    the opened dataset is what training, calibration and evaluation are handed.

    Runs live in ``out/<trained spec>/lr<lr>/seed<k>``; a run that has a checkpoint resumes,
    so an interrupted comparison picks up where it stopped.

    Args:
        preset: a preset name or a :class:`TrainConfig` (its model is replaced).
        seeds: training seeds (the first one selects the lr).
        lrs: candidate learning rates, chosen per model on val (default: the preset's).
        budget_s: seconds of one thread's compute per run (seannet.training.budget); None
            keeps the preset's batch count for all.
        on_selected: called with the selection file once it is written, before any test row
            is read.
        tag: names this comparison's files (``selection-<tag>.json``, ...), so comparisons of
            different model sets can share one ``out`` and its runs.
        batches: batches per epoch by trained network, as an earlier comparison recorded
            them (its selection); the others are calibrated to ``budget_s``, or take the
            calibration ``out/calibrations.json`` keeps of them.

    Raises:
        ModelError: no model or no seed named, or a bad spec.
    """
    if not models or not seeds:
        raise ModelError("name at least one model (--models) and one seed (--seeds)")
    say = announce or (lambda _text: None)
    base = load_preset(preset) if isinstance(preset, str) else preset
    specs = [model_spec(name, base) for name in models]  # refuse a bad spec before work
    ds = open_dataset(data)  # the manifest read once for the whole comparison
    batches = dict(batches or {})
    calibrations: dict[str, tuple[Calibration, str]] = {}  # and the comparison timed for
    chosen = []
    for spec in specs:
        config = spec.config
        if budget_s is not None or spec.trained in batches:
            if spec.trained not in batches:
                calibrations[spec.trained] = _calibration(
                    spec.trained, config, base, ds, out, budget_s, say, tag
                )
                batches[spec.trained] = calibrations[spec.trained][0].batches
            config = config.replace(max_train_batches=batches[spec.trained])
        choice = _select(spec, config, ds, out, seeds, lrs or (config.lr,), say)
        # what the budget bought, how it was measured and for which comparison (an earlier
        # one under ``out`` whose calibration this one reuses); or where the batches came from
        if spec.trained in calibrations:
            got, timed_for = calibrations[spec.trained]
            choice["budget"] = {"source": "calibrated", **got.to_dict(), "timed_for": timed_for}
        else:
            choice["budget"] = {"source": "recorded" if spec.trained in batches else "preset"}
        chosen.append(choice)
    selection = {
        "preset": preset if isinstance(preset, str) else "custom",
        "budget_s": budget_s,
        "seeds": list(seeds),
        "lrs": [float(lr) for lr in (lrs or (base.lr,))],
        "models": chosen,
    }
    out.mkdir(parents=True, exist_ok=True)
    suffix = f"-{tag}" if tag else ""
    selection_file = out / SELECTION.replace(".json", f"{suffix}.json")
    atomic_write_text(selection_file, json.dumps(selection, indent=2))
    if on_selected is not None:
        on_selected(selection_file)
    entries = []
    for spec, choice in zip(specs, chosen, strict=True):
        say(f"{spec.spec}: test, lr {choice['lr']:g}")
        runs = [evaluate_run(Path(r), ds, split="test", boxes=spec.boxes) for r in choice["runs"]]
        entries.append({**choice, "summary": summarize(runs), "runs": runs})
    counts = triplets_per_room(ds, "test")
    for entry in entries:
        entry["summary"]["two_level"] = _two_level(entry["runs"], counts)
    for entry in entries[1:]:
        entry["difference_to_first"] = _difference(entries[0]["runs"], entry["runs"], counts)
    results = {**selection, "split": "test", "models": entries}
    atomic_write_text(out / f"{COMPARISON}{suffix}.json", json.dumps(results, indent=2))
    atomic_write_text(out / f"{COMPARISON}{suffix}.md", markdown(results))
    return results


def _select(
    spec: ModelSpec,
    config: TrainConfig,
    ds: Dataset,
    out: Path,
    seeds: Sequence[int],
    lrs: Sequence[float],
    say: Callable[[str], None],
) -> dict[str, Any]:
    """Train seed 0 at every lr, choose the lr on the whole val split, train the seeds."""
    sweep = {}
    for lr in lrs:
        run = _run_dir(out, spec.trained, lr, seeds[0])
        say(f"{spec.spec}: lr {lr:g}, seed {seeds[0]} -> {run}")
        _train(config.replace(lr=lr, seed=seeds[0]), ds, run, spec.pretrained)
        sweep[lr] = evaluate_run(run, ds, split="val", boxes=spec.boxes)["accuracy"]
    lr = max(sweep, key=lambda k: (sweep[k], -k))  # best val accuracy; ties: the smaller
    runs = []
    for seed in seeds:
        run = _run_dir(out, spec.trained, lr, seed)
        if seed != seeds[0]:
            say(f"{spec.spec}: lr {lr:g}, seed {seed} -> {run}")
            _train(config.replace(lr=lr, seed=seed), ds, run, spec.pretrained)
        runs.append(str(run))
    return {
        "model": spec.spec,
        "trained": spec.trained,
        "pretrained": str(spec.pretrained) if spec.pretrained else None,
        "lr": lr,
        "val_accuracy_by_lr": {f"{k:g}": v for k, v in sweep.items()},
        "batches_per_epoch": config.max_train_batches,
        "epochs": config.epochs,
        # triplets trained per run (0 batches: the whole split every epoch)
        "examples": config.max_train_batches * config.batch_size * config.epochs,
        "runs": runs,
    }


def _calibration(
    trained: str,
    config: TrainConfig,
    base: TrainConfig,
    ds: Dataset,
    out: Path,
    budget_s: float,
    say: Callable[[str], None],
    tag: str,
) -> tuple[Calibration, str]:
    """The calibration that sets ``trained``'s batches for the runs under ``out``, and the
    tag of the comparison it was first taken for (``tag`` when taken now).

    The first one taken is kept in ``out/calibrations.json`` (before any run trains) and
    reused by every later call with the same network, budget and step shape: a comparison
    resumed, maybe on another machine, must train the batches its runs began with, and a
    second timing differs (by a few per cent on one machine, by half on another). A network
    first timed by a later process, while the file holds networks timed by an earlier one
    (maybe on another machine), is converted to the earlier one's seconds: the first network
    of the file is timed again here, and the ratio of its two steps scales the new one's
    (:meth:`Calibration.converted`), so every network under ``out`` trains by one rule."""
    path = out / CALIBRATIONS
    records = _read_calibrations(path)
    shape = {
        "budget_s": float(budget_s),
        "batch_size": config.batch_size,
        "epochs": config.epochs,
        "image_size": config.model.image_size,
        "device": device_for_run().type,
    }
    key = {"trained": trained, **shape}
    for record in records:
        if record["key"] == key:
            got = Calibration.from_dict(record["calibration"])
            say(
                f"{trained}: {got.batches} batches per epoch, as calibrated for these runs at "
                f"{record['taken']['started']} (a step {got.step_s:.3f} s; {path})"
            )
            return got, record.get("comparison", "")
    got = _calibrate(trained, config, ds, budget_s, say)
    first = next((r for r in records if {**r["key"], "trained": trained} == key), None)
    here = (os.getpid(), PROCESS.loaded)
    if first is not None and (first["taken"]["pid"], first["taken"]["code_loaded"]) != here:
        reference = first["key"]["trained"]
        now = calibrate(model_spec(reference, base).config, ds, budget_s).step_s
        got = got.converted(reference, first["calibration"]["step_s"], now, config)
        say(
            f"{trained}: {got.batches} batches per epoch in the seconds of {reference}'s "
            f"calibration at {first['taken']['started']} ({reference}'s step there "
            f"{got.converted_by['reference_then_s']:.3f} s, here {now:.3f} s)"
        )
    taken = provenance_record(None, step="calibrate")  # when, by which code and command
    records.append({"key": key, "taken": taken, "comparison": tag, "calibration": got.to_dict()})
    out.mkdir(parents=True, exist_ok=True)
    atomic_write_text(path, json.dumps(records, indent=2))
    return got, tag


def _read_calibrations(path: Path) -> list[dict[str, Any]]:
    """The records of ``path`` (none when it is absent).

    Raises:
        ModelError: the file is not a list of calibration records.
    """
    if not path.exists():
        return []
    try:
        records = json.loads(path.read_text())
        if all({"key", "taken", "calibration"} <= set(r) for r in records):
            return records
    except (ValueError, TypeError):
        pass
    raise ModelError(
        f"{path}: not a list of calibration records (key, taken, calibration); restore it, or "
        "delete it to time the networks again (runs already trained then refuse to resume)"
    )


def _calibrate(
    trained: str,
    config: TrainConfig,
    ds: Dataset,
    budget_s: float,
    say: Callable[[str], None],
) -> Calibration:
    """The budget's batches for one network, announced; a disturbed timing is a warning."""
    got = calibrate(config, ds, budget_s)
    say(
        f"{trained}: {got.batches} batches per epoch fill {budget_s:g} s of one thread "
        f"(a step {got.step_s:.3f} s, rounds {100 * got.spread:.0f} % apart)"
    )
    if got.noisy:
        warning = (
            f"{trained}: the calibration's rounds differ by {100 * got.spread:.0f} %: the "
            f"machine was busy ({100 * got.busy:.0f} % of the time elsewhere); pass the "
            "recorded batches to train the same, or calibrate again on a quieter machine"
        )
        warnings.warn(warning, RuntimeWarning, stacklevel=3)
        say(f"warning: {warning}")
    return got


def _run_dir(out: Path, name: str, lr: float, seed: int) -> Path:
    return out / name / f"lr{lr:g}" / f"seed{seed}"


def _train(config: TrainConfig, ds: Dataset, run: Path, pretrained: Path | None) -> None:
    train(config, ds, run, resume=(run / LAST).exists(), pretrained=pretrained)


def summarize(runs: list[dict[str, Any]]) -> dict[str, Any]:
    """Per-metric mean / std / 95 % t-interval over the seeds' evaluation results."""
    first = runs[0]
    summary = {
        "accuracy": t_interval([r["accuracy"] for r in runs]),
        "recall1": t_interval([r["retrieval"]["recall"][1] for r in runs]),
        "recall5": t_interval([r["retrieval"]["recall"][5] for r in runs]),
        "d_prime": t_interval([r["separation"]["d_prime"] for r in runs]),
        "per_tier": {
            str(k): t_interval([r["per_tier"][k] for r in runs]) for k in first["per_tier"]
        },
        "by_moved": {
            k: t_interval([r["by_moved"][k]["accuracy"] for r in runs]) for k in first["by_moved"]
        },
        "triplets": first["triplets"],
        "rooms": len(first["per_room"]),
        "queries": first["retrieval"]["queries"],
    }
    p, n = summary["accuracy"]["mean"], summary["triplets"]
    # the sampling interval of one run's accuracy over its triplets (binomial)
    summary["accuracy"]["binomial95"] = 1.96 * math.sqrt(p * (1 - p) / n) if n else float("nan")
    return summary


def _two_level(runs: list[dict[str, Any]], counts: dict[str, int]) -> dict[str, float]:
    rooms = sorted(counts)
    weight = np.array([counts[r] for r in rooms], dtype=np.float64)
    return two_level_interval(per_room_matrix(runs, rooms), weight)


def _difference(
    runs_a: list[dict[str, Any]], runs_b: list[dict[str, Any]], counts: dict[str, int]
) -> dict[str, Any]:
    """A minus B: the two-level interval (paired room bootstrap's variance plus each model's
    seed variance, t on the smaller seed count - 1 dof), and Welch over seeds."""
    rooms = sorted(counts)
    weight = np.array([counts[r] for r in rooms], dtype=np.float64)
    a, b = per_room_matrix(runs_a, rooms), per_room_matrix(runs_b, rooms)
    return {
        **two_level_difference(a, b, weight),
        "seeds_t": welch_difference(
            [r["accuracy"] for r in runs_a], [r["accuracy"] for r in runs_b]
        ),
    }


def triplets_per_room(data: DataSource, split: str) -> dict[str, int]:
    """How many ``split`` triplets each room holds (from the dataset's triplet table;
    ``data``: the dataset opened, or its root)."""
    rooms = open_dataset(data).triplets(split)
    names, counts = np.unique(rooms.column("room_id").to_numpy(), return_counts=True)
    return {str(n): int(c) for n, c in zip(names, counts, strict=True)}


def _pm(entry: dict[str, float]) -> str:
    mean, ci = 100 * entry["mean"], 100 * entry["ci95"]
    return f"{mean:.1f} ± {ci:.1f}" if not math.isnan(ci) else f"{mean:.1f}"


def _range(entry: dict[str, float]) -> str:
    return f"{100 * entry['mean']:+.1f} [{100 * entry['low']:+.1f}, {100 * entry['high']:+.1f}]"


def markdown(results: dict[str, Any]) -> str:
    """The comparison as markdown tables (in %): mean ± 95 % t-interval over seeds, and the
    two-level (rooms x seeds) interval."""
    rows = [
        f"# Comparison on test (preset {results['preset']}, budget {results['budget_s']} s "
        f"per run; lr of each model chosen on val from {results['lrs']})",
        "",
    ]
    header = ("model", "lr", "val acc", "seeds", "test acc (seeds t)", "rooms x seeds 95 %",
              "recall@1", "tier 0", "tier 1", "d'", "triplets / rooms")  # fmt: skip
    rows += table(header, (_model_cells(e) for e in results["models"]))
    if len(results["models"]) > 1:
        first = results["models"][0]["model"]
        rows += [
            "",
            f"{first} minus each model on the same rooms, points, 95 %: rooms x seeds (the "
            "variance of a room bootstrap paired on the rooms plus each model's seed variance "
            "over its seeds, t on the smaller seed count - 1 dof) and Welch's seed-level "
            "t-interval:",
            "",
        ]
        differences = [(e["model"], e["difference_to_first"]) for e in results["models"][1:]]
        rows += table(
            ("model", "rooms x seeds", "seeds (t)"),
            ((m, _range(d), _range(d["seeds_t"])) for m, d in differences),
        )
    rows += ["", "Accuracy by moved objects in view (mean over seeds, %):", ""]
    bins = list(results["models"][0]["summary"]["by_moved"]) if results["models"] else []
    moved = [(e["model"], e["summary"]["by_moved"]) for e in results["models"]]
    rows += table(("model", *bins), ((m, *(_pm(by[b]) for b in bins)) for m, by in moved))
    return "\n".join(rows) + "\n"


def _model_cells(e: dict[str, Any]) -> tuple[str, ...]:
    """One model's row of the comparison's first table."""
    s = e["summary"]
    tiers = s["per_tier"]
    two = s["two_level"]
    val = e["val_accuracy_by_lr"][f"{e['lr']:g}"]
    return (
        e["model"],
        f"{e['lr']:g}",
        f"{100 * val:.1f}",
        f"{s['accuracy']['n']}",
        _pm(s["accuracy"]),
        f"[{100 * two['low']:.1f}, {100 * two['high']:.1f}]",
        _pm(s["recall1"]),
        _pm(tiers["0"]) if "0" in tiers else "-",
        _pm(tiers["1"]) if "1" in tiers else "-",
        f"{s['d_prime']['mean']:.2f}",
        f"{s['triplets']} / {s['rooms']}",
    )
