"""Boxes in a method's vectors: every slot's box as 4 numbers (-1 where the slot is empty),
scored by a scene term (:class:`~seannet.evaluation.scene_term.SceneTerm`: the hand-made
overlap or a slot kernel learned on triplets)."""

from __future__ import annotations

import numpy as np
import torch
from torch import Tensor

from seannet.evaluation.box_overlap import SlotBoxes
from seannet.evaluation.scene_term import SceneTerm

__all__ = ["ABSENT", "box_scores", "box_vectors", "row_triplets", "vector_boxes"]

ABSENT = -1.0  # a slot's four numbers when the view has no object in it


def box_vectors(slot_boxes: Tensor) -> Tensor:
    """(N, M, 4) boxes by slot (NaN where empty) as (N, 4 M) vectors (:data:`ABSENT` there)."""
    return torch.nan_to_num(slot_boxes, nan=ABSENT).flatten(1)


def vector_boxes(vectors: Tensor | np.ndarray) -> SlotBoxes:
    """(N, 4 M) box vectors as :class:`SlotBoxes` whose ids are the row numbers as text
    (``"0"``, ``"1"``, ...: :func:`row_triplets`)."""
    if isinstance(vectors, Tensor):
        vectors = vectors.detach().cpu().numpy()
    boxes = np.asarray(vectors, dtype=np.float32).reshape(len(vectors), -1, 4).copy()
    boxes[boxes[..., 0] == ABSENT] = np.nan
    view, slot = np.nonzero(~np.isnan(boxes[..., 0]))
    offsets = np.concatenate([[0], np.cumsum(np.bincount(view, minlength=len(boxes)))])
    ids = [str(k) for k in range(len(boxes))]
    return SlotBoxes(ids, offsets, slot, boxes[view, slot], boxes.shape[1])


def row_triplets(triplets: np.ndarray) -> list[tuple[str, str, str]]:
    """(T, 3) row-index triplets as the ids of :func:`vector_boxes`."""
    return [(str(a), str(p), str(n)) for a, p, n in np.asarray(triplets).tolist()]


def box_scores(a: Tensor, b: Tensor, scene: SceneTerm) -> Tensor:
    """(P,) float64 ``S_scene`` in [0, 1] of row pairs of box vectors (a[k], b[k])."""
    boxes = vector_boxes(torch.cat([a.detach().cpu(), b.detach().cpu()]))
    rows = [str(k) for k in range(len(a) + len(b))]
    return torch.from_numpy(scene.scores(boxes, rows[: len(a)], rows[len(a) :]))
