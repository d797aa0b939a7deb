"""The stop threshold of each localizer chosen for navigation, on val rooms (every choice on
val, DESIGN §12): a run's eval epsilon is chosen for telling same-pose pairs apart, not for
stopping on a sub-goal seen in another layout, so the navigation test tries a few offsets
from it on val rooms and keeps the one with the best success.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from seannet.data.opening import DataSource, open_dataset
from seannet.errors import NavigationError
from seannet.navigation.benchmark import run_labels, run_navigation
from seannet.navigation.config import NavigationTestConfig
from seannet.navigation.episodes import CASES
from seannet.navigation.localizer import run_epsilon
from sgdata.pipeline.executors import executor_session

__all__ = [
    "EPSILON_OFFSETS",
    "VAL_EPSILON",
    "VAL_EPISODES",
    "best_epsilon",
    "choose_epsilon",
    "success_by_case",
]

# the thresholds tried per localizer, offsets from its eval epsilon
EPSILON_OFFSETS = (0.0, -0.05, -0.10, -0.15, -0.20)
VAL_EPISODES = 10  # per case and room on the val rooms
VAL_EPSILON = "navigation on val"  # the source tables print beside a threshold chosen here


def success_by_case(episodes: Sequence[dict[str, Any]]) -> dict[str, float]:
    """Per case (N, A): the share of ``episodes`` that succeeded under the paper's rule
    (NaN for a case without episodes)."""
    out = {}
    for case in CASES:
        outcomes = [e["paper"]["outcome"] == "success" for e in episodes if e["case"] == case]
        out[case] = sum(outcomes) / len(outcomes) if outcomes else float("nan")
    return out


def best_epsilon(grid: Sequence[dict[str, Any]]) -> float:
    """The epsilon of ``grid`` (``{"epsilon", "success": {case: share}}`` rows) with the best
    mean success over the cases; the first of equals, so the order of the offsets breaks ties
    (the eval epsilon first).

    Raises:
        NavigationError: an empty grid.
    """
    if not grid:
        raise NavigationError("no stop threshold was tried")
    return max(grid, key=lambda g: sum(g["success"].values()) / len(g["success"]))["epsilon"]


def choose_epsilon(
    runs: list[Path],
    navigator: Path | None,
    data: DataSource,
    out: Path,
    config: NavigationTestConfig | None = None,
    *,
    offsets: Sequence[float] = EPSILON_OFFSETS,
    workers: int = 1,
    progress: Callable[[str], None] | None = None,
) -> dict[str, Any]:
    """Per localizer run, the stop threshold of ``offsets`` (from its eval epsilon) with the
    best mean success (N and A, the paper's rule) on the rooms of ``config.split``.

    Each threshold's test runs into ``out/<run label>/<epsilon>`` (resumable as
    :func:`run_navigation` is), its maps into ``out/maps/<run label>``. Returns the record
    (per run: the grid tried and the chosen epsilon) that a later test on the test rooms takes
    as ``epsilon={run: (chosen, VAL_EPSILON)}``.

    Raises:
        NavigationError: ``config.split`` is the test split (choices are made on val), or a
            run has no eval epsilon to start from.
    """
    config = config if config is not None else NavigationTestConfig(split="val", episodes=10)
    if config.split == "test":
        raise NavigationError(
            "a stop threshold is chosen on val rooms, never on test: pass a config of split val"
        )
    data = open_dataset(data)  # every threshold's test shares one opening
    say = progress or (lambda _: None)
    with executor_session(workers=workers):  # one pool for every threshold's navigation
        rows = []
        for run, label in zip(runs, run_labels(runs), strict=True):
            found = run_epsilon(run)
            if found is None:
                raise NavigationError(
                    f"{run}: no evaluated epsilon; run `seannet eval` on val first"
                )
            base, source = found
            grid = []
            for offset in offsets:
                epsilon = round(base + offset, 4)
                results = run_navigation(
                    [run], navigator, data, config, epsilon=epsilon, workers=workers,
                    out=out / label / f"{epsilon:.4f}", maps=out / "maps" / label,
                )  # fmt: skip
                success = success_by_case(results["runs"][0]["episodes"])
                grid.append({"epsilon": epsilon, "offset": offset, "success": success})
                say(f"{label} epsilon {epsilon:.3f}: success {success}")
            rows.append(
                {"run": str(run), "label": label, "eval_epsilon": base, "eval_source": source,
                 "grid": grid, "chosen": best_epsilon(grid)}
            )  # fmt: skip
    return {
        "split": config.split,
        "episodes_per_case_and_room": config.episodes,
        "config": config.settings(),
        "localizers": rows,
    }
