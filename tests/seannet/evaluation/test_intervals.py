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


def test_three_seeds_keep_the_t_intervals_width() -> None:
    # the example: seeds at 0.72, 0.75 and 0.795, every room alike. A percentile
    # bootstrap over the seeds gave [0.720, 0.795]; the seeds' t-interval is +- 9.4 points
    seeds = [0.72, 0.75, 0.795]
    t = t_interval(seeds)
    assert t["ci95"] == pytest.approx(0.0938, abs=1e-4)
    matrix = np.array([[s] * ROOMS for s in seeds])
    two = two_level_interval(matrix, WEIGHT)
    assert two["mean"] == pytest.approx(0.755)
    assert two["high"] - two["mean"] >= t["ci95"] - 1e-12
    assert two["mean"] - two["low"] >= t["ci95"] - 1e-12
    assert two["low"] < 0.72 and two["high"] > 0.795  # wider than the seeds' range
    assert two["seeds"] == 3 and two["room_se"] == pytest.approx(0.0, abs=1e-12)


def test_same_seeds_and_rooms_give_a_point() -> None:
    same = two_level_interval(_runs([0.0, 0.0, 0.0]), WEIGHT)
    assert same["low"] == pytest.approx(0.8) and same["high"] == pytest.approx(0.8)


def test_room_and_seed_variance_add_up() -> None:
    rooms_only = two_level_interval(_runs([0.0, 0.0, 0.0], room_spread=0.1), WEIGHT)
    seeds_only = two_level_interval(_runs([-0.03, 0.0, 0.03]), WEIGHT)
    both = two_level_interval(_runs([-0.03, 0.0, 0.03], room_spread=0.1), WEIGHT)
    # the rooms' standard error: the spread of 20 room effects over sqrt(20)
    effects = np.linspace(-0.1, 0.1, ROOMS)
    assert rooms_only["room_se"] == pytest.approx(effects.std() / ROOMS**0.5, rel=0.05)
    assert seeds_only["seed_se"] == pytest.approx(0.03 / 3**0.5)
    # variances add: the half-widths (same t quantile) add in quadrature
    assert both["half"] ** 2 == pytest.approx(
        rooms_only["half"] ** 2 + seeds_only["half"] ** 2, rel=1e-6
    )


def test_one_seed_has_the_rooms_interval_alone() -> None:
    one = two_level_interval(_runs([0.0], room_spread=0.1), WEIGHT)
    assert one["seeds"] == 1 and one["seed_se"] == 0.0
    assert one["half"] == pytest.approx(1.959964 * one["room_se"])


def test_paired_difference_cancels_shared_room_effects_and_keeps_seed_spread() -> None:
    # two models with the same room effects (large) and a 5-point gap
    a = _runs([0.05, 0.05, 0.05], room_spread=0.15)
    b = _runs([0.0, 0.0, 0.0], room_spread=0.15)
    d = two_level_difference(a, b, WEIGHT)
    assert d["mean"] == pytest.approx(0.05)
    assert d["low"] == pytest.approx(0.05) and d["high"] == pytest.approx(0.05)  # paired
    noisy_a = [0.82, 0.85, 0.88]
    noisy = two_level_difference(_runs([0.02, 0.05, 0.08], room_spread=0.15), b, WEIGHT)
    # B's seeds agree: the difference's interval is A's seeds' t-interval, shifted
    assert noisy["half"] == pytest.approx(t_interval(noisy_a)["ci95"])
    welch = welch_difference(noisy_a, [0.8, 0.8, 0.8])
    assert noisy["high"] >= welch["high"] - 1e-12 and noisy["low"] <= welch["low"] + 1e-12
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


def test_an_accuracy_interval_stays_within_0_and_1() -> None:
    # two seeds far apart near the top: the t quantile on 1 dof reaches past 100 %
    wide = two_level_interval(_runs([0.15, 0.19]), WEIGHT)
    assert wide["mean"] - wide["half"] > 0.0 and wide["mean"] + wide["half"] > 1.0
    assert wide["high"] == 1.0 and wide["low"] == pytest.approx(wide["mean"] - wide["half"])
    low = two_level_interval(_runs([-0.79, -0.75]), WEIGHT)
    assert low["low"] == 0.0
