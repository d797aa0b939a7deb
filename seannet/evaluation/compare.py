"""``seannet compare``: train every model under one wall-clock budget, pick each model's
learning rate on the validation rooms, repeat over seeds, and report mean +- std and a 95 %
interval per model.

Fairness, as measured rather than assumed: every model gets the same *seconds* of training
(not the same number of batches), calibrated once per model by timing a few training steps;
the batch count that budget buys is recorded, so a rerun with the recorded figures trains
exactly the same. The learning rate of each model is the best of ``lrs`` on the validation
split (seed 0), and the seeds reuse it.

A model is named by a spec ``NAME[@lite0][+imagenet]``: ``NAME`` a model or ablation
(``seannet``, ``seannet-graph``, ``resnet18``, ``efficientnet_lite0``, ...), ``@lite0`` puts
SeanNet on the EfficientNet-Lite0 image network, ``+imagenet`` starts that network from the
ImageNet weights that install offline (the `lite` extra), e.g. ``seannet@lite0+imagenet``.
"""

from __future__ import annotations

import itertools
import json
import math
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow.parquet as pq
import torch
from scipy import stats
from torch.utils.data import DataLoader

from seannet.data.datasets import ImageTransform, TripletDataset, collate_triplets
from seannet.errors import ModelError
from seannet.evaluation.eval import evaluate_run
from seannet.model.loss import TripletLoss
from seannet.training.config import TrainConfig
from seannet.training.config import preset as load_preset
from seannet.training.loop import train_one_epoch, triplet_step
from seannet.training.runs import HISTORY, LAST, build_for_dataset, device_for_run
from seannet.training.train import param_groups, train
from seannet.weights import LITE0, LITE0_WEIGHTS
from sgdata.fileio import atomic_write_text

__all__ = [
    "COMPARISON",
    "calibrate_batches",
    "compare_models",
    "model_spec",
    "paired_difference",
    "summarize",
    "triplets_per_room",
]

COMPARISON = "comparison"  # comparison.json and comparison.md under the output directory
_CALIBRATION_STEPS = 3  # timed training steps (after one warm-up) per model


def model_spec(spec: str, base: TrainConfig) -> tuple[TrainConfig, Path | None]:
    """The training config and ImageNet weights a spec ``NAME[@lite0][+imagenet]`` names.

    Raises:
        ModelError: ``@`` names another image network, or ``+imagenet`` asks for weights the
            spec's image network has none of offline (only EfficientNet-Lite0 has).
    """
    imagenet = spec.endswith("+imagenet")
    name, _, network = spec.removesuffix("+imagenet").partition("@")
    config = base.replace(model=name)
    if network:
        if network != "lite0" or not name.startswith("seannet"):
            raise ModelError(f"model {spec!r}: '@' takes 'lite0' after a seannet model")
        config = config.replace(backbone=LITE0)
    if imagenet and config.model.image_family != LITE0:
        raise ModelError(
            f"model {spec!r}: +imagenet needs the EfficientNet-Lite0 network "
            f"(seannet@lite0 or {LITE0}); no other ImageNet weights install offline"
        )
    return config, Path(LITE0_WEIGHTS) if imagenet else None


