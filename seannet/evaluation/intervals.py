"""Intervals that include both sources of variance: the rooms a split holds and the seeds a
model was trained with (DESIGN §12).

A run's triplet accuracy varies with the test rooms (triplets of one room share its views
and layouts: rooms, not triplets, are the independent units) and with the training seed (a
ResNet-18's seeds spread 2.4 points on `medium`). The two-level interval adds the two as
variance components: the variance of the seed-averaged accuracy over a bootstrap of the rooms
(the same draw for two models compared on the same rooms: paired), plus the seeds' variance
over their number, with a t quantile on seeds - 1 degrees of freedom. So it is never narrower
than the seeds' own t-interval: a percentile bootstrap over 3 seeds could never be wider than
their range (seeds at 0.72, 0.75 and 0.795 gave [0.720, 0.795] where the t-interval is
± 9.4 points). With rooms dominating and few seeds the t quantile is conservative; more seeds
narrow it. A single seed has no seed variance to show: its interval is the rooms' alone (a
normal quantile) and says so (``seeds``: 1). The seed-level t-interval (Welch's, for a
difference) is reported beside it.
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
    "wilson_interval",
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


def wilson_interval(hits: int, n: int) -> dict[str, float]:
    """A share ``hits / n`` with its 95 % Wilson score interval (a deterministic count over
    ``n`` independent-enough items: no seeds to add)."""
    if n == 0:
        return {"mean": float("nan"), "low": float("nan"), "high": float("nan"), "n": 0}
    z = float(stats.norm.ppf(0.975))
    p = hits / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return {"mean": p, "low": centre - half, "high": centre + half, "n": n}


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


def _room_variance(matrices: Sequence[np.ndarray], weight: np.ndarray, resamples: int) -> float:
    """Variance over room resamples of the first seed-averaged matrix's weighted accuracy
    minus the others' (one draw of rooms for all: paired)."""
    rng = np.random.default_rng(_SEED)
    rooms = rng.integers(0, len(weight), size=(resamples, len(weight)))
    first, *others = (m.mean(axis=0) for m in matrices)  # (rooms,) over the seeds
    boot = _weighted(first[rooms], weight, rooms)
    for other in others:
        boot = boot - _weighted(other[rooms], weight, rooms)
    return float(boot.var(ddof=1)) if resamples > 1 else 0.0


def _seed_variance(matrix: np.ndarray, weight: np.ndarray) -> float:
    """Variance of the mean of the seeds' weighted accuracies (0 for a single seed)."""
    if matrix.shape[0] < 2:
        return 0.0
    per_seed = (matrix * weight).sum(axis=1) / weight.sum()
    return float(per_seed.var(ddof=1) / matrix.shape[0])


def _components(
    mean: float, room_var: float, seed_var: float, seeds: int
) -> dict[str, float | int]:
    """``mean`` ± a 95 % interval of the summed variance components, t on ``seeds`` - 1
    degrees of freedom (a normal quantile when one seed leaves none).

    t on the seeds' dof for the room part too is conservative on purpose: Welch-Satterthwaite
    would raise the dof when rooms dominate, and then the interval can come out narrower than
    the seeds' own t-interval (room variance half the seeds' over 3 seeds: 0.76 of its width),
    which the protocol forbids (DESIGN §12)."""
    quantile = float(stats.t.ppf(0.975, seeds - 1)) if seeds > 1 else float(stats.norm.ppf(0.975))
    half = quantile * math.sqrt(room_var + seed_var)
    return {
        "mean": mean,
        "low": mean - half,
        "high": mean + half,
        "half": half,
        "room_se": math.sqrt(room_var),
        "seed_se": math.sqrt(seed_var),
        "seeds": seeds,
    }


def two_level_interval(
    matrix: np.ndarray, weight: np.ndarray, *, resamples: int = RESAMPLES
) -> dict[str, float]:
    """One model's accuracy over seeds and rooms with a 95 % two-level interval: the room
    bootstrap's variance plus the seeds' over their number, t on seeds - 1 dof.

    Args:
        matrix: (seeds, rooms) per-room accuracy of each seed's run.
        weight: (rooms,) triplets per room (a run's accuracy weights rooms by them).

    Returns:
        ``mean``, ``low``, ``high``, ``half`` (the half-width), the two standard errors
        ``room_se`` and ``seed_se``, and ``seeds``. The bounds stay within [0, 1] (an accuracy
    cannot pass them; two seeds' t quantile can: 80.4 % ± 27 points read [53.0, 107.7]);
    ``half`` keeps the width the variance gives.
    """
    mean = float((matrix.mean(axis=0) * weight).sum() / weight.sum())
    room_var = _room_variance([matrix], weight, resamples)
    got = _components(mean, room_var, _seed_variance(matrix, weight), matrix.shape[0])
    return got | {"low": max(0.0, got["low"]), "high": min(1.0, got["high"])}


def two_level_difference(
    a: np.ndarray, b: np.ndarray, weight: np.ndarray, *, resamples: int = RESAMPLES
) -> dict[str, float]:
    """Accuracy of A minus B on the same rooms with a 95 % two-level interval: the variance of
    the difference over one room draw for both (paired), plus each model's seed variance over
    its seeds (independent), t on the smaller seed count - 1 dof (Welch's bound from below:
    never narrower than Welch's interval over seeds)."""
    diff = float(((a.mean(axis=0) - b.mean(axis=0)) * weight).sum() / weight.sum())
    room_var = _room_variance([a, b], weight, resamples)
    seed_var = _seed_variance(a, weight) + _seed_variance(b, weight)
    seeds = min(a.shape[0], b.shape[0])
    return {**_components(diff, room_var, seed_var, seeds), "rooms": int(a.shape[1])}
