"""The trainer: triplet loss on a dataset's cascaded triplets, validation every epoch.

Resumable at epoch boundaries and exactly so: every epoch draws its batch order and its
dropout masks from seeds derived from the config seed and the epoch, never from state carried
over from earlier epochs, so a run resumed after a kill continues as if never stopped.
"""

from __future__ import annotations

import json
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import torch
from torch.utils.data import DataLoader, Subset

from seannet.data.datasets import ImageTransform, TripletDataset, collate_triplets
from seannet.data.opening import DataSource, dataset_identity, open_dataset
from seannet.errors import CheckpointError
from seannet.model.loss import TripletLoss
from seannet.model.pretrained import check_pretrained_request
from seannet.provenance import append_provenance
from seannet.seeds import epoch_dropout_seed, epoch_order_seed, init_seed
from seannet.training.config import TrainConfig
from seannet.training.loop import Progress, collect, train_one_epoch, triplet_correct, triplet_step
from seannet.training.runs import (
    BEST,
    HISTORY,
    LAST,
    build_for_dataset,
    check_same_dataset,
    device_for_run,
    load_checkpoint,
    save_checkpoint,
)
from sgdata.fileio import atomic_write_text

__all__ = ["EpochResult", "evaluate_triplets", "param_groups", "train", "train_loader"]


@dataclass(frozen=True)
class EpochResult:
    """What one epoch did."""

    epoch: int
    train_loss: float
    train_accuracy: float
    val_accuracy: float
    lr: float
    seconds: float


def param_groups(model: torch.nn.Module, config: TrainConfig) -> list[dict[str, Any]]:
    """Optimiser groups: the pretrained-shape image network (``backbone``, ``head``) at
    ``lr``, every layer SeanNet adds (object fcn, GCN, norms, fusion) at
    ``lr * new_layers_lr_scale``; baselines are one group."""
    image_net, added = [], []
    for name, param in model.named_parameters():
        (image_net if name.startswith(("backbone.", "head.", "encoder.")) else added).append(param)
    groups = [{"params": image_net, "lr": config.lr}]
    if added:
        groups.append({"params": added, "lr": config.lr * config.new_layers_lr_scale})
    return groups


