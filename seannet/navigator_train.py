"""``seannet train-navigator``: render (current, goal) pairs from a dataset's rooms and train.

Pairs are drawn per room from seeded streams (:func:`sgdata.seeds.navigator_pairs_seed`) over
every layout of the room and rendered live (:class:`seannet.live_views.LiveRooms`) at the
dataset's camera, then resized to the navigator's input as the localizers' images are. The
train pairs are rendered once and reused by every epoch (order from
:func:`sgdata.seeds.navigator_order_seed`); val pairs pick ``best.pt``. Cross-entropy, SGD.
"""

from __future__ import annotations

import json
import math
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import torch
from PIL import Image
from torch.nn import functional as F

from seannet.checkpoint import load_checkpoint, save_checkpoint
from seannet.data import IMAGENET_MEAN, IMAGENET_STD, dataset_identity
from seannet.errors import CheckpointError, DataError
from seannet.live_views import LiveRooms
from seannet.motion import NAVIGATOR_ACTIONS
from seannet.navigator import NavigatorConfig, VisualNavigator, draw_pair
from seannet.train import device_for_run
from sgdata.fileio import atomic_write_text
from sgdata.seeds import navigator_init_seed, navigator_order_seed, navigator_pairs_seed, rng_for

__all__ = ["Policy", "load_navigator", "render_pairs", "resize", "to_tensor", "train_navigator"]

LAST, BEST, HISTORY = "last.pt", "best.pt", "history.json"
KIND = "navigator"  # checkpoints say what they hold: a localizer run is refused here


def resize(rgb: np.ndarray, size: int) -> np.ndarray:
    """(H, W, 3) uint8 -> (size, size, 3) uint8, Pillow bilinear (as ImageTransform)."""
    if rgb.shape[:2] == (size, size):
        return rgb
    return np.asarray(Image.fromarray(rgb).resize((size, size), Image.Resampling.BILINEAR))


def to_tensor(images: np.ndarray) -> torch.Tensor:
    """(B, S, S, 3) uint8 -> (B, 3, S, S) float32 normalised with the ImageNet statistics."""
    x = torch.from_numpy(np.array(images, dtype=np.uint8)).permute(0, 3, 1, 2).float() / 255.0
    mean = torch.tensor(IMAGENET_MEAN).view(1, 3, 1, 1)
    std = torch.tensor(IMAGENET_STD).view(1, 3, 1, 1)
    return (x - mean) / std


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
    progress: Callable[[str, int, int, dict[str, float]], None] | None = None,
) -> list[dict[str, float]]:
    """Train a :class:`~seannet.navigator.VisualNavigator` on pairs from ``data``'s rooms.

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
        model.train()
        seen = correct = 0
        total = 0.0
        steps = math.ceil(len(indices) / config.batch_size)
        for step in range(steps):
            batch = indices[step * config.batch_size : (step + 1) * config.batch_size]
            a, b = (to_tensor(x[batch]).to(device) for x in train_set[:2])
            y = torch.from_numpy(train_set[2][batch]).to(device)
            logits = model(a, b)
            loss = F.cross_entropy(logits, y)
            optimizer.zero_grad(set_to_none=True)
            loss.backward()
            optimizer.step()
            seen += len(batch)
            total += float(loss.detach()) * len(batch)
            correct += int((logits.argmax(1) == y).sum())
            if progress is not None:
                progress("train", step + 1, steps, {"loss": total / seen, "acc": correct / seen})
        train_acc = correct / max(seen, 1)
        val_acc = accuracy(model, val_set, config, device) if val_set is not None else train_acc
        history.append(
            {
                "epoch": epoch,
                "train_loss": total / max(seen, 1),
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


@torch.no_grad()
def accuracy(
    model: VisualNavigator,
    pairs: tuple[np.ndarray, np.ndarray, np.ndarray],
    config: NavigatorConfig,
    device: torch.device,
) -> float:
    """Share of pairs whose predicted action is the label."""
    model.eval()
    correct = 0
    for start in range(0, len(pairs[2]), config.batch_size):
        part = slice(start, start + config.batch_size)
        logits = model(to_tensor(pairs[0][part]).to(device), to_tensor(pairs[1][part]).to(device))
        correct += int((logits.argmax(1).cpu() == torch.from_numpy(pairs[2][part])).sum())
    return correct / max(len(pairs[2]), 1)


class Policy:
    """A trained navigator acting on RGB views: :meth:`act` gives an action name."""

    def __init__(self, model: VisualNavigator, config: NavigatorConfig, device: torch.device):
        self.model, self.config, self.device = model.eval(), config, device

    @torch.no_grad()
    def act(self, current: np.ndarray, goal: np.ndarray) -> str:
        """The action (forward / left / right) from (H, W, 3) uint8 current and goal views."""
        s = self.config.image_size
        a = to_tensor(resize(current, s)[None]).to(self.device)
        b = to_tensor(resize(goal, s)[None]).to(self.device)
        return NAVIGATOR_ACTIONS[int(self.model(a, b).argmax(1)[0])]


def load_navigator(run: Path) -> Policy:
    """``run/best.pt`` of ``seannet train-navigator`` as a :class:`Policy`.

    Raises:
        CheckpointError: no checkpoint, or not a navigator's.
    """
    path = run / BEST
    state = load_checkpoint(path)
    if state.get("kind") != KIND:
        raise CheckpointError(
            f"{path}: not a navigator checkpoint (train one with train-navigator)"
        )
    config = NavigatorConfig(**state["config"])
    device = device_for_run()
    model = VisualNavigator(config.encoder, hidden=config.hidden).to(device)
    model.load_state_dict(state["model"])
    return Policy(model, config, device)
