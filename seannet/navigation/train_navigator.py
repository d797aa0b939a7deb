"""``seannet train-navigator``: render (current, goal) pairs from a dataset's rooms and train.

Pairs are drawn per room from seeded streams (:func:`sgdata.seeds.navigator_pairs_seed`) over
every layout of the room and rendered live (:class:`seannet.data.live_views.LiveRooms`) at the
dataset's camera, then resized to the navigator's input as the localizers' images are. The
train pairs are rendered once and reused by every epoch (order from
:func:`sgdata.seeds.navigator_order_seed`); val pairs pick ``best.pt``. Cross-entropy, SGD.
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

from seannet.data.datasets import dataset_identity
from seannet.data.live_views import LiveRooms
from seannet.errors import CheckpointError, DataError
from seannet.navigation.navigator import (
    KIND,
    NavigatorConfig,
    VisualNavigator,
    draw_pair,
    navigator_inputs,
    resize,
)
from seannet.training.loop import Progress, collect, train_one_epoch
from seannet.training.runs import BEST, HISTORY, LAST, device_for_run, save_checkpoint
from sgdata.fileio import atomic_write_text
from sgdata.seeds import navigator_init_seed, navigator_order_seed, navigator_pairs_seed, rng_for

__all__ = ["accuracy", "render_pairs", "train_navigator"]


def render_pairs(
    live: LiveRooms, split: str, count: int, config: NavigatorConfig
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``count`` pairs over the rooms of ``split``: (current, goal) (N, S, S, 3) uint8, labels.

    Raises:
        DataError: the split has no room, or no room allows a pair.
    """
    rooms = list(live.dataset.rooms(split)) if split in live.dataset.splits else []
    if not rooms:
        raise DataError(f"{live.data}: split {split!r} has no room to draw navigator pairs from")
    per_room = math.ceil(count / len(rooms))
    draws: list[tuple[str, int, Any, Any, int]] = []
    for room_id in rooms:
        rng = rng_for(navigator_pairs_seed(config.seed, split, room_id))
        layouts = live.layouts(room_id)
        wanted = [layouts[int(k)] for k in rng.integers(len(layouts), size=per_room)]
        for layout in sorted(set(wanted)):
            live.load(room_id, layout)
            for _ in range(wanted.count(layout)):
                pair = draw_pair(
                    live.grid.reachable,
                    rng,
                    max_side=config.max_side,
                    max_forward=config.max_forward,
                )
                if pair is not None:
                    draws.append((room_id, layout, *pair))
    if not draws:
        raise DataError(f"{live.data}: no reachable pair in the rooms of split {split!r}")
    draws = draws[:count]
    s = config.image_size
    current = np.zeros((len(draws), s, s, 3), dtype=np.uint8)
    goal = np.zeros_like(current)
    labels = np.zeros(len(draws), dtype=np.int64)
    for n, (room_id, layout, a, b, label) in enumerate(draws):
        live.load(room_id, layout)
        current[n] = resize(live.image(*a), s)
        goal[n] = resize(live.image(*b), s)
        labels[n] = label
    return current, goal, labels


def train_navigator(
    config: NavigatorConfig,
    data: Path,
    out: Path,
    *,
    pretrained: Path | None = None,
    progress: Progress | None = None,
) -> list[dict[str, float]]:
    """Train a :class:`~seannet.navigation.navigator.VisualNavigator` on pairs from ``data``'s
    rooms.

    Writes ``last.pt`` every epoch, ``best.pt`` when val accuracy improves (train accuracy
    without val pairs), ``history.json``. Returns the history.

    Raises:
        CheckpointError: ``out`` holds a run already.
        DataError: the dataset is missing, or a split has no room to draw from.
        RenderError: EGL cannot start.
    """
    if (out / LAST).exists():
        raise CheckpointError(f"{out}: holds a navigator run already; pick another --out")
    identity = dataset_identity(data)
    if progress is not None:
        progress("render", 0, 1, {})
    with LiveRooms(data) as live:
        train_set = render_pairs(live, "train", config.train_pairs, config)
        val_set = render_pairs(live, "val", config.val_pairs, config) if config.val_pairs else None
    device = device_for_run()
    torch.manual_seed(navigator_init_seed(config.seed))
    model = VisualNavigator(config.encoder, hidden=config.hidden, pretrained=pretrained).to(device)
    optimizer = torch.optim.SGD(model.parameters(), lr=config.lr, momentum=config.momentum)
    out.mkdir(parents=True, exist_ok=True)
    history: list[dict[str, float]] = []
    best = -1.0
    for epoch in range(config.epochs):
        started = time.perf_counter()
        order = torch.Generator().manual_seed(navigator_order_seed(config.seed, epoch))
        indices = torch.randperm(len(train_set[2]), generator=order).numpy()
        batches = _pair_batches(train_set, indices, config.batch_size)
        steps = math.ceil(len(indices) / config.batch_size)
        loss, train_acc = train_one_epoch(
            model,
            batches,
            _cross_entropy_step(model, device),
            optimizer,
            total=steps,
            progress=progress,
        )
        val_acc = accuracy(model, val_set, config, device) if val_set is not None else train_acc
        history.append(
            {
                "epoch": epoch,
                "train_loss": loss,
                "train_accuracy": train_acc,
                "val_accuracy": val_acc,
                "seconds": time.perf_counter() - started,
            }
        )
        state = {
            "kind": KIND,
            "config": config.to_dict(),
            "dataset": identity,
            "epoch": epoch,
            "model": model.state_dict(),
            "history": history,
            "best": max(best, val_acc),
        }
        if val_acc > best:
            best = val_acc
            save_checkpoint(out / BEST, state)
        save_checkpoint(out / LAST, state)
        atomic_write_text(out / HISTORY, json.dumps(history, indent=2))
    return history


def accuracy(
    model: VisualNavigator,
    pairs: tuple[np.ndarray, np.ndarray, np.ndarray],
    config: NavigatorConfig,
    device: torch.device,
) -> float:
    """Share of pairs whose predicted action is the label."""
    if not len(pairs[2]):
        return 0.0
    order = np.arange(len(pairs[2]))
    batches = _pair_batches(pairs, order, config.batch_size)
    right = collect(model, batches, lambda batch: _logits_and_labels(model, device, batch)[2])
    return float(right.float().mean())


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
    a, b = (navigator_inputs(x).to(device) for x in batch[:2])
    y = torch.from_numpy(batch[2]).to(device)
    logits = model(a, b)
    return logits, y, (logits.argmax(1) == y)


def _cross_entropy_step(model: VisualNavigator, device: torch.device) -> Callable:
    def step(batch: tuple[np.ndarray, ...]) -> tuple[torch.Tensor, torch.Tensor]:
        logits, y, right = _logits_and_labels(model, device, batch)
        return F.cross_entropy(logits, y), right.detach()

    return step
