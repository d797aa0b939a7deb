"""The navigation test: motion, the navigator's labels, the rules on hand-made trajectories,
and a short end-to-end run on the mini dataset that writes Table II."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
import torch

from seannet.data.live_views import LiveRooms
from seannet.errors import ModelError, NavigationError
from seannet.navigation.benchmark import run_navigation
from seannet.navigation.config import NavigationTestConfig
from seannet.navigation.episodes import (
    OUTCOMES,
    Step,
    judge_episode,
    judge_segment,
    reached,
    sample_episode,
    step_verdict,
)
from seannet.navigation.maps import load_map
from seannet.navigation.motion import apply, local_offset, turn_towards
from seannet.navigation.navigator import (
    NavigatorConfig,
    VisualNavigator,
    draw_pair,
    label_for,
    load_navigator,
)
from seannet.navigation.tables import case_rates, read_results
from seannet.seeds import episode_seed
from sgdata.seeds import rng_for

from ...cli_runner import run_cli

# one spawned worker for the module's one-worker navigations (conftest.one_pool)
pytestmark = pytest.mark.usefixtures("one_pool")

EPS = 0.9
GOAL = (4, 2, 0)


def test_motion_moves_one_cell_and_turns_ninety_degrees() -> None:
    assert apply((2, 2, 0), "forward") == (3, 2, 0)
    assert apply((2, 2, 0), "left") == (2, 3, 0)  # left of +X is +Y (Z up)
    assert apply((2, 2, 1), "right") == (3, 2, 1)
    assert apply((2, 2, 3), "turn_left") == (2, 2, 0)
    assert apply((2, 2, 0), "turn_right") == (2, 2, 3)
    assert local_offset((2, 2, 1), (1, 5)) == (3, 1)  # 3 ahead (+Y), 1 to the left (-X)
    assert turn_towards(0, 1) == "turn_left" and turn_towards(0, 3) == "turn_right"


def test_navigator_labels_take_the_larger_displacement() -> None:
    assert label_for(3, 1) == 0 and label_for(2, -2) == 0  # forward, forward on a tie
    assert label_for(0, 2) == 1 and label_for(1, -2) == 2  # left, right
    rng = np.random.default_rng(0)
    reachable = np.ones((8, 8), dtype=bool)
    for _ in range(50):
        a, b, label = draw_pair(reachable, rng)
        forward, side = local_offset(a, b[:2])
        assert a[2] == b[2] and 0 <= forward <= 4 and abs(side) <= 2 and (forward, side) != (0, 0)
        assert label == label_for(forward, side)
    assert draw_pair(np.zeros((4, 4), dtype=bool), rng) is None
    net = VisualNavigator(hidden=16)
    assert net(torch.zeros(2, 3, 64, 64), torch.zeros(2, 3, 64, 64)).shape == (2, 3)
    with pytest.raises(ModelError, match="image_size"):
        NavigatorConfig(image_size=16)


def test_reached_is_half_a_cell_and_ten_degrees() -> None:
    assert reached(GOAL, GOAL)
    assert not reached((5, 2, 0), GOAL) and not reached((4, 2, 1), GOAL)


def test_every_outcome_from_hand_made_trajectories() -> None:
    on_the_way = Step("forward", (3, 2, 0), similarity=0.5)
    arrive = Step("forward", GOAL, similarity=0.95)
    # success: two segments, each stopped on its goal
    turn = Step("turn_left", (4, 2, 1), similarity=0.97)
    assert judge_episode([(GOAL, [on_the_way, arrive]), ((4, 2, 1), [turn])], EPS) == (
        "success",
        -1,
    )
    # localization: stopped one cell short (a false positive) ...
    assert judge_episode([(GOAL, [Step("forward", (3, 2, 0), similarity=0.93)])], EPS) == (
        "localization",
        0,
    )
    # ... or stood on the goal without stopping and walks past it
    passed = [on_the_way, Step("forward", GOAL, similarity=0.6), Step("forward", (5, 2, 0))]
    assert judge_segment(GOAL, passed, EPS) == ("localization", 2)
    # navigation: k_max steps, never near the goal, never stopped
    wander = [Step("left", (1, k, 0), similarity=0.1) for k in range(12)]
    assert judge_episode([(GOAL, [arrive]), ((9, 9, 0), wander)], EPS) == ("navigation", 1)
    assert judge_segment((9, 9, 0), wander + [Step("forward", (9, 9, 0), similarity=1.0)], EPS) == (
        "navigation",
        12,
    )
    # collision: a move into a blocked cell, whatever the localizer would say
    assert step_verdict(Step("forward", GOAL, collided=True), GOAL, EPS) == "collision"
    assert judge_episode([(GOAL, [on_the_way, Step("right", (3, 1, 0), collided=True)])], EPS) == (
        "collision",
        0,
    )
    with pytest.raises(NavigationError, match="decide nothing"):
        judge_segment(GOAL, [on_the_way], EPS)


def _without_times(results: dict) -> list:
    """Every run's episodes without their wall times (the one field that varies)."""
    return [
        [{k: v for k, v in e.items() if k != "seconds"} for e in run["episodes"]]
        for run in results["runs"]
    ]