def train(
    config: TrainConfig,
    data: DataSource,
    out: Path,
    *,
    resume: bool = False,
    pretrained: Path | None = None,
    pretrained_sha256: str | None = None,
    progress: Progress | None = None,
) -> list[EpochResult]:
    """Train ``config.model`` on ``data`` (an opened dataset or its root: opened once here)
    into the run directory ``out``.

    Writes ``last.pt`` after every epoch (whole: model, optimiser and schedule, to resume),
    ``best.pt`` when validation accuracy improves (the model only: what evaluation reads) and
    ``history.json``. ``progress(phase, step, total, metrics)`` is called per batch.

    Raises:
        CheckpointError: ``resume`` without a checkpoint, a different config, or a different
            dataset than the checkpoint's; ``out`` holds a run and ``resume`` is off.
        DataError: the dataset is missing or malformed.
        ModelError: ``pretrained_sha256`` without ``pretrained``, or not 64 hex digits.
    """
    check_pretrained_request(pretrained, pretrained_sha256)
    dataset = open_dataset(data)
    identity = dataset_identity(dataset)
    transform = ImageTransform.for_model(config.model.image_size, config.model.image_family)
    train_set = TripletDataset(dataset, "train", transform=transform)
    val_set = TripletDataset(dataset, "val", transform=transform)
    device = device_for_run()
    torch.manual_seed(init_seed(config.seed))  # the initial weights
    model = build_for_dataset(
        config, dataset, pretrained=pretrained, pretrained_sha256=pretrained_sha256
    ).to(device)
    optimizer = torch.optim.SGD(param_groups(model, config), lr=config.lr, momentum=config.momentum)
    schedule = torch.optim.lr_scheduler.StepLR(optimizer, config.decay_every, config.lr_decay)
    history: list[dict[str, Any]] = []
    best = -1.0
    start_epoch = 0
    last = out / LAST
    if resume:
        state = load_checkpoint(last)
        check_same_dataset(last, state["dataset"], identity)
        # a resumed run may be given more epochs; everything else must match
        saved = {**TrainConfig.from_dict(state["config"]).to_dict(), "epochs": config.epochs}
        if saved != config.to_dict():
            raise CheckpointError(f"{last}: was trained with another config; resume with that one")
        model.load_state_dict(state["model"])
        optimizer.load_state_dict(state["optimizer"])
        schedule.load_state_dict(state["schedule"])
        history, best, start_epoch = state["history"], state["best"], state["epoch"] + 1
    elif last.exists():
        raise CheckpointError(f"{out}: holds a run already; pass --resume or pick another --out")
    append_provenance(out, dataset, step="resume" if resume else "train")  # makes ``out``
    loss_fn = TripletLoss(config.margin)
    results = [EpochResult(**h) for h in history]
    for epoch in range(start_epoch, config.epochs):
        started = time.perf_counter()
        lr = optimizer.param_groups[0]["lr"]
        loader = train_loader(config, train_set, epoch)
        step = triplet_step(model, loss_fn, device)
        loss, accuracy = train_one_epoch(
            model, loader, step, optimizer, total=len(loader), progress=progress
        )
        val_accuracy = evaluate_triplets(config, model, val_set, device, progress)
        schedule.step()
        result = EpochResult(epoch, loss, accuracy, val_accuracy, lr, time.perf_counter() - started)
        results.append(result)
        history.append(result.__dict__)
        state = {
            "config": config.to_dict(),
            "dataset": identity,
            "epoch": epoch,
            "model": model.state_dict(),
            "optimizer": optimizer.state_dict(),
            "schedule": schedule.state_dict(),
            "history": history,
            "best": max(best, val_accuracy),
        }
        if val_accuracy > best:
            best = val_accuracy
            save_checkpoint(out / BEST, {k: v for k, v in state.items() if k not in _RESUME_ONLY})
        save_checkpoint(last, state)
        atomic_write_text(out / HISTORY, json.dumps(history, indent=2))
    return results


# what only resuming reads: best.pt leaves it out (the momentum buffers double its size)
_RESUME_ONLY = ("optimizer", "schedule")


def train_loader(config: TrainConfig, dataset: TripletDataset, epoch: int) -> DataLoader:
    """Epoch ``epoch``'s batches: an order drawn from the config seed and the epoch (never
    from state carried over), cut to ``max_train_batches``; seeds this epoch's dropout."""
    order = torch.Generator().manual_seed(epoch_order_seed(config.seed, epoch))
    indices = torch.randperm(len(dataset), generator=order).tolist()
    if config.max_train_batches:
        indices = indices[: config.max_train_batches * config.batch_size]
    torch.manual_seed(epoch_dropout_seed(config.seed, epoch))  # dropout masks of this epoch
    return DataLoader(
        Subset(dataset, indices),
        batch_size=config.batch_size,
        collate_fn=collate_triplets,
        num_workers=config.num_workers,
        persistent_workers=False,
    )


def evaluate_triplets(
    config: TrainConfig,
    model: torch.nn.Module,
    dataset: TripletDataset,
    device: torch.device,
    progress: Progress | None = None,
) -> float:
    """Share of triplets with S(A, P) > S(A, N) (on ``config.max_val_triplets`` of them,
    evenly spaced over the split, when that is set)."""
    subset: torch.utils.data.Dataset = dataset
    if 0 < config.max_val_triplets < len(dataset):
        picks = np.unique(np.linspace(0, len(dataset) - 1, config.max_val_triplets).round())
        subset = Subset(dataset, picks.astype(int).tolist())
    loader = DataLoader(
        subset,
        batch_size=config.batch_size,
        collate_fn=collate_triplets,
        num_workers=config.num_workers,
    )
    right = collect(
        model, loader, triplet_correct(model, device), total=len(loader), progress=progress
    )
    return float(right.float().mean()) if len(right) else 0.0
