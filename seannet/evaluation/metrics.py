"""Evaluation of a trained run: triplet accuracy, similarity against grid offset, threshold.

Every observation of a split is embedded once; all metrics are computed from those
embeddings:

- triplet accuracy (S(A, P) > S(A, N)) overall, per room and per cascade tier;
- similarity against grid offset (paper Fig. 6): mean and standard deviation of S over all
  pairs of views of one room with the same heading, by (delta i, delta j) within +-4 cells;
- the localization threshold epsilon, chosen on the validation split by a documented rule:
  the epsilon that maximises balanced accuracy between same-pose pairs (delta = 0, same
  heading, any two layouts) and one-step pairs (|delta i| + |delta j| = 1, same heading).
  The paper read 0.90 off the same statistics (same pose 0.95 +- 0.05, one step 0.77 +-
  0.13); its precision and recall are then measured on the evaluated split.
"""

from __future__ import annotations

from collections import defaultdict
from dataclasses import dataclass
from typing import Any

import numpy as np
import torch
from torch.utils.data import DataLoader

from seannet.data.box_noise import BoxNoise
from seannet.data.datasets import (
    ImageTransform,
    ObservationDataset,
    TripletDataset,
    collate_views,
)
from seannet.data.opening import DataSource
from seannet.data.poses import HEADINGS
from seannet.model.loss import similarity
from seannet.training.config import TrainConfig
from seannet.training.loop import collect, embed_batch

__all__ = [
    "Embeddings",
    "choose_threshold",
    "embed_split",
    "example_groups",
    "offset_statistics",
    "pose_pairs",
    "similarity_of",
    "threshold_quality",
    "triplet_metrics",
    "triplet_similarities",
]

MAX_OFFSET = 4


@dataclass(frozen=True)
class Embeddings:
    """Unit embeddings of every observation of a split, with their pose metadata."""

    obs_ids: list[str]
    vectors: np.ndarray  # (N, D) float32, L2-normalised
    room: np.ndarray  # (N,) str
    layout: np.ndarray  # (N,) int
    grid_i: np.ndarray  # (N,) int
    grid_j: np.ndarray
    heading: np.ndarray
    # every view's objects as the model saw them: (offsets (N + 1,), slots, boxes (K, 4))
    slot_boxes: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
    num_slots: int = 0

    def index(self) -> dict[str, int]:
        return {o: k for k, o in enumerate(self.obs_ids)}


def embed_split(
    model: torch.nn.Module,
    config: TrainConfig,
    data: DataSource,
    split: str,
    device: torch.device,
    *,
    noise: BoxNoise | None = None,
) -> Embeddings:
    """Embed every observation of ``split`` of ``data`` (an opened dataset, or its root) once
    (eval mode), its boxes under ``noise``."""
    dataset = ObservationDataset(
        data,
        split,
        transform=ImageTransform.for_model(config.model.image_size, config.model.image_family),
        noise=noise,
    )
    loader = DataLoader(
        dataset,
        batch_size=config.batch_size,
        collate_fn=collate_views,
        num_workers=config.num_workers,
    )
    meta: dict[str, list] = defaultdict(list)

    def output(batch: Any) -> torch.Tensor:
        info = batch[1]
        for key in ("obs_id", "room_id"):
            meta[key] += info[key]
        for key in ("layout", "grid_i", "grid_j", "heading"):
            meta[key] += info[key].tolist()
        return embed_batch(model, device)(batch)

    vectors = collect(model, loader, output)
    return Embeddings(
        obs_ids=meta["obs_id"],
        vectors=vectors.numpy().astype(np.float32),
        room=np.array(meta["room_id"]),
        layout=np.array(meta["layout"]),
        grid_i=np.array(meta["grid_i"]),
        grid_j=np.array(meta["grid_j"]),
        heading=np.array(meta["heading"]),
        slot_boxes=dataset.slot_boxes(),
        num_slots=dataset.num_slots,
    )


def triplet_similarities(
    embeddings: Embeddings, triplets: TripletDataset
) -> tuple[np.ndarray, np.ndarray]:
    """(S(A, P), S(A, N)) of every triplet, from the split's embeddings."""
    index = embeddings.index()
    v = embeddings.vectors
    a = np.array([index[t[0]] for t in triplets.obs], dtype=np.int64)
    p = np.array([index[t[1]] for t in triplets.obs], dtype=np.int64)
    n = np.array([index[t[2]] for t in triplets.obs], dtype=np.int64)
    return np.einsum("ij,ij->i", v[a], v[p]), np.einsum("ij,ij->i", v[a], v[n])


def triplet_metrics(triplets: TripletDataset, s_ap: np.ndarray, s_an: np.ndarray) -> dict[str, Any]:
    """Accuracy overall, per room and per tier, from each triplet's S(A, P) and S(A, N)."""
    correct = s_ap > s_an
    rooms = np.array(triplets.room_ids)
    tiers = np.asarray(triplets.tiers)
    return {
        "triplets": int(len(correct)),
        "accuracy": float(correct.mean()) if len(correct) else 0.0,
        "per_room": {r: float(correct[rooms == r].mean()) for r in sorted(set(rooms))},
        "per_tier": {int(k): float(correct[tiers == k].mean()) for k in sorted(set(tiers))},
        "mean_gap": float((s_ap - s_an).mean()) if len(correct) else 0.0,
    }


