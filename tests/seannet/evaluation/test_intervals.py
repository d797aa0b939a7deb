"""Intervals over rooms and seeds, checked on hand-made runs whose variance is known."""

from __future__ import annotations

import numpy as np
import pytest

from seannet.evaluation.intervals import (
    t_interval,
    two_level_difference,
    two_level_interval,
    welch_difference,
)

ROOMS = 20
WEIGHT = np.full(ROOMS, 60.0)


def _runs(seed_offsets: list[float], room_spread: float = 0.0) -> np.ndarray:
    """(seeds, rooms) accuracies: 0.8, plus a per-seed offset, plus fixed room effects."""
    rooms = np.linspace(-room_spread, room_spread, ROOMS)
    return np.array([[0.8 + s + r for r in rooms] for s in seed_offsets])


def test_seed_variance_widens_the_interval_where_rooms_alone_see_none() -> None:
    # every room alike: a room bootstrap alone would give a zero-width interval
    same_seeds = two_level_interval(_runs([0.0, 0.0, 0.0]), WEIGHT)
    assert same_seeds["low"] == same_seeds["high"] == pytest.approx(0.8)
    spread = two_level_interval(_runs([-0.03, 0.0, 0.03]), WEIGHT)
    assert spread["mean"] == pytest.approx(0.8)
    # resampling 3 seeds with replacement reaches their extremes' mean
    assert spread["low"] == pytest.approx(0.77) and spread["high"] == pytest.approx(0.83)


def test_room_and_seed_variance_add_up() -> None:
    rooms_only = two_level_interval(_runs([0.0, 0.0, 0.0], room_spread=0.1), WEIGHT)
    both = two_level_interval(_runs([-0.03, 0.0, 0.03], room_spread=0.1), WEIGHT)
    assert rooms_only["high"] - rooms_only["low"] > 0
    assert both["high"] - both["low"] > rooms_only["high"] - rooms_only["low"]


def test_paired_difference_cancels_shared_room_effects_and_keeps_seed_spread() -> None:
    # two models with the same room effects (large) and a 5-point gap
    a = _runs([0.05, 0.05, 0.05], room_spread=0.15)
    b = _runs([0.0, 0.0, 0.0], room_spread=0.15)
    d = two_level_difference(a, b, WEIGHT)
    assert d["mean"] == pytest.approx(0.05)
    assert d["low"] == pytest.approx(0.05) and d["high"] == pytest.approx(0.05)  # paired
    noisy = two_level_difference(_runs([0.02, 0.05, 0.08], room_spread=0.15), b, WEIGHT)
    assert noisy["low"] == pytest.approx(0.02) and noisy["high"] == pytest.approx(0.08)
    assert two_level_difference(a, b, WEIGHT) == d  # a fixed resampling seed


def test_rooms_are_weighted_by_their_triplets() -> None:
    a = np.array([[1.0, 0.0]])
    assert two_level_interval(a, np.array([3.0, 1.0]))["mean"] == pytest.approx(0.75)


def test_seed_level_intervals() -> None:
    t = t_interval([0.80, 0.82, 0.84])
    # t(0.975, 2) = 4.303; std 0.02; half-width 4.303 * 0.02 / sqrt(3)
    assert t["mean"] == pytest.approx(0.82) and t["ci95"] == pytest.approx(0.04969, abs=1e-4)
    w = welch_difference([0.80, 0.82, 0.84], [0.70, 0.72, 0.74])
    assert w["mean"] == pytest.approx(0.10)
    # equal variances and sizes: Welch's dof is 4, se = 0.02 * sqrt(2 / 3)
    assert w["high"] - w["mean"] == pytest.approx(2.776 * 0.02 * (2 / 3) ** 0.5, abs=1e-3)
    one = welch_difference([0.8], [0.7])
    assert one["mean"] == pytest.approx(0.1) and np.isnan(one["low"])