def compare_models(
    data: Path,
    out: Path,
    models: Sequence[str],
    *,
    preset: str | TrainConfig = "cpu",
    split: str = "test",
    seeds: Sequence[int] = (0,),
    lrs: Sequence[float] = (),
    budget_s: float | None = None,
    announce: Callable[[str], None] | None = None,
) -> dict[str, Any]:
    """Train and evaluate every model; write ``out/comparison.{json,md}`` and return it.

    Runs live in ``out/<model>/lr<lr>/seed<k>``; a run that has a checkpoint resumes, so an
    interrupted comparison picks up where it stopped.

    Args:
        preset: a preset name or a :class:`TrainConfig` (its ``model`` is replaced).
        seeds: training seeds; each model's figures are their mean, std and 95 % interval.
        lrs: candidate learning rates, chosen per model on ``val`` (default: the preset's).
        budget_s: training seconds per run; None keeps the preset's batch count for all.

    Raises:
        ModelError: no model or no seed named.
    """
    if not models or not seeds:
        raise ModelError("name at least one model (--models) and one seed (--seeds)")
    say = announce or (lambda _text: None)
    base = load_preset(preset) if isinstance(preset, str) else preset
    name_of_preset = preset if isinstance(preset, str) else "custom"
    results: dict[str, Any] = {"preset": name_of_preset, "split": split, "budget_s": budget_s}
    entries = []
    specs = {name: model_spec(name, base) for name in models}  # refuse a bad spec before work
    for name, (config, pretrained) in specs.items():
        if budget_s is not None:
            batches = calibrate_batches(config, data, budget_s)
            config = config.replace(max_train_batches=batches)
            say(f"{name}: {batches} batches per epoch fill {budget_s:.0f} s")
        sweep = {}
        for lr in lrs or (config.lr,):
            run = _run_dir(out, name, lr, seeds[0])
            say(f"{name}: lr {lr:g}, seed {seeds[0]} -> {run}")
            _train(config.replace(lr=lr, seed=seeds[0]), data, run, pretrained)
            sweep[lr] = max(h["val_accuracy"] for h in json.loads((run / HISTORY).read_text()))
        lr = max(sweep, key=lambda k: (sweep[k], -k))  # best val accuracy; ties: the smaller
        runs = []
        for seed in seeds:
            run = _run_dir(out, name, lr, seed)
            if seed != seeds[0]:
                say(f"{name}: lr {lr:g}, seed {seed} -> {run}")
                _train(config.replace(lr=lr, seed=seed), data, run, pretrained)
            runs.append(evaluate_run(run, data, split=split))
        entries.append(
            {
                "model": name,
                "pretrained": str(pretrained) if pretrained else None,
                "lr": lr,
                "val_accuracy_by_lr": {f"{k:g}": v for k, v in sweep.items()},
                "batches_per_epoch": config.max_train_batches,
                "epochs": config.epochs,
                "summary": summarize(runs),
                "runs": runs,
            }
        )
    results["models"] = entries
    counts = triplets_per_room(data, split)
    for entry in entries[1:]:
        entry["difference_to_first"] = paired_difference(entries[0]["runs"], entry["runs"], counts)
    out.mkdir(parents=True, exist_ok=True)
    atomic_write_text(out / f"{COMPARISON}.json", json.dumps(results, indent=2))
    atomic_write_text(out / f"{COMPARISON}.md", markdown(results))
    return results


def _run_dir(out: Path, name: str, lr: float, seed: int) -> Path:
    return out / name / f"lr{lr:g}" / f"seed{seed}"


def _train(config: TrainConfig, data: Path, run: Path, pretrained: Path | None) -> None:
    train(config, data, run, resume=(run / LAST).exists(), pretrained=pretrained)


def calibrate_batches(config: TrainConfig, data: Path, budget_s: float) -> int:
    """Batches per epoch that fill ``budget_s`` seconds of training, from timed steps."""
    torch.manual_seed(0)
    device = device_for_run()
    model = build_for_dataset(config, data).to(device)
    optimizer = torch.optim.SGD(param_groups(model, config), lr=config.lr, momentum=0.9)
    loss_fn = TripletLoss(margin=config.margin)
    triplets = TripletDataset(
        data,
        "train",
        transform=ImageTransform.for_model(config.model.image_size, config.model.image_family),
    )
    loader = DataLoader(triplets, batch_size=config.batch_size, collate_fn=collate_triplets)
    batches = itertools.islice(loader, _CALIBRATION_STEPS + 1)
    marks: list[float] = []

    def clock(_phase: str, _step: int, _total: int, _metrics: dict[str, float]) -> None:
        if device.type == "cuda":
            torch.cuda.synchronize()  # kernels run asynchronously: time them, not their launch
        marks.append(time.perf_counter())

    start = time.perf_counter()
    train_one_epoch(model, batches, triplet_step(model, loss_fn, device), optimizer, progress=clock)
    # the first step pays for allocation; each later one from the mark before it (the
    # loader's read of the next batch counts: a run pays for it too)
    seconds = np.diff([start, *marks])[1:]
    per_epoch = budget_s / config.epochs
    return max(1, int(per_epoch / float(np.median(seconds))))


def _interval(values: list[float]) -> dict[str, float]:
    """Mean, std (ddof 1) and the half-width of a 95 % t interval of the mean."""
    x = np.asarray(values, dtype=np.float64)
    n = len(x)
    std = float(x.std(ddof=1)) if n > 1 else float("nan")
    half = float(stats.t.ppf(0.975, n - 1) * std / math.sqrt(n)) if n > 1 else float("nan")
    return {"mean": float(x.mean()), "std": std, "ci95": half, "n": n}


