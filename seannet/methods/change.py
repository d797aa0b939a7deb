"""How much changed between a triplet's anchor and positive: the moved objects in view, the
share of the anchor's object pixels they cover, and their dynamics class; the sweep's bins.

Moved is :mod:`seannet.data.moved`'s rule (a box shifted by more than its tolerance; for a
same-pose pair, an object seen in one view only).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from seannet.data.moved import BIN_NAMES, box_moved, moved_bin
from sgdata.dataset import Dataset

__all__ = ["DYNAMICS_BINS", "SHARE_BINS", "Change", "change_of_pairs", "share_bin", "sweep"]

# upper bounds (inclusive) of the moved share of the anchor's object pixels
SHARE_BINS = (("0", 0.0), ("<=10%", 0.10), ("10-25%", 0.25), ("25-50%", 0.50), (">50%", 1.0))
DYNAMICS_BINS = ("none", "low", "high", "low+high")


@dataclass(frozen=True)
class Change:
    """Per pair: moved objects in view, their pixel share, the dynamics of what moved."""

    moved: np.ndarray  # (T,) int
    share: np.ndarray  # (T,) float in [0, 1]
    dynamics: list[str]  # (T,) one of DYNAMICS_BINS


def share_bin(share: float) -> str:
    """The bin of :data:`SHARE_BINS` a moved pixel share falls in."""
    if share <= 0.0:
        return SHARE_BINS[0][0]
    return next(name for name, hi in SHARE_BINS[1:] if share <= hi)


def change_of_pairs(dataset: Dataset, split: str, pairs: Sequence[tuple[str, str]]) -> Change:
    """The change between each pair's views (anchor first), read from the split's objects."""
    table = dataset.observations(split, columns=["obs_id", "layout", "objects"])
    ids = table.column("obs_id").to_pylist()
    layout_of = dict(zip(ids, table.column("layout").to_pylist(), strict=True))
    objects: dict[str, dict[int, tuple[np.ndarray, int, str]]] = {}
    for obs, rows in zip(ids, table.column("objects").to_pylist(), strict=True):
        objects[obs] = {
            o["instance"]: (
                np.array([*(o["box3d_min"] or ()), *(o["box3d_max"] or ())]),
                int(o["visible_pixels"]),
                str(o["dynamics"]),
            )
            for o in rows
        }
    moved = np.zeros(len(pairs), dtype=np.int64)
    share = np.zeros(len(pairs), dtype=np.float64)
    dynamics = []
    for t, (anchor, positive) in enumerate(pairs):
        a, p = objects[anchor], objects[positive]
        which: set[int] = set()
        if layout_of[anchor] != layout_of[positive]:
            which = {k for k in a.keys() & p.keys() if box_moved(a[k][0], p[k][0])}
            if anchor.split("/")[2:] == positive.split("/")[2:]:  # same pose: one-sided ones
                which |= a.keys() ^ p.keys()
        moved[t] = len(which)
        total = sum(v[1] for v in a.values())
        share[t] = sum(a[k][1] for k in which if k in a) / total if total else 0.0
        kinds = {(a.get(k) or p[k])[2] for k in which} & {"low", "high"}
        dynamics.append("+".join(sorted(kinds, key=["low", "high"].index)) or "none")
    return Change(moved, share, dynamics)


def sweep(correct: np.ndarray, change: Change) -> dict[str, dict[str, dict[str, float]]]:
    """The share of ``correct`` (a triplet ranked right, a query found) and the count per bin
    of each change measure (the count is named ``triplets`` for either)."""
    keys = {
        "moved_objects": ([moved_bin(int(m)) for m in change.moved], BIN_NAMES),
        "moved_share": ([share_bin(float(s)) for s in change.share], [n for n, _ in SHARE_BINS]),
        "moved_dynamics": (change.dynamics, DYNAMICS_BINS),
    }
    out: dict[str, dict[str, dict[str, float]]] = {}
    for measure, (labels, bins) in keys.items():
        labels_array = np.array(labels)
        out[measure] = {}
        for name in bins:
            mask = labels_array == name
            n = int(mask.sum())
            accuracy = float(correct[mask].mean()) if n else float("nan")
            out[measure][name] = {"triplets": n, "accuracy": accuracy}
    return out
