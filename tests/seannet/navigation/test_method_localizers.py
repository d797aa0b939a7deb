"""Any method as the localizer of maps, ``seannet localize`` and the navigation test: by name,
by a method directory (a benchmark card's), and ``seannet benchmark --navigator``."""

from __future__ import annotations

import json
from functools import partial
from pathlib import Path

import numpy as np
import pytest

from seannet.errors import DataError, MethodError, NavigationError
from seannet.methods import BenchmarkConfig, benchmark_method
from seannet.methods.cards import leaderboard, read_cards
from seannet.methods.localizer import METHOD_FILE, STATE_FILE, MethodLocalizer
from seannet.navigation.benchmark import run_labels, run_navigation
from seannet.navigation.config import NavigationTestConfig
from seannet.navigation.localizer import open_localizer
from seannet.navigation.map_localization import run_localize
from seannet.navigation.maps import build_maps, load_map
from seannet.navigation.method_navigation import navigation_test
from seannet.navigation.navigator import NavigatorConfig
from seannet.navigation.navigator_training import train_navigator
from sgdata.dataset import Dataset

from ...cli_runner import run_cli

# one spawned worker for the module's one-worker navigations (conftest.one_pool)
pytestmark = pytest.mark.usefixtures("one_pool")

ONE_EPISODE = NavigationTestConfig(episodes=1)


@pytest.fixture(scope="module")
def navigator(tmp_path_factory: pytest.TempPathFactory, mini_dataset: Path) -> Path:
    """A navigator trained in seconds on the mini dataset."""
    run = tmp_path_factory.mktemp("method_navigator") / "nav"
    config = NavigatorConfig(
        image_size=64, hidden=16, epochs=1, batch_size=8, train_pairs=8, val_pairs=4
    )
    train_navigator(config, mini_dataset, run)
    return run


def test_what_names_a_localizer_and_the_one_line_refusals(
    mini_dataset: Path, tmp_path: Path
) -> None:
    with pytest.raises(MethodError, match="is trained .*card directory"):
        open_localizer("boxes-kernel", mini_dataset, epsilon=0.5)
    with pytest.raises(MethodError, match="no epsilon; pass --epsilon"):
        open_localizer("tiny-image", mini_dataset)
    with pytest.raises(NavigationError, match="no such run or method directory"):
        open_localizer("runs/missing", mini_dataset)
    with pytest.raises(MethodError, match="not registered"):
        open_localizer("no-such-method", mini_dataset)
    named = open_localizer("tiny-image", mini_dataset, epsilon=0.9)
    assert isinstance(named, MethodLocalizer) and named.source == "tiny-image"
    assert named.epsilon == 0.9 and named.epsilon_source == "--epsilon"
    done = run_cli("seannet", "benchmark", "--data", mini_dataset, "--methods", "tiny-image",
                   "--out", tmp_path / "cards", "--stop-policy")  # fmt: skip
    assert done.returncode != 0 and len(done.stderr.strip().splitlines()) == 1
    assert "--stop-policy chooses a stop rule for --navigator" in done.stderr
    assert not (tmp_path / "cards").exists()
    done = run_cli("seannet", "benchmark", "--data", mini_dataset, "--methods", "tiny-image",
                   "--out", tmp_path / "cards", "--navigator", tmp_path, "--stop-policy",
                   "--val-episodes", "0")  # fmt: skip
    assert done.returncode != 0 and len(done.stderr.strip().splitlines()) == 1
    assert "--val-episodes 0: expected >= 1" in done.stderr and not (tmp_path / "cards").exists()
    assert run_labels(["tiny-image", "examples/custom_method.py:ColourBoxes", tmp_path]) == [
        "tiny-image",
        "custom_method.py__ColourBoxes",
        tmp_path.name,
    ]


