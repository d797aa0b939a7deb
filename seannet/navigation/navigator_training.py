"""``seannet train-navigator``: train the visual navigator on cached (current, goal) pairs.

Train pairs come from every layout of the train rooms, val pairs from the val rooms
(:func:`seannet.navigation.pairs.render_pairs`, rendered once into a cache and reused by every
epoch and by later runs with the same key). The batch order of each epoch comes from
:func:`seannet.seeds.navigator_order_seed`; the training goes through
:func:`seannet.training.loop.train_one_epoch` and the val accuracy through
:func:`seannet.training.loop.collect`. ``best.pt`` is the epoch of the best val accuracy, which
is also reported per action and per goal distance. Cross-entropy, SGD. What the test changes
can be trained for: goal views of another layout (``cross_layout``, in the pairs) and light
jitter per view (``jitter``, per epoch from :func:`seannet.seeds.navigator_jitter_seed`).
"""

from __future__ import annotations

import json
import math
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
import torch
from torch.nn import functional as F

from seannet.data.live_views import LiveRooms
from seannet.data.opening import dataset_identity, open_dataset
from seannet.errors import CheckpointError
from seannet.navigation.motion import NAVIGATOR_ACTIONS
from seannet.navigation.navigator import KIND, NavigatorConfig, VisualNavigator, navigator_inputs
from seannet.navigation.pairs import PairSet, render_pairs
from seannet.provenance import append_provenance
from seannet.seeds import navigator_init_seed, navigator_jitter_seed, navigator_order_seed
from seannet.training.loop import Progress, collect, train_one_epoch
from seannet.training.runs import BEST, HISTORY, LAST, device_for_run, save_checkpoint
from sgdata.fileio import atomic_write_text
from sgdata.seeds import rng_for

__all__ = ["fit_navigator", "jitter", "pair_accuracy", "train_navigator"]


def train_navigator(
    config: NavigatorConfig,
    data: Path,
    out: Path,
    *,
    cache: Path | None = None,
    pretrained: Path | None = None,
    progress: Progress | None = None,
) -> list[dict[str, Any]]:
    """Train a :class:`~seannet.navigation.navigator.VisualNavigator` on pairs from ``data``'s
    rooms.

    Args:
        cache: where rendered pairs are kept and found (None: render them, keep nothing).

    Writes ``last.pt`` every epoch, ``best.pt`` when val accuracy improves (train accuracy
    without val pairs), ``history.json`` (per epoch: loss, accuracies, val accuracy per
    action and per goal distance). Returns the history.

    Raises:
        CheckpointError: ``out`` holds a run already.
        DataError: the dataset is missing, or a split has no room to draw from.
        RenderError: EGL cannot start.
    """
    if (out / LAST).exists():
        raise CheckpointError(f"{out}: holds a navigator run already; pick another --out")
    dataset = open_dataset(data)  # the manifest read once: identity, provenance, live rooms
    identity = dataset_identity(dataset)
    append_provenance(out, dataset, step="train-navigator")
    if progress is not None:
        progress("render", 0, 1, {})
    with LiveRooms(dataset) as live:
        train_set = render_pairs(
            live, "train", config.train_pairs, config, cache=cache, identity=identity
        )
        val_set = (
            render_pairs(live, "val", config.val_pairs, config, cache=cache, identity=identity)
            if config.val_pairs
            else None
        )
    return fit_navigator(
        config, train_set, val_set, out, identity=identity, pretrained=pretrained, progress=progress
    )


