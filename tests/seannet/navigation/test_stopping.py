"""Stop rules (issue 48): judged on constructed traces, the paper's rule on a real trace
agreeing with a plain run, a live run under a rule agreeing with its trace, the map that
learns its layout, and `seannet navigate --stop-policy` choosing on val only."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from seannet.data.datasets import open_dataset
from seannet.data.live_views import LiveRooms
from seannet.errors import NavigationError
from seannet.navigation.benchmark import run_labels, run_navigation
from seannet.navigation.config import NavigationTestConfig
from seannet.navigation.episodes import run_episode, sample_episode
from seannet.navigation.localizer import load_localizer
from seannet.navigation.maps import load_map
from seannet.navigation.stop_policy import choose_and_test
from seannet.navigation.stopping import StopRule, candidates, choose_rule, judge_traced
from seannet.seeds import episode_seed
from sgdata.seeds import rng_for

from ...bench_scripts import load_script
from ...cli_runner import run_cli

# one spawned worker for the module's one-worker navigations (conftest.one_pool)
pytestmark = pytest.mark.usefixtures("one_pool")

EPS = 0.9


def _step(goal: float, start: float, on_goal: bool, *, after: float | None = None,
          other: float | None = None, cause: str = "") -> list:  # fmt: skip
    """A traced step's evidence row (EpisodeResult.evidence)."""
    best = max(v for v in (start, after, other) if v is not None)
    return [goal, start, after, best if other is None else other, on_goal, cause]


def test_the_relative_rule_stops_on_a_goal_that_is_the_clear_best_match() -> None:
    # on the goal S is 0.6, under epsilon: the paper's rule passes it; the goal beats the
    # segment's start by 0.2, so the relative rule stops there
    approach = _step(0.5, 0.7, False)
    arrive = _step(0.6, 0.4, True)
    assert judge_traced([[approach, arrive]], StopRule("paper", EPS)) == (
        "localization", 0, "missed goal"
    )  # fmt: skip
    assert judge_traced([[approach, arrive]], StopRule("local", 0.3, 0.05)) == (
        "success", -1, None
    )  # fmt: skip
    assert judge_traced([[approach, arrive]], StopRule("map", 0.3, 0.05)) == ("success", -1, None)


def test_the_relative_rule_does_not_stop_where_a_neighbour_is_the_better_match() -> None:
    # on the goal, the plan's next sub-node matches better: no stop, the goal is missed
    arrive = _step(0.6, 0.4, True, after=0.7)
    assert judge_traced([[arrive]], StopRule("local", 0.3, 0.05))[2] == "missed goal"
    # off the goal, the goal the best match by far: a false stop, as the paper's would be
    early = _step(0.95, 0.2, False)
    assert judge_traced([[early, arrive]], StopRule("local", 0.3, 0.05))[2] == "false stop"
    # one view's peak off the goal: a window of two views averages it away and stops on
    # the goal, where one view stops early
    peaked = [_step(0.2, 0.6, False), _step(0.7, 0.3, False), _step(0.8, 0.2, True)]
    assert judge_traced([peaked], StopRule("local", 0.3, 0.0))[2] == "false stop"
    assert judge_traced([peaked], StopRule("local", 0.3, 0.0, 2)) == ("success", -1, None)


def test_every_segment_must_stop_and_a_collision_ends_the_episode() -> None:
    ok = [_step(0.95, 0.1, True)]
    bumped = [_step(0.5, 0.4, False), _step(0.0, 0.0, False, cause="path blocked")]
    assert judge_traced([ok, ok, bumped], StopRule("paper", EPS)) == (
        "collision", 2, "path blocked"
    )  # fmt: skip
    wander = [_step(0.1, 0.2, False)] * 3
    assert judge_traced([ok, wander], StopRule("paper", EPS), k_max=3) == ("navigation", 1, None)


