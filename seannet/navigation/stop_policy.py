"""``seannet navigate --stop-policy``: a stop rule per localizer chosen on val episodes for
navigation success, then the test episodes judged once by it and by the paper's rule.

1. Traced episodes (:mod:`seannet.navigation.episodes`) on the val rooms, ``val_episodes``
   per case and room: every rule of :func:`seannet.navigation.stopping.candidates` is judged
   on the same traces, and the best mean success over N and A is kept.
2. Traced episodes on the test rooms, read once: the paper's rule at the localizer's eval
   epsilon (its own row, as the paper has it), the paper's rule at the epsilon val episodes
   chose for it, and the chosen rule, on the same episodes.
3. With a ``map_memory``, beyond the paper: the same test episodes run live, stopped by the
   chosen rule, on a map that learns the layout it is in (its own row).

Each run is :func:`~seannet.navigation.benchmark.run_navigation`'s (workers, resumable
parts, maps shared) under ``out/val``, ``out/test`` and ``out/memory-<scope>``;
``stop_policy.json`` and ``.md`` hold the choice (with its val grid) and the test rows, with
95 % intervals clustered by room.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

from seannet.data.opening import DataSource, open_dataset
from seannet.detection.live_graphs import LiveGraphs
from seannet.errors import NavigationError
from seannet.markdown import table
from seannet.navigation.benchmark import run_navigation
from seannet.navigation.config import STOP_POLICY_VAL_EPISODES, NavigationTestConfig
from seannet.navigation.stopping import KINDS, StopRule, choose_rule, judged
from seannet.navigation.tables import INTERVAL, RATE_HEADER, SPLIT_HEADER, case_rates, case_row
from seannet.provenance import append_provenance, stamp
from sgdata.fileio import atomic_write_text
from sgdata.pipeline.executors import executor_session

__all__ = ["STOP_POLICY", "check_val_episodes", "choose_and_test", "stop_policy_markdown"]

STOP_POLICY = "stop_policy.json"  # with stop_policy.md beside it


def choose_and_test(
    runs: list[Path | str],
    navigator: Path | None,
    data: DataSource,
    out: Path,
    config: NavigationTestConfig | None = None,
    *,
    epsilon: float | dict[Path, tuple[float, str]] | None = None,
    val_episodes: int = STOP_POLICY_VAL_EPISODES,
    map_memory: str = "off",
    workers: int = 1,
    graphs: LiveGraphs | None = None,
    progress: Callable[[str], None] | None = None,
) -> dict[str, Any]:
    """Choose each localizer's stop rule on val, then judge the test episodes once by it and
    by the paper's rule (see the module doc); writes ``out/stop_policy.json`` and ``.md``.
    ``epsilon`` as :func:`run_navigation` takes it (None: each run's eval epsilon): the paper
    row's threshold and the centre of the grid the rule is chosen from. ``map_memory``
    (:data:`~seannet.navigation.config.MAP_MEMORY`): off, or the third row's scope.
    ``graphs``: a detector's scene graphs for every rendered view, val and test alike.

    Raises:
        NavigationError: ``config`` is not of the test split, or asks for ``replan``; what
            :func:`run_navigation` refuses.
    """
    config = config if config is not None else NavigationTestConfig()
    if config.split != "test":
        raise NavigationError(
            f"--stop-policy chooses on val and tests on test: --split {config.split} given"
        )
    if config.replan:
        raise NavigationError("--stop-policy judges episodes under the paper's rule: no --replan")
    check_val_episodes(val_episodes)
    live_config = config.replace(map_memory=map_memory)  # checked before any episode runs
    ds = open_dataset(data)
    maps = out / "maps"
    val_config = config.replace(split="val", episodes=val_episodes, trace=True)
    with executor_session(workers=workers):  # one pool for the three navigations
        val = run_navigation(runs, navigator, ds, val_config, epsilon=epsilon, workers=workers,
                             out=out / "val", maps=maps, graphs=graphs,
                             progress=progress)  # fmt: skip
        choices = [choose_rule(run["episodes"], run["epsilon"], k_max=config.k_max)
                   for run in val["runs"]]  # fmt: skip
        test = run_navigation(runs, navigator, ds, config.replace(trace=True), epsilon=epsilon,
                              workers=workers, out=out / "test", maps=maps, graphs=graphs,
                              progress=progress)  # fmt: skip
        rules = {
            run: StopRule(**choice["chosen"]) for run, choice in zip(runs, choices, strict=True)
        }
        learned = [None] * len(runs)
        if map_memory != "off":
            live = run_navigation(runs, navigator, ds, live_config, epsilon=epsilon,
                                  workers=workers, out=out / f"memory-{map_memory}", maps=maps,
                                  stop_rules=rules, graphs=graphs,
                                  progress=progress)  # fmt: skip
            learned = [case_rates(run["episodes"]) for run in live["runs"]]
    entries = []
    for run, choice, rule, memory in zip(test["runs"], choices, rules.values(), learned,
                                         strict=True):  # fmt: skip
        entries.append({
            "run": run["run"], "label": run["label"], "model": run["model"],
            "epsilon": run["epsilon"], "epsilon_source": run["epsilon_source"],
            "choice": choice,
            "test": {"paper": case_rates(run["episodes"]),
                     "paper_val": case_rates(judged(run["episodes"], StopRule(**choice["paper"]),
                                                    config.k_max)),
                     "chosen": case_rates(judged(run["episodes"], rule, config.k_max)),
                     **({"memory": memory} if memory is not None else {})},
        })  # fmt: skip
    out.mkdir(parents=True, exist_ok=True)
    made = append_provenance(out, ds, step="stop_policy")
    result = {
        "made": stamp([made]),
        "navigator": test["navigator"],
        "dataset": test["dataset"],
        "val": val_config.settings(),
        "test": config.replace(trace=True).settings(),
        "map_memory": map_memory,
        **({"graphs": test["graphs"]} if graphs is not None else {}),
        "runs": entries,
    }
    atomic_write_text(out / STOP_POLICY, json.dumps(result, indent=1))
    written = out / STOP_POLICY.replace(".json", ".md")
    atomic_write_text(written, stop_policy_markdown(result))
    result["written"] = str(written)
    return result


def check_val_episodes(val_episodes: int) -> None:
    """Refuse a val episode count that can choose nothing (before anything runs).

    Raises:
        NavigationError: fewer than one episode per case and room.
    """
    if val_episodes < 1:
        raise NavigationError(f"--val-episodes {val_episodes}: expected >= 1 per case and room")


def _pct(share: float) -> str:
    return f"{100 * share:.1f}"


def _curve(choice: dict[str, Any]) -> list[list[str]]:
    """The val success of the chosen rule's kind, margin and window at every epsilon tried."""
    chosen = choice["chosen"]
    rows = []
    for row in choice["grid"]:
        rule = row["rule"]
        if (rule["kind"], rule["margin"], rule["window"]) == (
            chosen["kind"], chosen["margin"], chosen["window"]
        ):  # fmt: skip
            rows.append([f"{rule['epsilon']:.3f}", _pct(row["success"]["N"]),
                         _pct(row["success"]["A"]), _pct(row["mean"])])  # fmt: skip
    return sorted(rows, key=lambda r: float(r[0]))


def _best_per_kind(choice: dict[str, Any]) -> list[list[str]]:
    """The best rule of every kind on val, with its success."""
    rows = []
    for kind in KINDS:
        mine = [row for row in choice["grid"] if row["rule"]["kind"] == kind]
        best = max(mine, key=lambda row: row["mean"])
        rows.append([kind, best["label"], _pct(best["success"]["N"]), _pct(best["success"]["A"]),
                     _pct(best["mean"])])  # fmt: skip
    return rows


def stop_policy_markdown(result: dict[str, Any]) -> str:
    """``stop_policy.md``: per localizer the choice on val (the best of each kind, the chosen
    rule's curve over epsilon), then the test rows of the paper's rule and the chosen one."""
    val, test = result["val"], result["test"]
    lines = [
        "# A stop rule chosen on val for navigation success",
        "",
        result["made"],
        "",
        f"Val: {val['episodes_per_case_and_room']} traced episodes per case and room of the "
        f"val rooms; test: {test['episodes_per_case_and_room']} per case and room of the test "
        f"rooms, read once; k_max {test['k_max']}, map spacing {test['spacing']}, episode seed "
        f"{test['seed']}, navigator {result['navigator']}. Every rule is judged on the same "
        "traced episodes (seannet.navigation.stopping).",
    ]
    rows, splits = [], []
    for run in result["runs"]:
        name = f"{run['model']} ({run['label']})"
        choice = run["choice"]
        lines += [
            "",
            f"## {name}",
            "",
            f"Eval epsilon {run['epsilon']:.3f} ({run['epsilon_source']}); chosen on "
            f"{choice['episodes']} val episodes: **{choice['label']}**. The best rule of each "
            "kind (val success %):",
            "",
            *table(["kind", "rule", "N", "A", "mean"], _best_per_kind(choice)),
            "",
            "The chosen rule's kind, margin and window over epsilon (val success %):",
            "",
            *table(["epsilon", "N", "A", "mean"], _curve(choice)),
        ]
        tested = [("paper rule, eval epsilon", run["test"]["paper"])]
        if "paper_val" in run["test"]:  # results made before it lack it
            tested.append((f"paper rule, epsilon chosen on val: {choice['paper_label']}",
                           run["test"]["paper_val"]))  # fmt: skip
        tested.append((f"chosen: {choice['label']}", run["test"]["chosen"]))
        if "memory" in run["test"]:
            tested.append((f"chosen, map memory {result['map_memory']} (beyond the paper)",
                           run["test"]["memory"]))  # fmt: skip
        for rule, rates in tested:
            rows.append(case_row(f"{name}, {rule}", rates))
            splits.append(case_row(f"{name}, {rule}", rates, split=True))
    lines += [
        "",
        "## Test (read once)",
        "",
        f"Each cell: percent [{INTERVAL}], N / A.",
        "",
        *table(RATE_HEADER, rows),
        "",
        *table(SPLIT_HEADER, splits),
    ]
    return "\n".join(lines) + "\n"
