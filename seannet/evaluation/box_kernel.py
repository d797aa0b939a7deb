"""A box kernel learned from the train triplets: the scene term of ``MODEL+box-kernel``.

The hand-made overlap (:mod:`seannet.evaluation.box_overlap`) counts every slot alike. But a
chair or a mug moves between layouts and a fridge does not: the kernel learns how much each
slot counts, ``w_s`` (softplus of a free weight, 1 at the start: the overlap itself), from the
train split's triplets and nothing else.

``S_kernel(a, b) = sum_s w_s IoU(a_s, b_s) [s in both] / sum_s w_s [s in either]``: the
overlap's shape (a weighted mean over the slots present in either view, in [0, 1]), so
``MODEL+box-kernel`` scores ``S_image + lambda * S_kernel`` with lambda chosen on val
(:func:`seannet.evaluation.box_overlap.choose_box_weight`), like ``MODEL+boxes``. It is fit by
full-batch Adam on a logistic triplet loss from a fixed start: the same boxes give the same
kernel. Only the slots present in either view are stored, so memory grows with the objects in
view, not with the slot count.

Box-only accuracy on the val triplets of `medium` (seed 74113): the overlap 80.0 %, the kernel
83.2 %. A kernel that also learned how alike two boxes are (an MLP of IoU, centre shift and
size ratio) scored no better on val (82.8 %) and was dropped.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import torch
from torch import Tensor, nn

from seannet.evaluation.box_overlap import SlotBoxes

__all__ = ["BoxKernel", "SlotPairs", "fit_box_kernel", "slot_pairs"]

_STEPS = 300
_CHUNK = 2048  # pairs per vectorised block, as in box_overlap
_LR = 0.05
_SHARPNESS = 20.0  # the logistic loss's scale: S differences of ~0.05 decide a triplet
_INIT_WEIGHT = float(np.log(np.e - 1.0))  # softplus(_INIT_WEIGHT) = 1: every slot alike


@dataclass(frozen=True)
class SlotPairs:
    """The slots present in either view of each pair: ``K`` rows over ``P`` pairs."""

    pair: Tensor  # (K,) int64: which pair
    slot: Tensor  # (K,) int64
    iou: Tensor  # (K,) float32; 0 where the slot is in one view only
    pairs: int  # P


def slot_pairs(boxes: SlotBoxes, first: Sequence[str], second: Sequence[str]) -> SlotPairs:
    """The IoU of each slot present in either view of each pair (first[k], second[k])."""
    a_all = np.array([boxes.index[o] for o in first], dtype=np.int64)
    b_all = np.array([boxes.index[o] for o in second], dtype=np.int64)
    pairs, slots, ious = [], [], []
    for start in range(0, len(a_all), _CHUNK):
        a = boxes.boxes[a_all[start : start + _CHUNK]]
        b = boxes.boxes[b_all[start : start + _CHUNK]]
        in_a, in_b = ~np.isnan(a[..., 0]), ~np.isnan(b[..., 0])
        pair, slot = np.nonzero(in_a | in_b)
        both = in_a[pair, slot] & in_b[pair, slot]
        a, b = np.nan_to_num(a[pair, slot]).astype(np.float64), np.nan_to_num(b[pair, slot])
        area = lambda x: (x[:, 2] - x[:, 0]) * (x[:, 3] - x[:, 1])  # noqa: E731
        inter = np.prod(
            np.clip(np.minimum(a[:, 2:], b[:, 2:]) - np.maximum(a[:, :2], b[:, :2]), 0, None),
            axis=1,
        )
        union = area(a) + area(b) - inter
        ious.append(np.where(both & (union > 0), inter / np.where(union > 0, union, 1.0), 0.0))
        pairs.append(pair + start)
        slots.append(slot)
    return SlotPairs(
        pair=torch.from_numpy(np.concatenate([np.zeros(0, np.int64), *pairs]).astype(np.int64)),
        slot=torch.from_numpy(np.concatenate([np.zeros(0, np.int64), *slots]).astype(np.int64)),
        iou=torch.from_numpy(np.concatenate([np.zeros(0), *ious]).astype(np.float32)),
        pairs=len(first),
    )


class BoxKernel(nn.Module):
    """``S_kernel``: the IoU of each slot's boxes, weighted per slot (module docstring)."""

    def __init__(self, num_slots: int) -> None:
        super().__init__()
        self.slot_weight = nn.Parameter(torch.full((num_slots,), _INIT_WEIGHT))

    def forward(self, pairs: SlotPairs) -> Tensor:
        """(P,) scores in [0, 1]; 0 for a pair with no slot in either view."""
        weight = nn.functional.softplus(self.slot_weight)[pairs.slot]
        num = torch.zeros(pairs.pairs).index_add_(0, pairs.pair, weight * pairs.iou)
        den = torch.zeros(pairs.pairs).index_add_(0, pairs.pair, weight)
        return num / den.clamp_min(1e-6)

    def score(self, pairs: SlotPairs) -> np.ndarray:
        """:meth:`forward` without gradients, as float64 numpy."""
        with torch.no_grad():
            return self(pairs).double().numpy()


def fit_box_kernel(
    positive: SlotPairs, negative: SlotPairs, num_slots: int
) -> tuple[BoxKernel, float]:
    """The kernel fit on triplets (anchor-positive and anchor-negative pairs, row-aligned),
    and its accuracy on them."""
    kernel = BoxKernel(num_slots)
    optimizer = torch.optim.Adam(kernel.parameters(), lr=_LR)
    for _ in range(_STEPS):
        gap = kernel(positive) - kernel(negative)
        loss = nn.functional.softplus(-_SHARPNESS * gap).mean()
        optimizer.zero_grad()
        loss.backward()
        optimizer.step()
    accuracy = float(np.mean(kernel.score(positive) > kernel.score(negative)))
    return kernel.eval(), accuracy
