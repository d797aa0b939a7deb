"""The hand-made box overlap of two views, and the strongest simple baseline built on it.

``S_box(a, b)``: the mean, over the slots present in either view, of the IoU of that slot's
boxes in the two views (0 where the slot is in one view only). A slot is a class's instance
as the model sees it (DESIGN §8), so this is "the same objects' boxes" with no learning.
``resnet18+boxes`` (any ``MODEL+boxes``) scores a pair ``S_image + lambda * S_box``, with
``lambda`` chosen on the validation triplets (:func:`choose_box_weight`): the strongest simple
baseline every headline table holds (DESIGN §12).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

__all__ = [
    "BOX_WEIGHTS",
    "SlotBoxes",
    "choose_box_weight",
]

# lambda's grid: wide enough that val never picks its edge on `medium` (it picked 5 of 0.1-5)
BOX_WEIGHTS = (0.0, 0.1, 0.2, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0)
_CHUNK = 2048  # pairs per vectorised block: (2048, M, 4) float32 is 8 MB at M = 256


class SlotBoxes:
    """Every view's box per slot: (N, M, 4) float32, NaN where the slot is empty."""

    def __init__(
        self,
        obs_ids: Sequence[str],
        offsets: np.ndarray,
        slots: np.ndarray,
        boxes: np.ndarray,
        num_slots: int,
    ) -> None:
        self.index = {o: k for k, o in enumerate(obs_ids)}
        self.boxes = np.full((len(obs_ids), num_slots, 4), np.nan, dtype=np.float32)
        view = np.repeat(np.arange(len(obs_ids)), np.diff(offsets))
        self.boxes[view, slots] = boxes

    def overlap(self, first: Sequence[str], second: Sequence[str]) -> np.ndarray:
        """``S_box`` of each pair (first[k], second[k]): (P,) float64 in [0, 1]."""
        a = np.array([self.index[o] for o in first], dtype=np.int64)
        b = np.array([self.index[o] for o in second], dtype=np.int64)
        out = np.zeros(len(a), dtype=np.float64)
        for start in range(0, len(a), _CHUNK):
            part = slice(start, start + _CHUNK)
            out[part] = _mean_iou(self.boxes[a[part]], self.boxes[b[part]])
        return out


def _mean_iou(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(P, M, 4) box pairs -> (P,) mean IoU over the slots present in either view."""
    in_a, in_b = ~np.isnan(a[..., 0]), ~np.isnan(b[..., 0])
    a, b = np.nan_to_num(a), np.nan_to_num(b)
    w = np.clip(np.minimum(a[..., 2], b[..., 2]) - np.maximum(a[..., 0], b[..., 0]), 0, None)
    h = np.clip(np.minimum(a[..., 3], b[..., 3]) - np.maximum(a[..., 1], b[..., 1]), 0, None)
    inter = w * h
    area = lambda x: (x[..., 2] - x[..., 0]) * (x[..., 3] - x[..., 1])  # noqa: E731
    union = area(a) + area(b) - inter
    iou = np.where((in_a & in_b) & (union > 0), inter / np.where(union > 0, union, 1), 0.0)
    present = (in_a | in_b).sum(axis=1)
    return np.where(present > 0, iou.sum(axis=1) / np.maximum(present, 1), 0.0)


def choose_box_weight(
    s_ap: np.ndarray, s_an: np.ndarray, box_ap: np.ndarray, box_an: np.ndarray
) -> tuple[float, dict[str, float]]:
    """The lambda of :data:`BOX_WEIGHTS` that ranks the most (validation) triplets right
    with ``S + lambda * S_box`` (ties: the smaller), and each lambda's accuracy."""
    accuracy = {
        f"{lam:g}": float(np.mean(s_ap + lam * box_ap > s_an + lam * box_an)) for lam in BOX_WEIGHTS
    }
    best = max(BOX_WEIGHTS, key=lambda lam: (accuracy[f"{lam:g}"], -lam))
    return best, accuracy
