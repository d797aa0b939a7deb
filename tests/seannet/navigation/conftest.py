"""Fixtures of the navigation tests: a tiny trained navigator and one navigation run."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import pytest

from seannet.navigation.benchmark import run_navigation
from seannet.navigation.config import NavigationTestConfig
from seannet.navigation.navigator import NavigatorConfig
from seannet.navigation.navigator_training import train_navigator

# What the tiny navigation run used: the kill-and-resume test runs it again with these.
TINY_NAVIGATION = {"config": NavigationTestConfig(episodes=2, replan=True), "epsilon": 0.95}


@pytest.fixture(scope="session")
def navigation_run(
    tmp_path_factory: pytest.TempPathFactory, localizer_run: Path, mini_dataset: Path
) -> SimpleNamespace:
    """A navigator trained in seconds, and ``seannet navigate`` of the tiny localizer with
    it on the mini dataset's test room (two workers, paper rule and --replan, strips)."""
    root = tmp_path_factory.mktemp("navigation")
    config = NavigatorConfig(
        image_size=64, hidden=16, epochs=1, batch_size=8, train_pairs=8, val_pairs=4
    )
    history = train_navigator(config, mini_dataset, root / "nav")
    results = run_navigation(
        [localizer_run],
        root / "nav",
        mini_dataset,
        workers=2,
        out=root / "out",
        strips=root / "strips",
        **TINY_NAVIGATION,
    )
    return SimpleNamespace(
        navigator=root / "nav", out=root / "out", strips=root / "strips", history=history,
        results=results, options=TINY_NAVIGATION,
    )  # fmt: skip
