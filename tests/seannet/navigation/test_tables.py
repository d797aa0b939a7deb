"""Table II's arithmetic: Wilson intervals against published figures, intervals clustered by
room, rates from records."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from seannet.errors import NavigationError
from seannet.navigation.benchmark import run_labels
from seannet.navigation.tables import case_rates, markdown, room_interval, wilson


@pytest.mark.parametrize(
    ("k", "n", "low", "high"),
    [
        # Newcombe (1998), Stat. Med. 17:857, Table I, method 3 (score, no continuity correction)
        (81, 263, 0.2553, 0.3662),
        (15, 148, 0.0624, 0.1605),
        (0, 20, 0.0000, 0.1611),
        (1, 29, 0.0061, 0.1718),
    ],
)
def test_wilson_matches_published_intervals(k: int, n: int, low: float, high: float) -> None:
    lo, hi = wilson(k, n)
    assert (round(lo, 4), round(hi, 4)) == (low, high)


def test_wilson_edges() -> None:
    assert wilson(10, 10)[1] == pytest.approx(1.0) and wilson(0, 10)[0] == 0.0
    assert wilson(10, 10)[0] == pytest.approx(1 - wilson(0, 10)[1])
    assert all(math.isnan(v) for v in wilson(0, 0))


def test_room_interval_is_clustered_and_never_narrower_than_wilson() -> None:
    # 40 episodes, 20 successes: as independent episodes Wilson says 35..65 %
    agree = {f"r{k}": (5, 10) for k in range(4)}
    apart = {"r0": (10, 10), "r1": (10, 10), "r2": (0, 10), "r3": (0, 10)}
    w_low, w_high = wilson(20, 40)
    assert room_interval(agree) == (w_low, w_high)  # rooms that agree: Wilson's
    low, high = room_interval(apart)  # rooms all or nothing: much wider
    assert low < w_low - 0.1 and high > w_high + 0.1
    assert room_interval(apart) == (low, high)  # the bootstrap's draws are seeded
    assert room_interval({"only": (1, 4)}) == wilson(1, 4)  # one room: no spread to see
    assert all(math.isnan(v) for v in room_interval({}))


def test_rates_of_rooms_that_disagree_get_the_clustered_interval() -> None:
    records = [
        {**_record("N", "success", None, "success", None), "room_id": "a"} for _ in range(5)
    ] + [{**_record("N", "navigation", None, "navigation", None), "room_id": "b"} for _ in range(5)]
    success = case_rates(records, "paper")["N"]["success"]
    assert success["count"] == 5 and success["percent"] == 50.0
    counts = {"a": (5, 5), "b": (0, 5)}
    assert (success["low"], success["high"]) == pytest.approx(
        tuple(100 * v for v in room_interval(counts))
    )


def _record(case: str, outcome: str, detail: str | None, paper: str, paper_detail: str | None):
    return {
        "case": case,
        "outcome": outcome,
        "detail": detail,
        "replans": 1 if outcome != paper else 0,
        "paper": {"outcome": paper, "failed_segment": 0, "detail": paper_detail},
        "steps": 3,
        "seconds": {"render": 0.5, "embed": 0.25, "navigator": 0.125, "total": 1.0},
    }


def test_rates_split_failures_and_read_each_rule() -> None:
    records = [
        _record("N", "success", None, "collision", "path blocked"),
        _record("N", "success", None, "success", None),
        _record("N", "localization", "false stop", "localization", "false stop"),
        _record("N", "navigation", None, "collision", "navigator error"),
        _record("A", "localization", "missed goal", "localization", "missed goal"),
    ]
    paper = case_rates(records, "paper")["N"]
    assert paper["total"] == 4 and paper["collision"]["count"] == 2
    assert paper["path blocked"]["count"] == 1 == paper["navigator error"]["count"]
    assert paper["success"]["percent"] == 25.0
    assert (paper["success"]["low"], paper["success"]["high"]) == pytest.approx(
        tuple(100 * v for v in wilson(1, 4))
    )
    replan = case_rates(records, "replan")
    assert replan["N"]["success"]["count"] == 2 and replan["N"]["replans"] == 0.5
    assert replan["A"]["missed goal"]["percent"] == 100.0
    results = {
        "split": "test", "episodes_per_case_and_room": 4, "k_max": 12, "spacing": 2, "seed": 0,
        "navigator": "nav", "replan": True,
        "runs": [{"run": "runs/x", "label": "x", "model": "seannet", "epsilon": 0.8,
                  "epsilon_source": "val", "episodes": records}],
    }  # fmt: skip
    text = markdown(results)
    assert "25.0 [5, 70]" in text  # 1 of 4: Wilson 95 % 4.6 .. 69.9 %
    assert "| seannet (x) | 5 | 0.50 | 0.25 | 0.12 | 1.00 | 3.0 |" in text


def test_run_labels_tell_runs_apart(tmp_path: Path) -> None:
    a, b = tmp_path / "cmp/seannet/lr0.01/seed0", tmp_path / "cmp/resnet18/lr0.003/seed0"
    assert run_labels([a, tmp_path / "x"]) == ["seed0", "x"]
    assert run_labels([a, b]) == ["lr0.01_seed0", "lr0.003_seed0"]
    with pytest.raises(NavigationError, match="twice"):
        run_labels([a, a])
