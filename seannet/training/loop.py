"""The one training loop and the one evaluation loop (as torchvision's references keep one
``train_one_epoch`` and one ``evaluate``), with the triplet steps every SeanNet run uses.

What a batch means is the caller's: a *step* turns a batch into ``(loss, correct)`` (the mean
loss and a per-sample bool tensor), an *output* function turns a batch into a tensor. The
triplet trainer, ``compare``'s calibration, the navigator trainer and every evaluation
(triplet accuracy, embedding a split, a navigator's action accuracy) run through these two.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import Any

import torch
from torch import Tensor
from torch.nn import functional as F

from seannet.model.loss import TripletLoss, similarity

__all__ = [
    "Progress",
    "collect",
    "embed_batch",
    "train_one_epoch",
    "triplet_correct",
    "triplet_step",
]

# progress(phase, step, total, metrics): called once per batch
Progress = Callable[[str, int, int, dict[str, float]], None]


def train_one_epoch(
    model: torch.nn.Module,
    batches: Iterable[Any],
    step: Callable[[Any], tuple[Tensor, Tensor]],
    optimizer: torch.optim.Optimizer,
    *,
    total: int = 0,
    progress: Progress | None = None,
) -> tuple[float, float]:
    """One pass of ``step`` + backward + optimiser step over ``batches`` (train mode).

    Returns:
        ``(mean loss, accuracy)`` over the samples seen (each batch weighted by its size).
    """
    model.train()
    total_loss = 0.0
    correct = seen = 0
    for number, batch in enumerate(batches, 1):
        loss, right = step(batch)
        optimizer.zero_grad(set_to_none=True)
        loss.backward()
        optimizer.step()
        size = len(right)
        total_loss += float(loss.detach()) * size
        correct += int(right.sum())
        seen += size
        if progress is not None:
            metrics = {"loss": total_loss / seen, "acc": correct / seen}
            progress("train", number, total or number, metrics)
    return total_loss / max(seen, 1), correct / max(seen, 1)


@torch.no_grad()
def collect(
    model: torch.nn.Module,
    batches: Iterable[Any],
    output: Callable[[Any], Tensor],
    *,
    phase: str = "val",
    total: int = 0,
    progress: Progress | None = None,
) -> Tensor:
    """``output(batch)`` of every batch in eval mode, concatenated on the CPU (dim 0)."""
    model.eval()
    parts = []
    for number, batch in enumerate(batches, 1):
        parts.append(output(batch).cpu())
        if progress is not None:
            progress(phase, number, total or number, {})
    return torch.cat(parts) if parts else torch.zeros(0)


def triplet_step(
    model: torch.nn.Module, loss_fn: TripletLoss, device: torch.device
) -> Callable[[Any], tuple[Tensor, Tensor]]:
    """The training step on a collated triplet batch ``(A, P, N, info)``."""

    def step(batch: Any) -> tuple[Tensor, Tensor]:
        anchor, positive, negative = (b.to(device) for b in batch[:3])
        a, p, n = model.embed(anchor), model.embed(positive), model.embed(negative)
        loss = loss_fn(a, p, n)  # (A, P, N): the authors' baselines were fed (A, N, P)
        with torch.no_grad():
            right = similarity(a, p) > similarity(a, n)
        return loss, right

    return step


def triplet_correct(model: torch.nn.Module, device: torch.device) -> Callable[[Any], Tensor]:
    """Per triplet of a collated batch: S(A, P) > S(A, N)."""

    def output(batch: Any) -> Tensor:
        a, p, n = (model.embed(b.to(device)) for b in batch[:3])
        return similarity(a, p) > similarity(a, n)

    return output


def embed_batch(model: torch.nn.Module, device: torch.device) -> Callable[[Any], Tensor]:
    """Unit embeddings of a collated view batch ``(views, info)``."""

    def output(batch: Any) -> Tensor:
        return F.normalize(model.embed(batch[0].to(device)), dim=1)

    return output