def summarize(runs: list[dict[str, Any]]) -> dict[str, Any]:
    """Per-metric mean / std / 95 % interval over the seeds' evaluation results."""
    first = runs[0]
    summary = {
        "accuracy": _interval([r["accuracy"] for r in runs]),
        "recall1": _interval([r["retrieval"]["recall"][1] for r in runs]),
        "recall5": _interval([r["retrieval"]["recall"][5] for r in runs]),
        "d_prime": _interval([r["separation"]["d_prime"] for r in runs]),
        "per_tier": {
            str(k): _interval([r["per_tier"][k] for r in runs]) for k in first["per_tier"]
        },
        "by_moved": {
            k: _interval([r["by_moved"][k]["accuracy"] for r in runs]) for k in first["by_moved"]
        },
        "triplets": first["triplets"],
        "rooms": len(first["per_room"]),
        "queries": first["retrieval"]["queries"],
    }
    p, n = summary["accuracy"]["mean"], summary["triplets"]
    # the sampling interval of one run's accuracy over its triplets (binomial)
    summary["accuracy"]["binomial95"] = 1.96 * math.sqrt(p * (1 - p) / n) if n else float("nan")
    return summary


def paired_difference(
    runs_a: list[dict[str, Any]],
    runs_b: list[dict[str, Any]],
    triplets_per_room: dict[str, int],
    *,
    resamples: int = 10_000,
) -> dict[str, float]:
    """Triplet accuracy of A minus B on the same rooms, with a 95 % room-bootstrap interval.

    Each room's accuracy is averaged over each model's seeds, the difference weighted by the
    room's triplets; the rooms are resampled (a fixed seed: the same figures every time).
    Why rooms: triplets of one room share its views and layouts, so they are not independent;
    the rooms are, and pairing removes what the two models find equally hard.
    """
    rooms = sorted(triplets_per_room)
    a = np.mean([[r["per_room"][room] for room in rooms] for r in runs_a], axis=0)
    b = np.mean([[r["per_room"][room] for room in rooms] for r in runs_b], axis=0)
    weight = np.array([triplets_per_room[room] for room in rooms], dtype=np.float64)
    pick = np.random.default_rng(0).integers(0, len(rooms), size=(resamples, len(rooms)))
    boot = ((a - b)[pick] * weight[pick]).sum(1) / weight[pick].sum(1)
    low, high = np.percentile(boot, [2.5, 97.5])
    diff = float(((a - b) * weight).sum() / weight.sum())
    return {"mean": diff, "low": float(low), "high": float(high), "rooms": len(rooms)}


def triplets_per_room(data: Path, split: str) -> dict[str, int]:
    """How many ``split`` triplets each room holds (from the dataset's triplet table)."""
    rooms = pq.read_table(data / "triplets" / f"{split}.parquet", columns=["room_id"])
    names, counts = np.unique(rooms.column("room_id").to_numpy(), return_counts=True)
    return {str(n): int(c) for n, c in zip(names, counts, strict=True)}


def _pm(entry: dict[str, float]) -> str:
    mean, ci = 100 * entry["mean"], 100 * entry["ci95"]
    return f"{mean:.1f} ± {ci:.1f}" if not math.isnan(ci) else f"{mean:.1f}"


def markdown(results: dict[str, Any]) -> str:
    """The comparison as markdown tables (mean ± 95 % interval over seeds, in %)."""
    rows = [
        f"# Comparison on {results['split']} (preset {results['preset']}, "
        f"budget {results['budget_s']} s per run)",
        "",
        "| model | lr | seeds | triplet acc | recall@1 | recall@5 | tier 0 | tier 1 | d' | "
        "triplets / rooms |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for e in results["models"]:
        s = e["summary"]
        tiers = s["per_tier"]
        rows.append(
            f"| {e['model']} | {e['lr']:g} | {s['accuracy']['n']} | {_pm(s['accuracy'])} | "
            f"{_pm(s['recall1'])} | {_pm(s['recall5'])} | "
            f"{_pm(tiers['0']) if '0' in tiers else '-'} | "
            f"{_pm(tiers['1']) if '1' in tiers else '-'} | "
            f"{s['d_prime']['mean']:.2f} | {s['triplets']} / {s['rooms']} |"
        )
    if len(results["models"]) > 1:
        first = results["models"][0]["model"]
        rows += ["", f"{first} minus each model, same rooms (95 % room-bootstrap interval):", ""]
        for e in results["models"][1:]:
            d = e["difference_to_first"]
            rows.append(
                f"- {e['model']}: {100 * d['mean']:+.1f} points "
                f"[{100 * d['low']:+.1f}, {100 * d['high']:+.1f}] over {d['rooms']} rooms"
            )
    rows += ["", "Accuracy by moved objects in view (mean over seeds, %):", ""]
    bins = list(results["models"][0]["summary"]["by_moved"]) if results["models"] else []
    rows += ["| model | " + " | ".join(bins) + " |", "|---|" + "---|" * len(bins)]
    for e in results["models"]:
        moved = e["summary"]["by_moved"]
        rows.append(f"| {e['model']} | " + " | ".join(_pm(moved[b]) for b in bins) + " |")
    return "\n".join(rows) + "\n"