def fit_navigator(
    config: NavigatorConfig,
    train_set: PairSet,
    val_set: PairSet | None,
    out: Path,
    *,
    identity: dict[str, Any],
    pretrained: Path | None = None,
    progress: Progress | None = None,
) -> list[dict[str, Any]]:
    """Train on rendered pairs (the second half of :func:`train_navigator`; a comparison of
    navigator variants fits each on the same pairs). Writes and returns as it does."""
    if (out / LAST).exists():
        raise CheckpointError(f"{out}: holds a navigator run already; pick another --out")
    device = device_for_run()
    torch.manual_seed(navigator_init_seed(config.seed))
    model = VisualNavigator(
        config.encoder, hidden=config.hidden, pretrained=pretrained, fusion=config.fusion
    ).to(device)
    optimizer = torch.optim.SGD(model.parameters(), lr=config.lr, momentum=config.momentum)
    out.mkdir(parents=True, exist_ok=True)
    history: list[dict[str, Any]] = []
    best = -1.0
    for epoch in range(config.epochs):
        started = time.perf_counter()
        order = torch.Generator().manual_seed(navigator_order_seed(config.seed, epoch))
        indices = torch.randperm(len(train_set), generator=order).numpy()
        batches = _pair_batches(train_set.arrays(), indices, config.batch_size)
        if config.jitter:
            light = rng_for(navigator_jitter_seed(config.seed, epoch))
            batches = (
                (jitter(a, light, config.jitter), jitter(b, light, config.jitter), y)
                for a, b, y in batches
            )
        loss, train_acc = train_one_epoch(
            model,
            batches,
            _cross_entropy_step(model, device),
            optimizer,
            total=math.ceil(len(indices) / config.batch_size),
            progress=progress,
        )
        entry: dict[str, Any] = {
            "epoch": epoch,
            "train_loss": loss,
            "train_accuracy": train_acc,
            "train_pairs": len(train_set),
        }
        if val_set is not None:
            entry.update(pair_accuracy(model, val_set, config, device))
        else:
            entry["val_accuracy"] = train_acc
        entry["seconds"] = time.perf_counter() - started
        history.append(entry)
        val_acc = entry["val_accuracy"]
        state = {
            "kind": KIND,
            "config": config.to_dict(),
            "dataset": identity,
            "epoch": epoch,
            "model": model.state_dict(),
            "pretrained": None if pretrained is None else str(pretrained),  # ImageNet init
            "history": history,
            "best": max(best, val_acc),
        }
        if val_acc > best:
            best = val_acc
            save_checkpoint(out / BEST, state)
        save_checkpoint(out / LAST, state)
        atomic_write_text(out / HISTORY, json.dumps(history, indent=2))
    return history


def pair_accuracy(
    model: VisualNavigator, pairs: PairSet, config: NavigatorConfig, device: torch.device
) -> dict[str, Any]:
    """``val_accuracy`` (share of pairs whose predicted action is the label), and the same
    per action (``val_by_action``) and per goal distance in cells (``val_by_distance``),
    each ``{name: [accuracy, pairs]}``."""
    if not len(pairs):
        return {"val_accuracy": 0.0, "val_pairs": 0, "val_by_action": {}, "val_by_distance": {}}
    order = np.arange(len(pairs))
    batches = _pair_batches(pairs.arrays(), order, config.batch_size)
    right = collect(model, batches, lambda batch: _logits_and_labels(model, device, batch)[2])
    right = right.numpy().astype(bool)

    def by(keys: np.ndarray) -> dict[str, list[float | int]]:
        return {
            str(k): [float(right[keys == k].mean()), int((keys == k).sum())]
            for k in sorted(set(keys.tolist()))
        }

    names = np.array(NAVIGATOR_ACTIONS)[pairs.labels]
    return {
        "val_accuracy": float(right.mean()),
        "val_pairs": len(pairs),
        "val_by_action": by(names),
        "val_by_distance": by(pairs.distances()),
    }


def jitter(images: np.ndarray, rng: np.random.Generator, amount: float) -> np.ndarray:
    """(B, S, S, 3) uint8 views, each with its brightness and contrast scaled by its own
    factors within ``1 +- amount``: the light of another layout."""
    x = images.astype(np.float32)
    size = (len(x), 1, 1, 1)
    brightness = rng.uniform(1 - amount, 1 + amount, size=size)
    contrast = rng.uniform(1 - amount, 1 + amount, size=size)
    mean = x.mean(axis=(1, 2, 3), keepdims=True)
    return np.clip((x - mean) * contrast + mean * brightness, 0, 255).round().astype(np.uint8)


def _pair_batches(
    pairs: tuple[np.ndarray, np.ndarray, np.ndarray], order: np.ndarray, size: int
) -> Iterator[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    for start in range(0, len(order), size):
        pick = order[start : start + size]
        yield pairs[0][pick], pairs[1][pick], pairs[2][pick]


def _logits_and_labels(
    model: VisualNavigator, device: torch.device, batch: tuple[np.ndarray, ...]
) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """(logits, labels, correct) of a batch of (current, goal, label) arrays."""
    a, b = (navigator_inputs(x, model.encoder_name).to(device) for x in batch[:2])
    y = torch.from_numpy(batch[2]).to(device)
    logits = model(a, b)
    return logits, y, (logits.argmax(1) == y)


def _cross_entropy_step(model: VisualNavigator, device: torch.device) -> Callable:
    def step(batch: tuple[np.ndarray, ...]) -> tuple[torch.Tensor, torch.Tensor]:
        logits, y, right = _logits_and_labels(model, device, batch)
        return F.cross_entropy(logits, y), right.detach()

    return step
