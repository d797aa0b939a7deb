"""``seannet detector train``: the detector trained on the COCO export of a dataset's train
split, its epoch chosen by AP50 on val views, within a time limit.

A run directory holds ``coco/`` (the export it trained on, also what it is scored on),
``detector.pt`` (the chosen epoch's weights with its config and the dataset's identity) and
``detector.json`` (config, per-epoch curve, the chosen epoch; written after every epoch).
"""

from __future__ import annotations

import json
import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import torch
from torch import nn

from seannet.data.opening import DataSource, dataset_identity, open_dataset
from seannet.detection.coco_eval import CocoScore, coco_score, detect
from seannet.detection.coco_views import CocoViews, collate_detection
from seannet.detection.model import DetectorConfig, build_detector
from seannet.errors import CheckpointError
from seannet.provenance import append_provenance
from seannet.training.runs import check_same_dataset, load_checkpoint, save_checkpoint
from sgdata.fileio import atomic_write_text

__all__ = [
    "DETECTOR",
    "DETECTOR_JSON",
    "TrainedDetector",
    "export_for",
    "load_detector",
    "train_detector",
]

DETECTOR, DETECTOR_JSON, COCO = "detector.pt", "detector.json", "coco"
# the labeling tool's box proposer of a run (seannet.detection.proposer; sgdata label --detector)
PROPOSER = "seannet.detection.proposer:open_proposer"
# progress(phase, done, total, metrics): "train" counts steps, "val" views
Progress = Callable[[str, int, int, dict[str, float]], None]


def export_for(data: DataSource, run: Path) -> Path:
    """The run's COCO export of ``data`` (every split), written once per dataset: an export
    of another dataset (its manifest's sha256 differs) is replaced."""
    from sgdata.label.coco_export import export_coco

    ds = open_dataset(data)
    folder = run / COCO
    marker = run / f"{COCO}.manifest_sha256"
    if not marker.is_file() or marker.read_text().strip() != ds.manifest_sha256:
        export_coco(ds.root, folder, force=True)
        atomic_write_text(marker, ds.manifest_sha256 + "\n")
    return folder


def _val_indices(views: CocoViews, count: int, seed: int) -> list[int]:
    """``count`` val views drawn once from the seed (all of them for 0), in index order."""
    if count == 0 or count >= len(views):
        return list(range(len(views)))
    rng = np.random.default_rng([seed, 1])
    return sorted(rng.choice(len(views), size=count, replace=False).tolist())


def _lr_at(config: DetectorConfig, step: int, total: int) -> float:
    """Linear warm-up, then cosine decay to zero over the planned steps."""
    if step < config.warmup_steps:
        return config.lr * (step + 1) / config.warmup_steps
    progress = (step - config.warmup_steps) / max(total - config.warmup_steps, 1)
    return config.lr * 0.5 * (1.0 + math.cos(math.pi * min(progress, 1.0)))


