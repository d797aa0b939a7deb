"""The navigation test with a benchmarked method as localizer: what ``seannet benchmark
--navigator RUN`` adds to each card (issue 32).

The benchmark (:mod:`seannet.methods.benchmark`, a stage below this one) saves the method
of its first seed in the card's directory as a method directory and calls
:func:`navigation_test` on it; the test runs :func:`~seannet.navigation.benchmark.run_navigation`
with that directory as the only localizer (its epsilon chosen on val by the benchmark) and
writes its files into ``<card dir>/navigation/``. The card gets the success and failure
rates per case (N, A) and rule, with their 95 % intervals clustered by room.

With ``stop_policy`` (``seannet benchmark --navigator RUN --stop-policy``) the test is
:func:`~seannet.navigation.stop_policy.choose_and_test`'s: the method's stop rule chosen on
val episodes for navigation success, then the test episodes judged once by the paper's rule
(the ``paper`` row, as without it) and by the chosen rule (the ``chosen`` row).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from seannet.data.opening import DataSource
from seannet.navigation.benchmark import run_navigation
from seannet.navigation.config import STOP_POLICY_VAL_EPISODES, NavigationTestConfig
from seannet.navigation.episodes import OUTCOMES
from seannet.navigation.stop_policy import choose_and_test
from seannet.navigation.tables import case_rates

__all__ = ["NAVIGATION_DIR", "navigation_test"]

NAVIGATION_DIR = "navigation"  # under the card's directory: results, maps, parts


def navigation_test(
    directory: Path,
    *,
    navigator: Path | None,
    data: DataSource,
    config: NavigationTestConfig,
    workers: int = 1,
    stop_policy: bool = False,
    val_episodes: int = STOP_POLICY_VAL_EPISODES,
) -> dict[str, Any]:
    """Run the navigation test with the method directory ``directory`` as localizer (and the
    ``navigator`` run, or None for the oracle navigator); the card's summary of it: settings,
    epsilon and, per rule and case, the outcome rates (%);
    with ``stop_policy``, the rule chosen on ``val_episodes`` per case and room of the val
    rooms and its row beside the paper's.

    Raises:
        MethodError: the method breaks a check while it localizes.
        NavigationError, CheckpointError: as :func:`run_navigation` (and
            :func:`choose_and_test`).
    """
    out = directory / NAVIGATION_DIR
    summary: dict[str, Any] = {
        "navigator": "oracle" if navigator is None else str(navigator),
        "split": config.split,
        "episodes_per_case_and_room": config.episodes,
    }
    if stop_policy:
        result = choose_and_test([directory], navigator, data, out, config,
                                 val_episodes=val_episodes, workers=workers)  # fmt: skip
        run = result["runs"][0]
        rates = {rule: _card_rates(by_case) for rule, by_case in run["test"].items()}
        summary["stop_rule"] = {"label": run["choice"]["label"], "val_episodes": val_episodes}
    else:
        result = run_navigation([directory], navigator, data, config, workers=workers, out=out)
        run = result["runs"][0]
        rates = {rule: _card_rates(case_rates(run["episodes"], rule)) for rule in config.rules}
    return summary | {
        "epsilon": run["epsilon"],
        "epsilon_source": run["epsilon_source"],
        "rates": rates,
        "results": str(Path(result["written"]).relative_to(directory)),
    }


def _card_rates(by_case: dict[str, dict[str, Any]]) -> dict[str, dict[str, Any]]:
    """A card's rates of one rule: per case its episodes and each outcome's rate."""
    return {
        case: {"episodes": row["total"], **{name: row[name] for name in OUTCOMES}}
        for case, row in by_case.items()
    }