def test_the_choice_is_the_best_mean_success_and_keeps_the_paper_rule_on_ties() -> None:
    arrive = _step(0.6, 0.4, True)
    records = [
        {"case": "N", "evidence": [[arrive]]},
        {"case": "A", "evidence": [[_step(0.95, 0.1, True)], [arrive]]},
    ]
    choice = choose_rule(records, EPS)
    assert choice["val"] == {"N": 1.0, "A": 1.0}
    # the paper's rule at epsilon - 0.4 stops at 0.6 (S > epsilon: - 0.3 does not), and a
    # relative rule that does as well comes later in the grid
    assert choice["chosen"]["kind"] == "paper"
    assert choice["chosen"]["epsilon"] == pytest.approx(EPS - 0.4)
    assert len(choice["grid"]) == len(candidates(EPS))
    assert candidates(EPS)[0] == StopRule("paper", EPS)
    assert choice["paper"] == choice["chosen"]  # the best is of the paper's kind here


def test_the_paper_rule_gets_its_own_epsilon_where_a_relative_rule_wins() -> None:
    # S peaks off the goal before it: any epsilon the paper's rule stops on the goal at, it
    # stops earlier at; the local rule waits for the goal to beat the segment's start
    early, arrive = _step(0.7, 0.75, False), _step(0.65, 0.3, True)
    records = [{"case": c, "evidence": [[early, arrive]]} for c in ("N", "A")]
    choice = choose_rule(records, EPS)
    assert choice["chosen"]["kind"] == "local" and choice["val"] == {"N": 1.0, "A": 1.0}
    # the paper's best stops nowhere (epsilon above 0.7: the goal missed, not a false stop,
    # ties keep the eval epsilon) and is said with its label
    assert choice["paper"] == {"kind": "paper", "epsilon": EPS, "margin": 0.0, "window": 1}
    assert choice["paper_label"] == StopRule("paper", EPS).label()
    with pytest.raises(NavigationError, match="case A"):
        choose_rule(records[:1], EPS)