def test_a_box_method_maps_and_localizes_by_its_own_similarity(
    mini_dataset: Path, tmp_path: Path
) -> None:
    room = Dataset.open(mini_dataset).rooms("test")[0]
    localizer = open_localizer("boxes-overlap", mini_dataset, require_epsilon=False)
    (directory,) = build_maps(localizer, mini_dataset, [room], tmp_path / "maps")
    topo = load_map(directory)
    assert topo.meta["run"] == "boxes-overlap" and topo.meta["model"] == "boxes-overlap"
    assert topo.embeddings.shape[1] % 4 == 0  # every slot's box: the map holds what it scores
    assert not np.allclose(np.linalg.norm(topo.embeddings, axis=1), 1.0)  # not unit vectors
    rows = (
        Dataset.open(mini_dataset)
        .observations("test", columns=["obs_id", "layout", "grid_i", "grid_j", "objects"])
        .to_pylist()
    )
    unchanged = [
        r["obs_id"]
        for r in rows
        if r["layout"] == 0 and r["grid_i"] % 2 == 0 and r["grid_j"] % 2 == 0 and r["objects"]
    ]
    assert unchanged, "the mini test room has no layout-0 view with objects on the map"
    with pytest.raises(DataError, match="pass --out"):
        run_localize("boxes-overlap", directory, mini_dataset, queries=unchanged[:1])
    result = run_localize(
        "boxes-overlap", directory, mini_dataset, queries=unchanged[:2], epsilon=0.5,
        out=tmp_path,
    )  # fmt: skip
    for query in result["queries"]:
        best = query["matches"][0]
        assert best["similarity"] == pytest.approx(1.0)  # the same boxes: mean IoU 1
        tied = [m["obs_id"] for m in query["matches"] if m["similarity"] == best["similarity"]]
        assert query["query"] in tied
    assert result["model"] == "boxes-overlap" and result["epsilon_source"] == "--epsilon"


@pytest.mark.slow  # a method's maps rendered and embedded, then its episodes navigated
def test_a_method_by_name_navigates(mini_dataset: Path, navigator: Path, tmp_path: Path) -> None:
    results = run_navigation(
        ["tiny-image"], navigator, mini_dataset, ONE_EPISODE, epsilon=0.9, out=tmp_path
    )
    (run,) = results["runs"]
    assert run["run"] == run["label"] == run["model"] == "tiny-image"
    assert run["epsilon"] == 0.9 and len(run["episodes"]) == 2 * len(
        Dataset.open(mini_dataset).rooms("test")
    )
    assert (tmp_path / "maps" / "tiny-image").is_dir()
    assert "tiny-image" in Path(results["written"]).read_text()


@pytest.mark.slow  # a benchmark card with its navigation test and the stop rule chosen on val
def test_benchmark_with_a_navigator_puts_the_rates_in_the_card(
    mini_dataset: Path, navigator: Path, tmp_path: Path
) -> None:
    """With --stop-policy the card (and the leaderboard) gives the stop rule chosen on val
    beside the paper's rule, all judged on the same test episodes."""
    config = BenchmarkConfig(seeds=(0,), preset="smoke", batch_size=16, noise=())
    test = partial(navigation_test, navigator=navigator, data=mini_dataset, config=ONE_EPISODE,
                   stop_policy=True, val_episodes=1)  # fmt: skip
    card_file = benchmark_method(
        "boxes-kernel", mini_dataset, tmp_path / "cards", config, navigation=test
    )
    directory = card_file.parent
    card = json.loads(card_file.read_text())
    nav = card["summary"]["navigation"]
    # the paper's rule at the eval epsilon and at the one val chose, and the chosen rule
    assert set(nav["rates"]) == {"paper", "paper_val", "chosen"}
    assert nav["stop_rule"]["val_episodes"] == 1
    for rule in nav["rates"].values():
        assert set(rule) == {"N", "A"}
        for case in rule.values():
            assert case["episodes"] >= 1
            shares = [case[k]["percent"] for k in ("success", "localization", "navigation")]
            assert sum(shares) + case["collision"]["percent"] == pytest.approx(100.0)
    policy = json.loads((directory / "navigation" / "stop_policy.json").read_text())
    assert policy["runs"][0]["choice"]["label"] == nav["stop_rule"]["label"]
    assert policy["val"]["split"] == "val" and policy["test"]["split"] == "test"
    assert nav["epsilon"] == pytest.approx(card["runs"][0]["threshold"]["epsilon"])
    assert "Navigation test with this method as localizer" in (directory / "card.md").read_text()
    assert (directory / nav["results"]).is_file()
    # the card's directory names the fitted method: seannet navigate / localize take it
    assert (directory / METHOD_FILE).is_file() and (directory / STATE_FILE).is_file()
    opened = open_localizer(directory, mini_dataset)
    assert isinstance(opened, MethodLocalizer) and opened.name == "boxes-kernel"
    assert opened.epsilon == pytest.approx(nav["epsilon"])
    assert opened.method.scene.kernel is not None  # the kernel fit on train, not a fresh method
    board = leaderboard(read_cards([tmp_path / "cards"]))
    assert "navigation success % N / A" in board
    chosen = nav["rates"]["chosen"]
    assert f"chosen {chosen['N']['success']['percent']:.1f} / " in board