def _pairs(embeddings: Embeddings) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(delta i, delta j, similarity, same-layout) of all same-room same-heading pairs."""
    di, dj, sims, same = [], [], [], []
    for room in sorted(set(embeddings.room)):
        for heading in range(HEADINGS):
            k = np.nonzero((embeddings.room == room) & (embeddings.heading == heading))[0]
            if len(k) < 2:
                continue
            first, second = np.triu_indices(len(k), 1)
            a, b = k[first], k[second]
            di.append(embeddings.grid_i[b] - embeddings.grid_i[a])
            dj.append(embeddings.grid_j[b] - embeddings.grid_j[a])
            sims.append(np.einsum("ij,ij->i", embeddings.vectors[a], embeddings.vectors[b]))
            same.append(embeddings.layout[a] == embeddings.layout[b])
    if not di:
        empty = np.zeros(0)
        return empty, empty, empty, empty.astype(bool)
    return np.concatenate(di), np.concatenate(dj), np.concatenate(sims), np.concatenate(same)


def offset_statistics(embeddings: Embeddings) -> dict[str, Any]:
    """Mean / std / count of similarity by (delta i, delta j) in [-4, 4]^2 (same heading).

    Pairs are counted in both directions so the maps are symmetric; the centre cell holds
    same-pose pairs across different layouts (a view is not paired with itself).
    """
    di, dj, sims, _ = _pairs(embeddings)
    size = 2 * MAX_OFFSET + 1
    total = np.zeros((size, size))
    squares = np.zeros((size, size))
    count = np.zeros((size, size))
    for sign in (1, -1):
        keep = (np.abs(di) <= MAX_OFFSET) & (np.abs(dj) <= MAX_OFFSET)
        rows = sign * di[keep] + MAX_OFFSET
        cols = sign * dj[keep] + MAX_OFFSET
        np.add.at(total, (rows, cols), sims[keep])
        np.add.at(squares, (rows, cols), sims[keep] ** 2)
        np.add.at(count, (rows, cols), 1)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = total / count
        std = np.sqrt(np.maximum(squares / count - mean**2, 0.0))
    return {"mean": mean, "std": std, "count": count}


def pose_pairs(embeddings: Embeddings) -> tuple[np.ndarray, np.ndarray]:
    """Similarities of same-pose pairs and of one-step pairs (same heading)."""
    di, dj, sims, _ = _pairs(embeddings)
    steps = np.abs(di) + np.abs(dj)
    return sims[steps == 0], sims[steps == 1]


def choose_threshold(embeddings: Embeddings) -> dict[str, float]:
    """Epsilon maximising balanced accuracy of same-pose vs one-step pairs (see module doc)."""
    same, step = pose_pairs(embeddings)
    if not len(same) or not len(step):
        return {"epsilon": float("nan"), "balanced_accuracy": float("nan")}
    candidates = np.unique(np.concatenate([same, step]))
    best, best_score = float(candidates[0]), -1.0
    for eps in candidates:
        score = 0.5 * ((same > eps).mean() + (step <= eps).mean())
        if score > best_score:
            best, best_score = float(eps), float(score)
    return {
        "epsilon": best,
        "balanced_accuracy": best_score,
        "same_pose_mean": float(same.mean()),
        "same_pose_std": float(same.std()),
        "one_step_mean": float(step.mean()),
        "one_step_std": float(step.std()),
    }


def threshold_quality(embeddings: Embeddings, epsilon: float) -> dict[str, float]:
    """Precision and recall of "S > epsilon means same pose" on same-pose vs one-step pairs."""
    same, step = pose_pairs(embeddings)
    true_pos = float((same > epsilon).sum())
    false_pos = float((step > epsilon).sum())
    return {
        "precision": true_pos / (true_pos + false_pos) if true_pos + false_pos else float("nan"),
        "recall": true_pos / len(same) if len(same) else float("nan"),
        "same_pose_pairs": int(len(same)),
        "one_step_pairs": int(len(step)),
    }


def example_groups(
    embeddings: Embeddings, triplets: TripletDataset, *, count: int = 3, seed: int = 0
) -> list[list[str]]:
    """A few tier-0 triplets as [A, P, extra same-pose views..., N] (up to 3 positives)."""
    rng = np.random.default_rng(seed)
    tier0 = [k for k, tier in enumerate(np.asarray(triplets.tiers)) if tier == 0]
    groups = []
    index = embeddings.index()
    for k in rng.permutation(tier0)[:count]:
        anchor, positive, negative = triplets.obs[int(k)]
        a = index[anchor]
        same = np.nonzero(
            (embeddings.room == embeddings.room[a])
            & (embeddings.grid_i == embeddings.grid_i[a])
            & (embeddings.grid_j == embeddings.grid_j[a])
            & (embeddings.heading == embeddings.heading[a])
            & (embeddings.layout != embeddings.layout[a])
        )[0]
        extra = [embeddings.obs_ids[j] for j in same if embeddings.obs_ids[j] != positive][:2]
        groups.append([anchor, positive, *extra, negative])
    return groups


def similarity_of(embeddings: Embeddings, ids: list[str]) -> np.ndarray:
    """Pairwise similarity matrix of some observations (paper Fig. 7)."""
    index = embeddings.index()
    v = torch.from_numpy(embeddings.vectors[[index[i] for i in ids]])
    return similarity(v[:, None, :], v[None, :, :]).numpy()
