"""The navigation test with a benchmarked method as localizer: what ``seannet benchmark
--navigator RUN`` adds to each card (issue 32).

The benchmark (:mod:`seannet.methods.benchmark`, a stage below this one) saves the method
of its first seed in the card's directory as a method directory and calls
:func:`navigation_test` on it; the test runs :func:`~seannet.navigation.benchmark.run_navigation`
with that directory as the only localizer (its epsilon chosen on val by the benchmark) and
writes its files into ``<card dir>/navigation/``. The card gets the success and failure
rates per case (N, A) and rule, with their 95 % intervals clustered by room.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from seannet.data.opening import DataSource
from seannet.navigation.benchmark import run_navigation
from seannet.navigation.config import NavigationTestConfig
from seannet.navigation.episodes import OUTCOMES
from seannet.navigation.tables import case_rates

__all__ = ["NAVIGATION_DIR", "navigation_test"]

NAVIGATION_DIR = "navigation"  # under the card's directory: results, maps, parts


def navigation_test(
    directory: Path,
    *,
    navigator: Path,
    data: DataSource,
    config: NavigationTestConfig,
    workers: int = 1,
) -> dict[str, Any]:
    """Run the navigation test with the method directory ``directory`` as localizer; the
    card's summary of it: settings, epsilon and, per rule and case, the outcome rates (%).

    Raises:
        MethodError: the method breaks a check while it localizes.
        NavigationError, CheckpointError: as :func:`run_navigation`.
    """
    out = directory / NAVIGATION_DIR
    results = run_navigation([directory], navigator, data, config, workers=workers, out=out)
    run = results["runs"][0]
    rates = {}
    for rule in config.rules:
        by_case = case_rates(run["episodes"], rule)
        rates[rule] = {
            case: {"episodes": row["total"], **{name: row[name] for name in OUTCOMES}}
            for case, row in by_case.items()
        }
    return {
        "navigator": str(navigator),
        "split": config.split,
        "episodes_per_case_and_room": config.episodes,
        "epsilon": run["epsilon"],
        "epsilon_source": run["epsilon_source"],
        "rates": rates,
        "results": str(Path(results["written"]).relative_to(directory)),
    }
