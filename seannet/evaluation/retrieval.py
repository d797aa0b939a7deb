"""Localization metrics beyond triplet accuracy: recall@k against a map layout, accuracy by
the number of moved objects in view, and the same-pose / one-step similarity separation.

- **recall@k**: per room, the views of the map layout (layout 0) are the map; every view of
  another layout whose pose also has a map view is a query; the query's map views are ranked
  by cosine similarity and recall@k is the share of queries whose same-pose map view is among
  the first k. A dataset holds the views its triplets referenced, so the map is that subset
  of the room's poses (the count of map views per room is reported with the figures).
- **moved objects** (:mod:`seannet.data.moved`): accuracy per bin of moved objects in view.
- **separation**: d' = (mean S same pose - mean S one step) / pooled std, same heading.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from seannet.data.moved import BIN_NAMES, MOVED_BINS

__all__ = [
    "recall_at_k",
    "map_queries",
    "map_recall",
    "accuracy_by_moved",
    "separation",
]


def recall_at_k(sim: np.ndarray, truth: np.ndarray, ks: Sequence[int] = (1, 5)) -> dict[int, float]:
    """Share of rows whose true column ranks among the ``k`` most similar, for each k.

    Args:
        sim: (Q, N) similarities of Q queries to N candidates.
        truth: (Q,) index of each query's true candidate.

    Ties count against the query (a true candidate tied with others ranks after them).
    """
    sim = np.asarray(sim, dtype=np.float64)
    truth = np.asarray(truth, dtype=np.int64)
    if sim.shape[0] == 0:
        return {int(k): float("nan") for k in ks}
    true_score = sim[np.arange(len(truth)), truth]
    rank = (sim >= true_score[:, None]).sum(axis=1) - 1  # others at least as similar
    return {int(k): float((rank < k).mean()) for k in ks}


def map_queries(
    embeddings: Any, room: str, map_layout: int = 0
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A room's map and its queries: the map layout's view indices, the indices of the other
    layouts' views whose pose the map holds, and each query's true map view (a position in
    the map's indices)."""
    e = embeddings
    in_room = e.room == room
    map_idx = np.nonzero(in_room & (e.layout == map_layout))[0]
    pose_of = {(e.grid_i[k], e.grid_j[k], e.heading[k]): n for n, k in enumerate(map_idx)}
    queries = [
        (k, pose_of[(e.grid_i[k], e.grid_j[k], e.heading[k])])
        for k in np.nonzero(in_room & (e.layout != map_layout))[0]
        if (e.grid_i[k], e.grid_j[k], e.heading[k]) in pose_of
    ]
    q = np.array([k for k, _ in queries], dtype=np.int64)
    return map_idx, q, np.array([t for _, t in queries], dtype=np.int64)


def map_recall(embeddings: Any, *, map_layout: int = 0, ks: Sequence[int] = (1, 5)) -> dict:
    """recall@k of the same pose among the map layout's views, queries from other layouts."""
    sims, truths, rooms, map_views = [], [], [], {}
    e = embeddings
    for room in sorted(set(e.room)):
        map_idx, q, truth = map_queries(e, room, map_layout)
        map_views[room] = int(len(map_idx))
        if not len(q):
            continue
        sims.append(e.vectors[q] @ e.vectors[map_idx].T)
        truths.append(truth)
        rooms.append(room)
    per_room = {r: recall_at_k(s, t, ks) for r, s, t in zip(rooms, sims, truths, strict=True)}
    queries = sum(len(t) for t in truths)
    overall = {
        int(k): (
            float(
                sum(per_room[r][k] * len(t) for r, t in zip(rooms, truths, strict=True)) / queries
            )
            if queries
            else float("nan")
        )
        for k in ks
    }
    return {
        "recall": overall,
        "queries": int(queries),
        "rooms": len(rooms),
        "map_views_per_room": map_views,
        "per_room": per_room,
    }


def accuracy_by_moved(correct: np.ndarray, moved: np.ndarray) -> dict[str, dict[str, float]]:
    """Triplet accuracy and count per bin of moved objects (:data:`MOVED_BINS`)."""
    out = {}
    for (lo, hi), name in zip(MOVED_BINS, BIN_NAMES, strict=True):
        mask = (moved >= lo) & ((moved <= hi) if hi is not None else True)
        n = int(mask.sum())
        out[name] = {"triplets": n, "accuracy": float(correct[mask].mean()) if n else float("nan")}
    return out


def separation(same: np.ndarray, step: np.ndarray) -> dict[str, float]:
    """Means, stds and d' of same-pose against one-step similarities."""
    if not len(same) or not len(step):
        return {"d_prime": float("nan")}
    pooled = np.sqrt((same.var() + step.var()) / 2)
    return {
        "same_pose_mean": float(same.mean()),
        "one_step_mean": float(step.mean()),
        "d_prime": float((same.mean() - step.mean()) / pooled) if pooled > 0 else float("inf"),
    }
