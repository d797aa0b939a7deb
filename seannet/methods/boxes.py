"""Boxes in a method's vectors: every slot's box as 4 numbers (-1 where the slot is empty),
scored by the hand-made overlap or a slot kernel learned on triplets."""

from __future__ import annotations

import numpy as np
import torch
from torch import Tensor

from seannet.evaluation.box_kernel import BoxKernel, fit_box_kernel, slot_pairs
from seannet.evaluation.box_overlap import SlotBoxes

__all__ = ["ABSENT", "box_scores", "box_vectors", "fit_kernel", "triplet_box_scores"]

ABSENT = -1.0  # a slot's four numbers when the view has no object in it


def box_vectors(slot_boxes: Tensor) -> Tensor:
    """(N, M, 4) boxes by slot (NaN where empty) as (N, 4 M) vectors (:data:`ABSENT` there)."""
    return torch.nan_to_num(slot_boxes, nan=ABSENT).flatten(1)


def _slot_boxes(a: np.ndarray, b: np.ndarray) -> tuple[SlotBoxes, list[str], list[str]]:
    """Two (P, 4 M) box-vector arrays as one :class:`SlotBoxes` and the ids of each side."""
    both = np.concatenate([a, b]).astype(np.float32).reshape(len(a) + len(b), -1, 4)
    both[both[..., 0] == ABSENT] = np.nan
    view, slot = np.nonzero(~np.isnan(both[..., 0]))
    offsets = np.concatenate([[0], np.cumsum(np.bincount(view, minlength=len(both)))])
    ids = [str(k) for k in range(len(both))]
    boxes = SlotBoxes(ids, offsets, slot, both[view, slot], both.shape[1])
    return boxes, ids[: len(a)], ids[len(a) :]


def box_scores(a: Tensor, b: Tensor, kernel: BoxKernel | None = None) -> Tensor:
    """(P,) scores in [0, 1] of row pairs of box vectors: the mean IoU over the slots present
    in either view (:class:`~seannet.evaluation.box_overlap.SlotBoxes`), or the kernel's."""
    boxes, first, second = _slot_boxes(a.detach().cpu().numpy(), b.detach().cpu().numpy())
    if kernel is None:
        return torch.from_numpy(boxes.overlap(first, second)).float()
    return torch.from_numpy(kernel.score(slot_pairs(boxes, first, second))).float()


def triplet_box_scores(
    vectors: Tensor, triplets: np.ndarray, kernel: BoxKernel | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """(S_box(A, P), S_box(A, N)) of (T, 3) triplets over rows of ``vectors``."""
    a, p, n = (vectors[torch.from_numpy(triplets[:, k])] for k in range(3))
    return box_scores(a, p, kernel).double().numpy(), box_scores(a, n, kernel).double().numpy()


def fit_kernel(vectors: Tensor, triplets: np.ndarray) -> tuple[BoxKernel, float]:
    """A slot kernel fit on train triplets of box vectors, and its train accuracy."""
    num_slots = vectors.shape[1] // 4
    a, p, n = (vectors[torch.from_numpy(triplets[:, k])].numpy() for k in range(3))
    boxes, first, second = _slot_boxes(a, p)
    positive = slot_pairs(boxes, first, second)
    boxes, first, second = _slot_boxes(a, n)
    negative = slot_pairs(boxes, first, second)
    return fit_box_kernel(positive, negative, num_slots)