@pytest.mark.slow  # navigate killed (kill -9) in a fresh interpreter, then resumed to the end
def test_navigate_end_to_end_writes_table_two(
    navigation_run: SimpleNamespace, localizer_run: Path, mini_dataset: Path, tmp_path: Path, procs
) -> None:
    nav, out = navigation_run.navigator, navigation_run.out
    assert len(navigation_run.history) == 1 and (nav / "best.pt").is_file()
    assert load_navigator(nav).act(
        np.zeros((96, 96, 3), np.uint8), np.zeros((96, 96, 3), np.uint8)
    ) in ("forward", "left", "right")
    written = read_results(out / "navigate_test.json")
    assert "seconds" not in (out / "navigate_test.json").read_text()
    (run,) = written["runs"]
    for rule in ("paper", "replan"):
        table = case_rates(run["episodes"], rule)
        for case in ("N", "A"):
            row = table[case]
            assert row["total"] == 2  # one test room, two episodes per case
            assert sum(row[k]["percent"] for k in OUTCOMES) == pytest.approx(100.0)
            # every collision has a cause, every localization failure a kind
            assert (
                row["path blocked"]["count"] + row["navigator error"]["count"]
                == (row["collision"]["count"])
            )
            assert (
                row["false stop"]["count"] + row["missed goal"]["count"]
                == (row["localization"]["count"])
            )
            assert row["success"]["low"] <= row["success"]["percent"] <= row["success"]["high"]
    text = (out / "navigate_test.md").read_text()
    assert "The paper's rule" in text and "Bump and replan" in text and "render s" in text
    assert all(e["seconds"]["total"] > 0 for e in run["episodes"])
    # a strip of the first episode of each outcome and kind, per room and case
    expected = {}
    for e in run["episodes"]:
        kind = "_".join(str(k).replace(" ", "-") for k in (e["outcome"], e["detail"]) if k)
        expected.setdefault((e["room_id"], e["case"], kind), e["index"])
    strips = {p.stem for p in (navigation_run.strips / localizer_run.name).glob("*.png")}
    assert strips == {f"{r}_{c}_{i}_{k}" for (r, c, k), i in expected.items()}
    # reproducible: the episodes are drawn again from their seeds, with the same paths
    (room_dir,) = (out / "maps" / localizer_run.name).iterdir()
    topo = load_map(room_dir)
    with LiveRooms(mini_dataset) as live:
        for record in run["episodes"]:
            rng = rng_for(episode_seed(0, record["room_id"], record["case"], record["index"]))
            episode = sample_episode(topo, live, record["case"], rng, index=record["index"])
            assert [list(p) for p in episode.path] == record["path"]
            assert episode.layout == record["layout"] != topo.layout
            if record["case"] == "N":
                assert len(episode.path) == 2

    # killed (SIGKILL, its workers go with it) after its first part, then resumed: the same
    # episodes, byte for byte but for wall times, as the uninterrupted run with two workers
    killed = tmp_path / "killed"
    command = [
        sys.executable, "-m", "sgdata_cli.seannet_app", "navigate", str(localizer_run),
        "--navigator", str(nav), "--data", str(mini_dataset), "--episodes", "2",
        "--epsilon", "0.95", "--replan", "--workers", "1", "--out", str(killed),
        "--maps", str(out / "maps"),
    ]  # fmt: skip
    process = subprocess.Popen(
        command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, start_new_session=True
    )
    deadline = time.monotonic() + 300
    while not list((killed / "parts").glob("*/*.json")):
        assert process.poll() is None, process.stderr.read().decode() if process.stderr else ""
        assert time.monotonic() < deadline, "no part finished in time"
        time.sleep(0.05)
    os.kill(process.pid, signal.SIGKILL)
    process.wait()
    assert procs.wait_until_gone(lambda: procs.in_session(process.pid)) == []
    (first,) = list((killed / "parts").glob("*/*.json"))
    stamp = first.stat().st_mtime_ns
    assert not (killed / "navigate_test.json").exists()
    resumed = run_navigation(
        [localizer_run], nav, mini_dataset, workers=1, out=killed, maps=out / "maps",
        **navigation_run.options,
    )  # fmt: skip
    assert first.stat().st_mtime_ns == stamp  # the finished part was not run again
    assert _without_times(resumed) == _without_times(written)
    # the results file itself: the same bytes (wall times live beside it)
    assert (killed / "navigate_test.json").read_bytes() == (out / "navigate_test.json").read_bytes()


def test_navigate_wants_a_navigator_or_the_oracle(localizer_run: Path, mini_dataset: Path) -> None:
    result = run_cli("seannet", "navigate", localizer_run, "--data", mini_dataset)
    assert result.returncode != 0 and "Traceback" not in result.stderr
    (line,) = result.stderr.strip().splitlines()
    assert "--navigator RUN" in line and "--oracle" in line


def test_a_stop_threshold_per_localizer_and_where_it_comes_from(
    navigation_run: SimpleNamespace, localizer_run: Path, mini_dataset: Path, tmp_path: Path
) -> None:
    given = {localizer_run: (0.25, "navigation on val")}
    results = run_navigation(
        [localizer_run], navigation_run.navigator, mini_dataset, NavigationTestConfig(episodes=1),
        epsilon=given, out=tmp_path, maps=navigation_run.out / "maps",
    )  # fmt: skip
    (run,) = results["runs"]
    assert (run["epsilon"], run["epsilon_source"]) == (0.25, "navigation on val")
    assert "| 0.250 | navigation on val |" in (tmp_path / "navigate_test.md").read_text()
    # a run left out reads its eval files: this one has none, so it is refused
    with pytest.raises(NavigationError, match="no eval_<split>.json"):
        run_navigation([localizer_run], navigation_run.navigator, mini_dataset, epsilon={},
                       out=tmp_path / "none")  # fmt: skip