@pytest.fixture(scope="module")
def stop_policy_run(localizer_run: Path, mini_dataset: Path, tmp_path_factory) -> Path:
    """`seannet navigate --stop-policy` of the tiny localizer with the oracle navigator."""
    out = tmp_path_factory.mktemp("stop_policy")
    done = run_cli(
        "seannet", "navigate", localizer_run, "--data", mini_dataset, "--oracle",
        "--stop-policy", "--val-episodes", "2", "--episodes", "2", "--epsilon", "0.95",
        "--map-memory", "layout", "--out", out,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert "# A stop rule chosen on val" in done.stdout
    assert "map memory layout (beyond the paper)" in done.stdout
    return out


def test_a_trace_judged_by_the_paper_rule_is_the_plain_run(
    stop_policy_run: Path, localizer_run: Path, mini_dataset: Path, tmp_path: Path
) -> None:
    traced = json.loads((stop_policy_run / "test" / "navigate_test.json").read_text())
    assert traced["trace"] is True
    plain = run_navigation([localizer_run], None, mini_dataset, NavigationTestConfig(episodes=2),
                           epsilon=0.95, out=tmp_path,
                           maps=stop_policy_run / "maps")  # fmt: skip
    rule = StopRule("paper", 0.95)
    pairs = zip(plain["runs"][0]["episodes"], traced["runs"][0]["episodes"], strict=True)
    for a, b in pairs:
        assert a["path"] == b["path"] and "evidence" in b and "evidence" not in a
        assert a["paper"] == b["paper"]
        ending = judge_traced(b["evidence"], rule)
        assert ending == (a["paper"]["outcome"], a["paper"]["failed_segment"], a["paper"]["detail"])
        # a trace runs every segment of the plan
        assert len(b["evidence"]) == len(b["path"]) - 1
    with pytest.raises(NavigationError, match="no --replan"):
        NavigationTestConfig(trace=True, replan=True)


def test_the_stop_policy_is_chosen_on_val_episodes_only(
    stop_policy_run: Path, mini_dataset: Path
) -> None:
    (a,) = json.loads((stop_policy_run / "stop_policy.json").read_text())["runs"]
    # the choice is a function of the val episodes alone: made again from the val file, in
    # the val rooms only, it is the same
    val = json.loads((stop_policy_run / "val" / "navigate_val.json").read_text())
    episodes = val["runs"][0]["episodes"]
    assert {e["room_id"] for e in episodes} <= set(_rooms(mini_dataset, "val"))
    assert len(episodes) == 2 * 2 and all("evidence" in e for e in episodes)
    assert choose_rule(episodes, 0.95) == a["choice"]
    test = json.loads((stop_policy_run / "test" / "navigate_test.json").read_text())
    assert {e["room_id"] for e in test["runs"][0]["episodes"]} <= set(_rooms(mini_dataset, "test"))
    assert a["test"]["paper"]["N"]["total"] == 2 == a["test"]["chosen"]["A"]["total"]
    assert a["test"]["paper_val"]["A"]["total"] == 2  # the paper's rule at its val epsilon
    assert (
        f"paper rule, epsilon chosen on val: {a['choice']['paper_label']}"
        in (stop_policy_run / "stop_policy.md").read_text()
    )
    assert a["test"]["memory"]["A"]["total"] == 2  # the map that learns its layout, live
    written = (stop_policy_run / "stop_policy.md").read_text()
    assert f"**{a['choice']['label']}**" in written and "## Test (read once)" in written


def test_the_detector_page_shows_a_recorded_stop_policy_run(
    stop_policy_run: Path, tmp_path: Path
) -> None:
    # docs/detector.md's navigation rows come from the stop_policy.json recorded, not the run
    figures = load_script("detector_figures")
    folder = tmp_path / "sgdata-mini"
    (folder / "navigation").mkdir(parents=True)
    shutil.copy(stop_policy_run / "stop_policy.json", folder / "navigation" / "truth.json")
    (a,) = json.loads((stop_policy_run / "stop_policy.json").read_text())["runs"]
    rows = figures._navigation_rows(folder)
    assert "2 episodes per case and room" in rows[0]
    for rule, name in (
        ("paper", "paper (S > ε), eval ε"),
        ("paper_val", f"paper, ε chosen on val ({a['choice']['paper_label']})"),
        ("chosen", f"chosen on val ({a['choice']['label']})"),
    ):
        (row,) = [r for r in rows if name in r]
        cells = [c.strip() for c in row.strip("|").split("|")]
        assert cells[1] == "truth"
        success = a["test"][rule]["A"]["success"]
        assert cells[4] == f"{success['percent']:.1f} [{success['low']:.0f}, {success['high']:.0f}]"
    assert figures._navigation_rows(tmp_path / "nothing recorded") == []


@pytest.mark.parametrize("rule", [StopRule("local", 0.5, 0.02), StopRule("map", 0.3, 0.05, 2)])
def test_a_live_run_under_a_rule_ends_as_its_trace_is_judged(
    rule: StopRule, stop_policy_run: Path, localizer_run: Path, mini_dataset: Path,
    tmp_path: Path,
) -> None:  # fmt: skip
    traced = json.loads((stop_policy_run / "test" / "navigate_test.json").read_text())
    live = run_navigation([localizer_run], None, mini_dataset, NavigationTestConfig(episodes=2),
                          epsilon=0.95, out=tmp_path, maps=stop_policy_run / "maps",
                          stop_rules={localizer_run: rule})  # fmt: skip
    (run,) = live["runs"]
    assert StopRule(**run["stop_rule"]) == rule
    pairs = zip(run["episodes"], traced["runs"][0]["episodes"], strict=True)
    for a, b in pairs:
        assert a["path"] == b["path"]
        ending = (a["paper"]["outcome"], a["paper"]["failed_segment"], a["paper"]["detail"])
        assert ending == judge_traced(b["evidence"], rule)
        assert a["outcome"] == a["paper"]["outcome"]
    assert "chosen stop rule, map memory off" in Path(live["written"]).read_text()


def test_the_map_learns_only_the_sub_nodes_it_stopped_on(
    stop_policy_run: Path, localizer_run: Path, mini_dataset: Path
) -> None:
    localizer = load_localizer(localizer_run, mini_dataset, epsilon=0.95)
    (room,) = open_dataset(mini_dataset).rooms("test")
    (label,) = run_labels([localizer_run])
    topo = load_map(stop_policy_run / "maps" / label / room)
    given = topo.embeddings.copy()
    rule = StopRule("paper", -1.0)  # S > -1 always: it stops on every step that does not bump
    learned = 0
    with LiveRooms(mini_dataset) as live:
        for index in range(4):
            rng = rng_for(episode_seed(0, room, "A", index))
            episode = sample_episode(topo, live, "A", rng, index=index)
            memory = topo.embeddings.copy()
            result = run_episode(episode, topo, live, localizer, None, rule=rule, memory=memory)
            stops = {topo.index(goal): steps[-1].pose for goal, steps in result.segments
                     if not steps[-1].collided}  # fmt: skip
            changed = {i for i in range(len(memory)) if not np.array_equal(memory[i], given[i])}
            assert changed <= set(stops)
            for row in changed:  # the view it stood in when it stopped
                view = live.tensors(live.view(*stops[row]), localizer.transform)
                np.testing.assert_allclose(memory[row], localizer.embed([view])[0], atol=1e-5)
            learned += len(changed)
        with pytest.raises(NavigationError, match="under a chosen stop rule only"):
            run_episode(episode, topo, live, localizer, None, memory=topo.embeddings.copy())
    assert learned > 0
    np.testing.assert_array_equal(topo.embeddings, given)  # the map itself is never written
    with pytest.raises(NavigationError, match="the paper's rule keeps the map"):
        run_navigation([localizer_run], None, mini_dataset,
                       NavigationTestConfig(episodes=2, map_memory="layout"), epsilon=0.95,
                       out=stop_policy_run / "refused", maps=stop_policy_run / "maps")  # fmt: skip
    assert not (stop_policy_run / "refused").exists()


def test_the_stop_policy_is_refused_on_the_val_split_or_with_strips(
    localizer_run: Path, mini_dataset: Path, tmp_path: Path
) -> None:
    with pytest.raises(NavigationError, match="--split val given"):
        choose_and_test([localizer_run], None, mini_dataset, tmp_path,
                        NavigationTestConfig(split="val"), epsilon=0.95)  # fmt: skip
    with pytest.raises(NavigationError, match="--val-episodes 0"):
        choose_and_test([localizer_run], None, mini_dataset, tmp_path, epsilon=0.95,
                        val_episodes=0)  # fmt: skip
    refused = run_cli(
        "seannet", "navigate", localizer_run, "--data", mini_dataset, "--oracle",
        "--stop-policy", "--strips", tmp_path / "s", "--out", tmp_path,
    )  # fmt: skip
    assert refused.returncode != 0 and "Traceback" not in refused.stderr
    assert "--strips" in refused.stderr.strip().splitlines()[-1]
    refused = run_cli(
        "seannet", "navigate", localizer_run, "--data", mini_dataset, "--oracle",
        "--map-memory", "episode", "--out", tmp_path,
    )  # fmt: skip
    assert refused.returncode != 0 and "Traceback" not in refused.stderr
    assert "--map-memory episode is for --stop-policy" in refused.stderr.strip().splitlines()[-1]
    assert not any(tmp_path.iterdir())


def _rooms(root: Path, split: str) -> list[str]:
    return json.loads((root / "dataset.json").read_text())["splits"][split]
