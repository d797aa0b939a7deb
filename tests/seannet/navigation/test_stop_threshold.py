"""The stop threshold chosen on val rooms: the choice rule, the refusal to choose on test, and
a real choice over two thresholds on the mini dataset's val room."""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path
from types import SimpleNamespace

import pytest

from seannet.errors import NavigationError
from seannet.navigation.benchmark import results_path
from seannet.navigation.config import NavigationTestConfig
from seannet.navigation.stop_threshold import best_epsilon, choose_epsilon, success_by_case

# one spawned worker for the module's one-worker navigations (conftest.one_pool)
pytestmark = pytest.mark.usefixtures("one_pool")


def _row(epsilon: float, n: float, a: float) -> dict:
    return {"epsilon": epsilon, "success": {"N": n, "A": a}}


def test_the_best_mean_success_wins_and_the_first_of_equals() -> None:
    assert best_epsilon([_row(0.9, 0.5, 0.1), _row(0.85, 0.4, 0.4), _row(0.8, 0.3, 0.3)]) == 0.85
    # a tie: the earlier offset (the eval epsilon comes first)
    assert best_epsilon([_row(0.9, 0.5, 0.3), _row(0.85, 0.3, 0.5)]) == 0.9
    with pytest.raises(NavigationError, match="no stop threshold"):
        best_epsilon([])


def test_success_by_case_reads_the_paper_rule() -> None:
    episodes = [
        {"case": "N", "paper": {"outcome": "success"}},
        {"case": "N", "paper": {"outcome": "collision"}},
        {"case": "A", "paper": {"outcome": "localization"}},
    ]
    rates = success_by_case(episodes)
    assert rates["N"] == 0.5 and rates["A"] == 0.0
    assert math.isnan(success_by_case(episodes[:2])["A"])


def test_a_threshold_is_never_chosen_on_test(tmp_path: Path) -> None:
    with pytest.raises(NavigationError, match="never on test"):
        choose_epsilon([tmp_path], None, tmp_path, tmp_path, NavigationTestConfig(split="test"))


@pytest.mark.slow  # navigation episodes on the live renderer for each tried epsilon
def test_choose_epsilon_on_the_val_room(
    navigation_run: SimpleNamespace, localizer_run: Path, mini_dataset: Path, tmp_path: Path
) -> None:
    run = tmp_path / "seed0"
    shutil.copytree(localizer_run, run)
    (run / "eval_val.json").write_text(json.dumps({"threshold": {"epsilon": 0.95}}))
    out = tmp_path / "epsilon"
    config = NavigationTestConfig(split="val", episodes=2)
    record = choose_epsilon(
        [run], navigation_run.navigator, mini_dataset, out, config, offsets=(0.0, -0.9)
    )
    (loc,) = record["localizers"]
    assert (loc["eval_epsilon"], loc["eval_source"]) == (0.95, "eval_val.json")
    assert [g["epsilon"] for g in loc["grid"]] == [0.95, 0.05]
    # each grid row is what that threshold's test on the val room wrote, and the choice follows
    for g in loc["grid"]:
        written = json.loads(results_path(out / "seed0" / f"{g['epsilon']:.4f}", "val").read_text())
        assert written["split"] == "val" and written["runs"][0]["epsilon"] == g["epsilon"]
        assert g["success"] == success_by_case(written["runs"][0]["episodes"])
    assert loc["chosen"] == best_epsilon(loc["grid"])
    assert record["split"] == "val" and record["config"] == config.settings()
