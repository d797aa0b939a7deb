"""The covisibility oracle: how many triplets the views can decide at all.

For each triplet (anchor A, positive P, negative N) of a split, the oracle answers "P is the
nearer pose" when covisibility(A, P) > covisibility(A, N) (:mod:`sgdata.render.covisibility`,
depth rendered live from the dataset's rooms): an appearance-only method that knew exactly
how much of the scene two views share could do no better on triplets where the label's
metric ordering disagrees with what is visible. It is a diagnostic, never a method: it reads
the poses and the rooms' geometry, which no method may.

Triplets are broken down by tier and by the direction of the positive's step from the anchor
(:func:`step_direction`): along the anchor's view axis, across it, both (mixed), or the same
cell (tier 0, another layout).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from seannet.data.opening import DataSource, open_dataset

__all__ = ["DIRECTIONS", "decidable", "decidable_by_tier", "oracle", "step_direction"]

# One letter per triplet in a record: same cell, along the view axis, across it, both
DIRECTIONS = {"s": "same cell", "a": "along", "c": "across", "m": "mixed"}
EXAMPLES = 12  # triplets where covisibility disagrees with the label, kept for a contact sheet


def step_direction(anchor: tuple[float, float, float], other: tuple[float, float]) -> str:
    """The letter of :data:`DIRECTIONS` for the step from ``anchor`` (x, y, theta) to ``other``
    (x, y): along the anchor's heading, across it, both, or none (the same cell)."""
    dx, dy = other[0] - anchor[0], other[1] - anchor[1]
    along = abs(dx * math.cos(anchor[2]) + dy * math.sin(anchor[2]))
    across = abs(-dx * math.sin(anchor[2]) + dy * math.cos(anchor[2]))
    small = 1e-6
    if along < small and across < small:
        return "s"
    if across < small:
        return "a"
    return "c" if along < small else "m"


def oracle(
    data: DataSource, split: str = "test", say: Callable[[str], None] = lambda _text: None
) -> dict[str, Any]:
    """The oracle on every triplet of ``split``: per triplet its tier, the positive step's
    direction, the oracle's answer (``1``: covisibility(A, P) > covisibility(A, N); a tie is
    wrong) as strings in the split's row order, and both covisibilities' means per tier."""
    from seannet.data.live_views import LiveRooms

    ds = open_dataset(data)
    columns = ["obs_id", "room_id", "layout", "grid_i", "grid_j", "heading", "x", "y", "theta"]
    views = {r["obs_id"]: r for r in ds.observations(split, columns=columns).to_pylist()}
    table = ds.triplets(split)
    rows = list(zip(*(table.column(c).to_pylist() for c in ("anchor", "positive", "negative")),
                    strict=True))  # fmt: skip
    tiers = table.column("tier").to_pylist()
    needed = sorted({o for row in rows for o in row},
                    key=lambda o: (views[o]["room_id"], views[o]["layout"]))  # fmt: skip

    def pose(obs: str) -> tuple[float, float, float]:
        v = views[obs]
        return (v["x"], v["y"], v["theta"])

    depth: dict[str, np.ndarray] = {}
    correct, directions, scores = [], [], []
    ap_by_tier: dict[str, list[float]] = {}
    an_by_tier: dict[str, list[float]] = {}
    with LiveRooms(ds) as live:
        for k, obs in enumerate(needed):
            v = views[obs]
            live.load(v["room_id"], v["layout"])
            depth[obs] = live.depth(v["grid_i"], v["grid_j"], v["heading"])
            if k % 500 == 0:
                say(f"covisibility: depth of {k} of {len(needed)} {split} views")

        def score(a: str, b: str) -> float:
            return live.covisibility((depth[a], pose(a)), (depth[b], pose(b)))

        for (a, p, n), tier in zip(rows, tiers, strict=True):
            ap, an = score(a, p), score(a, n)
            correct.append("1" if ap > an else "0")
            scores.append((ap, an))
            directions.append(step_direction(pose(a), pose(p)[:2]))
            ap_by_tier.setdefault(str(tier), []).append(ap)
            an_by_tier.setdefault(str(tier), []).append(an)
    return {
        "split": split,
        "triplets": len(rows),
        "tier": "".join(str(t) for t in tiers),
        "direction": "".join(directions),
        "correct": "".join(correct),
        "accuracy": float(np.mean([c == "1" for c in correct])) if correct else float("nan"),
        "mean_covisibility": {
            t: {
                "anchor_positive": round(float(np.mean(ap_by_tier[t])), 4),
                "anchor_negative": round(float(np.mean(an_by_tier[t])), 4),
            }
            for t in sorted(ap_by_tier)
        },  # fmt: skip
        "views": len(needed),
        "disagreements": _examples(rows, tiers, directions, correct, scores, EXAMPLES),
    }


