"""Accuracy on the triplets the views decide (issue 54): the covisibility oracle's split of a
method's outcomes, and `seannet benchmark --covisibility` putting it in the card and the
leaderboard."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from seannet.errors import MethodError
from seannet.evaluation.covisibility_oracle import decidable, decidable_by_tier, oracle
from seannet.methods import BenchmarkConfig, benchmark_method
from tests.cli_runner import run_cli


def test_decidable_splits_the_mean_over_seeds_by_the_oracle() -> None:
    # triplet 2 is the one the oracle orders against its label
    outcomes = np.array([[1, 0, 1, 1], [1, 1, 0, 1]])
    d = decidable("1101", outcomes)
    assert (d["triplets"], d["decidable_triplets"]) == (4, 3)
    assert d["oracle_accuracy"] == pytest.approx(0.75)
    assert d["accuracy"] == pytest.approx(0.75)
    assert d["decidable"] == pytest.approx((1 + 0.5 + 1) / 3)
    assert d["not_decidable"] == pytest.approx(0.5)
    assert math.isnan(decidable("11", np.array([1, 0]))["not_decidable"])
    with pytest.raises(ValueError, match="3 outcomes per seed for 4 triplets"):
        decidable("1101", np.array([[1, 0, 1]]))


def test_decidable_by_tier_cuts_along_the_oracles_tiers() -> None:
    result = {"tier": "0011", "correct": "1011"}
    d = decidable_by_tier(result, np.array([1, 1, 0, 1]))
    assert list(d["per_tier"]) == ["0", "1"]
    assert d["per_tier"]["0"]["decidable_triplets"] == 1
    assert d["per_tier"]["0"]["decidable"] == 1.0 and d["per_tier"]["0"]["not_decidable"] == 1.0
    assert d["per_tier"]["1"]["decidable"] == 0.5 and d["decidable"] == pytest.approx(2 / 3)


def test_benchmark_with_covisibility_reports_the_decidable_triplets(
    tmp_path: Path, mini_dataset: Path
) -> None:
    cards = tmp_path / "cards"
    done = run_cli(
        "seannet", "benchmark", "--data", mini_dataset, "--methods", "tiny-image",
        "--out", cards, "--seeds", "0", "--covisibility",
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    card = json.loads((cards / "tiny-image" / "card.json").read_text())
    got = card["summary"]["covisibility"]
    # the same split, recomputed from the oracle and the card's own per-triplet outcomes
    expected = oracle(mini_dataset, "test")
    outcomes = np.array([[c == "1" for c in card["runs"][0]["test_correct"]]])
    again = decidable(expected["correct"], outcomes)
    for key in ("triplets", "decidable_triplets", "oracle_accuracy", "accuracy"):
        assert got[key] == pytest.approx(again[key]), key
    assert got["accuracy"] == pytest.approx(card["summary"]["accuracy"]["mean"])
    assert sum(t["triplets"] for t in got["per_tier"].values()) == got["triplets"]
    markdown = (cards / "tiny-image" / "card.md").read_text()
    assert f"orders {got['decidable_triplets']} of {got['triplets']} test triplets" in markdown
    board = run_cli("seannet", "leaderboard", cards)
    assert board.returncode == 0, board.stderr
    assert "| decidable % |" in board.stdout


def test_an_oracle_of_another_split_is_refused_before_any_work(
    tmp_path: Path, mini_dataset: Path
) -> None:
    wrong = {"split": "val", "triplets": 3, "tier": "000", "correct": "111"}
    with pytest.raises(MethodError, match="not of this dataset's test split"):
        benchmark_method("tiny-image", mini_dataset, tmp_path, BenchmarkConfig(seeds=(0,)),
                         covisibility=wrong)  # fmt: skip
    assert not any(tmp_path.iterdir())
