"""Intervals that include both sources of variance: the rooms a split holds and the seeds a
model was trained with (DESIGN §12).

A run's triplet accuracy varies with the test rooms (triplets of one room share its views
and layouts: rooms, not triplets, are the independent units) and with the training seed (a
ResNet-18's seeds spread 2.4 points on `medium`). The two-level bootstrap resamples both:
rooms with replacement (the same draw for two models compared on the same rooms: paired),
then each model's seeds with replacement, and reads the 2.5 / 97.5 percentiles. The
seed-level t-interval (Welch's, for a difference) is reported beside it.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
from scipy import stats

__all__ = [
    "RESAMPLES",
    "per_room_matrix",
    "t_interval",
    "two_level_difference",
    "two_level_interval",
    "welch_difference",
]

RESAMPLES = 10_000
_SEED = 0  # the bootstrap's own draws: the same figures every time


def t_interval(values: Sequence[float]) -> dict[str, float]:
    """Mean, std (ddof 1) and the half-width of a 95 % t interval of the mean."""
    x = np.asarray(values, dtype=np.float64)
    n = len(x)
    std = float(x.std(ddof=1)) if n > 1 else float("nan")
    half = float(stats.t.ppf(0.975, n - 1) * std / math.sqrt(n)) if n > 1 else float("nan")
    return {"mean": float(x.mean()), "std": std, "ci95": half, "n": n}


def welch_difference(a: Sequence[float], b: Sequence[float]) -> dict[str, float]:
    """Mean of ``a`` minus mean of ``b`` (per-seed accuracies) with a 95 % Welch t interval:
    the seeds of two models are independent draws, not pairs."""
    x, y = np.asarray(a, np.float64), np.asarray(b, np.float64)
    diff = float(x.mean() - y.mean())
    if len(x) < 2 or len(y) < 2:
        return {"mean": diff, "low": float("nan"), "high": float("nan")}
    va, vb = x.var(ddof=1) / len(x), y.var(ddof=1) / len(y)
    se = math.sqrt(va + vb)
    if se == 0:
        return {"mean": diff, "low": diff, "high": diff}
    dof = (va + vb) ** 2 / (va**2 / (len(x) - 1) + vb**2 / (len(y) - 1))
    half = float(stats.t.ppf(0.975, dof) * se)
    return {"mean": diff, "low": diff - half, "high": diff + half}


def per_room_matrix(runs: Sequence[dict[str, Any]], rooms: Sequence[str]) -> np.ndarray:
    """(seeds, rooms) accuracy of each run's ``per_room`` figures, rooms in the given order."""
    return np.array([[r["per_room"][room] for room in rooms] for r in runs], dtype=np.float64)


def _weighted(acc: np.ndarray, weight: np.ndarray, rooms: np.ndarray) -> np.ndarray:
    """Triplet-weighted accuracy over resampled ``rooms`` (B, R) of (B, R) accuracies."""
    w = weight[rooms]
    return (acc * w).sum(axis=1) / w.sum(axis=1)


def _resampled(matrix: np.ndarray, rooms: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """(B, R) per-room accuracy: each resample's rooms, averaged over its resampled seeds."""
    seeds = rng.integers(0, matrix.shape[0], size=(rooms.shape[0], matrix.shape[0]))
    # mean over the drawn seeds of each drawn room: (B, S, R) -> (B, R)
    return matrix[seeds[:, :, None], rooms[:, None, :]].mean(axis=1)


def two_level_interval(
    matrix: np.ndarray, weight: np.ndarray, *, resamples: int = RESAMPLES
) -> dict[str, float]:
    """One model's accuracy over seeds and rooms with a 95 % two-level bootstrap interval.

    Args:
        matrix: (seeds, rooms) per-room accuracy of each seed's run.
        weight: (rooms,) triplets per room (a run's accuracy weights rooms by them).
    """
    rng = np.random.default_rng(_SEED)
    rooms = rng.integers(0, matrix.shape[1], size=(resamples, matrix.shape[1]))
    boot = _weighted(_resampled(matrix, rooms, rng), weight, rooms)
    low, high = np.percentile(boot, [2.5, 97.5])
    mean = float((matrix.mean(axis=0) * weight).sum() / weight.sum())
    return {"mean": mean, "low": float(low), "high": float(high)}


def two_level_difference(
    a: np.ndarray, b: np.ndarray, weight: np.ndarray, *, resamples: int = RESAMPLES
) -> dict[str, float]:
    """Accuracy of A minus B on the same rooms, 95 % two-level bootstrap interval: one room
    draw for both (paired), then each model's seeds drawn apart."""
    rng = np.random.default_rng(_SEED)
    rooms = rng.integers(0, a.shape[1], size=(resamples, a.shape[1]))
    boot = _weighted(_resampled(a, rooms, rng), weight, rooms) - _weighted(
        _resampled(b, rooms, rng), weight, rooms
    )
    low, high = np.percentile(boot, [2.5, 97.5])
    diff = float(((a.mean(axis=0) - b.mean(axis=0)) * weight).sum() / weight.sum())
    return {"mean": diff, "low": float(low), "high": float(high), "rooms": int(a.shape[1])}