def train_detector(
    config: DetectorConfig,
    data: DataSource,
    run: Path,
    *,
    minutes: float | None = None,
    progress: Progress | None = None,
) -> dict[str, Any]:
    """Train, choose the epoch on val, write the run; returns ``detector.json``'s content.

    ``minutes`` bounds the whole command (export and scoring included): no epoch starts that
    the epochs before it say cannot finish, and a step past the limit ends training there.
    """
    started = time.monotonic()
    run = Path(run)
    ds = open_dataset(data)
    append_provenance(run, ds, step="detector-train")
    folder = export_for(ds, run)
    train_views, val_views = CocoViews(folder, "train"), CocoViews(folder, "val")
    torch.manual_seed(config.seed)
    model = build_detector(config, train_views.num_classes)
    params = [p for p in model.parameters() if p.requires_grad]
    optimiser = torch.optim.SGD(
        params, lr=config.lr, momentum=0.9, weight_decay=config.weight_decay
    )
    per_epoch = min(config.epoch_views or len(train_views), len(train_views))
    steps_per_epoch = math.ceil(per_epoch / config.batch_size)
    total = steps_per_epoch * config.epochs
    val = _val_indices(val_views, config.val_views, config.seed)
    rng = np.random.default_rng([config.seed, 0])
    record: dict[str, Any] = {
        "config": config.to_dict(),
        "dataset": dataset_identity(ds),
        "classes": list(ds.class_names),
        # what opens this run as the labeling tool's box proposer (sgdata label --detector)
        "proposer": PROPOSER,
        "epochs": [],
        "best_epoch": None,
        "stopped": "epochs",
    }
    best = -1.0
    step = 0
    for epoch in range(1, config.epochs + 1):
        epoch_start = time.monotonic()
        if minutes is not None and record["epochs"]:
            longest = max(e["seconds"] for e in record["epochs"])
            if epoch_start - started + longest > minutes * 60:
                record["stopped"] = "time"
                break
        order = rng.permutation(len(train_views))[:per_epoch]
        train_views.flips = rng.random(len(train_views)) < 0.5
        model.train()
        losses: list[float] = []
        for start in range(0, len(order), config.batch_size):
            images, targets = collate_detection(
                [train_views[int(i)] for i in order[start : start + config.batch_size]]
            )
            for group in optimiser.param_groups:
                group["lr"] = _lr_at(config, step, total)
            parts = model(images, targets)
            loss = sum(parts.values())
            optimiser.zero_grad(set_to_none=True)
            loss.backward()
            nn.utils.clip_grad_norm_(params, 10.0)  # early FCOS steps spike without it
            optimiser.step()
            losses.append(loss.item())
            step += 1
            if progress is not None:
                progress(
                    "train", step, total, {"epoch": epoch, "loss": float(np.mean(losses[-50:]))}
                )
            if minutes is not None and time.monotonic() - started > minutes * 60:
                record["stopped"] = "time"
                break
        score = coco_score(
            val_views, val, detect(model, val_views, val, progress=_val_progress(progress, epoch))
        )
        record["epochs"].append(
            {
                "epoch": epoch,
                "steps": step,
                "loss": float(np.mean(losses)),
                "val_ap": score.ap,
                "val_ap50": score.ap50,
                "seconds": time.monotonic() - epoch_start,
            }
        )
        if score.ap50 > best:
            best = score.ap50
            record["best_epoch"] = epoch
            save_checkpoint(
                run / DETECTOR,
                {
                    "config": config.to_dict(),
                    "dataset": record["dataset"],
                    "classes": record["classes"],
                    "epoch": epoch,
                    "model": model.state_dict(),
                },
            )
        atomic_write_text(run / DETECTOR_JSON, json.dumps(record, indent=1) + "\n")
        if record["stopped"] == "time":
            break
    record["seconds"] = time.monotonic() - started
    atomic_write_text(run / DETECTOR_JSON, json.dumps(record, indent=1) + "\n")
    return record


def _val_progress(progress: Progress | None, epoch: int) -> Callable[[int, int], None] | None:
    if progress is None:
        return None
    return lambda done, total: progress("val", done, total, {"epoch": epoch})


@dataclass(frozen=True)
class TrainedDetector:
    """A detector restored from its run, in eval mode, with what it was trained on."""

    run: Path
    config: DetectorConfig
    model: nn.Module
    classes: list[str]
    epoch: int
    checkpoint_sha256: str

    def score(self, views: CocoViews, indices: list[int] | None = None) -> CocoScore:
        chosen = list(range(len(views))) if indices is None else indices
        return coco_score(views, chosen, detect(self.model, views, chosen))


def load_detector(run: Path, data: DataSource | None = None) -> TrainedDetector:
    """The detector of ``run`` (checked against ``data``'s vocabulary when given).

    Raises:
        CheckpointError: no detector in ``run``, or one trained on another vocabulary.
    """
    from sgdata.fileio import sha256_file

    path = Path(run) / DETECTOR
    state = load_checkpoint(path)
    if "classes" not in state or "config" not in state:
        raise CheckpointError(f"{path}: not a detector checkpoint (seannet detector train)")
    if data is not None:
        keys = ("num_slots", "vocabulary_sha256")
        check_same_dataset(
            path,
            {k: state["dataset"][k] for k in keys},
            {k: dataset_identity(data)[k] for k in keys},
        )
    config = DetectorConfig.from_dict(state["config"])
    # the weights come from the checkpoint: no ImageNet file is needed to rebuild it
    model = build_detector(
        DetectorConfig.from_dict({**state["config"], "pretrained": None}), len(state["classes"])
    )
    model.load_state_dict(state["model"])
    return TrainedDetector(
        Path(run),
        config,
        model.eval(),
        list(state["classes"]),
        int(state["epoch"]),
        sha256_file(path)[0],
    )