def decidable(oracle_correct: str, outcomes: np.ndarray) -> dict[str, Any]:
    """A method's accuracy on all triplets, on those the views decide (the oracle, string
    ``oracle_correct`` of :func:`oracle`, agrees with the label) and on the others.

    ``outcomes``: each triplet right (1) or wrong (0) in the split's row order, one row per
    seed (or one row); accuracies are means over seeds. "Not decidable" is NaN when every
    triplet is decidable.
    """
    right = np.array([c == "1" for c in oracle_correct])
    per_triplet = np.atleast_2d(np.asarray(outcomes, dtype=np.float64)).mean(axis=0)
    if per_triplet.shape != right.shape:
        raise ValueError(
            f"{per_triplet.size} outcomes per seed for {right.size} triplets of the oracle: "
            "both must be of the same split, in its row order"
        )
    return {
        "triplets": int(right.size),
        "decidable_triplets": int(right.sum()),
        "oracle_accuracy": float(right.mean()) if right.size else float("nan"),
        "accuracy": float(per_triplet.mean()) if right.size else float("nan"),
        "decidable": float(per_triplet[right].mean()) if right.any() else float("nan"),
        "not_decidable": float(per_triplet[~right].mean()) if (~right).any() else float("nan"),
    }


def decidable_by_tier(result: dict[str, Any], outcomes: np.ndarray) -> dict[str, Any]:
    """:func:`decidable` on every triplet of the oracle's ``result`` (:func:`oracle`), and
    per tier under ``per_tier``; ``outcomes`` as :func:`decidable` takes them."""
    outcomes = np.atleast_2d(np.asarray(outcomes, dtype=np.float64))
    tiers = np.array([int(t) for t in result["tier"]])
    per_tier = {}
    for tier in sorted(set(tiers.tolist())):
        rows = np.flatnonzero(tiers == tier)
        correct = "".join(result["correct"][k] for k in rows)
        per_tier[str(tier)] = decidable(correct, outcomes[:, rows])
    return {**decidable(result["correct"], outcomes), "per_tier": per_tier}


def _examples(
    rows: list[tuple[str, str, str]],
    tiers: list[int],
    directions: list[str],
    correct: list[str],
    scores: list[tuple[float, float]],
    count: int,
) -> list[dict[str, Any]]:
    """Up to ``count`` triplets where covisibility disagrees with the label, spread evenly
    over them in row order (the contact sheet's)."""
    wrong = [k for k, c in enumerate(correct) if c == "0"]
    picked = [wrong[round(i * (len(wrong) - 1) / max(count - 1, 1))] for i in range(count)] if (
        len(wrong) > count) else wrong  # fmt: skip
    return [
        {"anchor": rows[k][0], "positive": rows[k][1], "negative": rows[k][2], "tier": tiers[k],
         "direction": directions[k], "anchor_positive": round(scores[k][0], 4),
         "anchor_negative": round(scores[k][1], 4)}
        for k in picked
    ]  # fmt: skip
