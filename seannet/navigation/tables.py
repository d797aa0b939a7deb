"""Table II from episode records: rates with 95 % intervals clustered by room, failure
splits, time; the results file and its wall times, written apart and read back together.

Episodes of one room share its map, its layouts and its localizer's view of them: rooms, not
episodes, are the independent units. A rate's interval is a percentile bootstrap over the
rooms (each draw a sample of rooms with replacement, its rate the pooled episodes' share),
widened where needed to Wilson's interval of the episodes as if independent, so that a table
of few rooms (one room: no spread between rooms to see) is never narrower than its count
allows.
"""

from __future__ import annotations

import copy
import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from seannet.errors import NavigationError
from seannet.markdown import table
from seannet.navigation.config import RULES
from seannet.navigation.episodes import CASES, CAUSES, LOCALIZATION_KINDS, OUTCOMES
from sgdata.fileio import atomic_write_text

__all__ = [
    "EPSILON_HEADER",
    "INTERVAL",
    "RULES",
    "Z95",
    "case_rates",
    "case_row",
    "epsilon_rows",
    "markdown",
    "rate_rows",
    "read_results",
    "room_interval",
    "time_rows",
    "wilson",
    "write_results",
]

Z95 = 1.959963984540054  # the standard normal's 97.5 % quantile
# what a row counts: the outcomes, then the two kinds of each failure the issue splits
DETAILS = (*LOCALIZATION_KINDS, *CAUSES)
TIME_PARTS = ("render", "embed", "navigator", "total")
RESAMPLES = 4000  # bootstrap draws of the rooms
_SEED = 0  # the bootstrap's own draws: the same table every time


def wilson(successes: int, n: int, z: float = Z95) -> tuple[float, float]:
    """Wilson's score interval of a proportion (Wilson 1927; Newcombe 1998, method 3).

    Unlike the normal approximation it stays inside [0, 1] and is not empty at 0 or n
    successes. NaNs for ``n`` = 0.
    """
    if n == 0:
        return math.nan, math.nan
    p = successes / n
    scale = 1 + z * z / n
    centre = (p + z * z / (2 * n)) / scale
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / scale
    return max(0.0, centre - half), min(1.0, centre + half)


def room_interval(
    counts: dict[str, tuple[int, int]], resamples: int = RESAMPLES
) -> tuple[float, float]:
    """95 % interval of a share pooled over rooms, ``counts`` room -> (hits, episodes): the
    percentile bootstrap over the rooms, widened to :func:`wilson`'s of the pooled count
    where that is wider. NaNs without episodes."""
    hits = np.array([k for k, _ in counts.values()], dtype=np.float64)
    sizes = np.array([n for _, n in counts.values()], dtype=np.float64)
    total = sizes.sum() if len(sizes) else 0.0
    low, high = wilson(int(hits.sum()) if len(hits) else 0, int(total))
    if total == 0 or len(sizes) < 2:
        return low, high
    draw = np.random.default_rng(_SEED).integers(len(sizes), size=(resamples, len(sizes)))
    n = sizes[draw].sum(axis=1)
    shares = hits[draw].sum(axis=1)[n > 0] / n[n > 0]
    b_low, b_high = np.percentile(shares, [2.5, 97.5])
    return min(low, float(b_low)), max(high, float(b_high))


def _ending(record: dict[str, Any], rule: str) -> tuple[str, str | None]:
    """(outcome, detail) of an episode under ``rule``."""
    if rule == "paper":
        return record["paper"]["outcome"], record["paper"]["detail"]
    return record["outcome"], record["detail"]


def case_rates(records: list[dict[str, Any]], rule: str = "paper") -> dict[str, dict[str, Any]]:
    """Per case: ``total`` and, for every outcome and failure kind, its count, percent and
    95 % interval clustered by room (:func:`room_interval`, percent); under ``replan`` also
    the mean replans per episode."""
    table: dict[str, dict[str, Any]] = {}
    for case in CASES:
        mine = [r for r in records if r["case"] == case]
        endings = [_ending(r, rule) for r in mine]
        rooms = [r.get("room_id", "") for r in mine]
        n = len(endings)
        row: dict[str, Any] = {"total": n}
        for name in (*OUTCOMES, *DETAILS):
            hit = [name in ending for ending in endings]
            counts = {
                room: (sum(h for h, r in zip(hit, rooms, strict=True) if r == room),
                       rooms.count(room))
                for room in dict.fromkeys(rooms)
            }  # fmt: skip
            k = sum(hit)
            low, high = room_interval(counts)
            row[name] = {
                "count": k,
                "percent": 100.0 * k / n if n else math.nan,
                "low": 100.0 * low,
                "high": 100.0 * high,
            }
        if rule == "replan":
            row["replans"] = sum(r["replans"] for r in mine) / n if n else math.nan
        table[case] = row
    return table


def _cell(row: dict[str, Any], name: str) -> str:
    r = row[name]
    return f"{r['percent']:.1f} [{r['low']:.0f}, {r['high']:.0f}]"


def _label(run: dict[str, Any]) -> str:
    return f"{run['model']} ({run['label']})"


# what a cell's interval is, for the documents that print them
INTERVAL = "95 % interval: a bootstrap over rooms, at least Wilson's"
RATE_HEADER = [
    "localizer",
    "cases N / A",
    *(f"{name} % N / A" for name in OUTCOMES),
]
SPLIT_HEADER = ["localizer", *(f"{name} % N / A" for name in DETAILS)]
EPSILON_HEADER = ["localizer", "epsilon", "from"]
TIME_HEADER = ["localizer", "episodes", *(f"{p} s / episode" for p in TIME_PARTS), "steps"]


def rate_rows(
    results: dict[str, Any], rule: str = "paper", *, split: bool = False
) -> list[list[str]]:
    """Table II rows (``split``: the failure kinds instead) of every run under ``rule``;
    each cell ``percent [95 % low, high]`` (clustered by room) for N, then A."""
    return [
        case_row(_label(run), case_rates(run["episodes"], rule), split=split)
        for run in results["runs"]
    ]


def case_row(label: str, rates: dict[str, dict[str, Any]], *, split: bool = False) -> list[str]:
    """One row of :data:`RATE_HEADER` (``split``: of :data:`SPLIT_HEADER`) from
    :func:`case_rates`' ``rates``, under ``label``."""
    if split:
        cells, names = [label], DETAILS
    else:
        cells, names = [label, f"{rates['N']['total']} / {rates['A']['total']}"], OUTCOMES
    return cells + [f"{_cell(rates['N'], name)} / {_cell(rates['A'], name)}" for name in names]


def time_rows(results: dict[str, Any]) -> list[list[str]]:
    """Mean seconds per episode spent rendering, embedding, in the navigator, and in all."""
    rows = []
    for run in results["runs"]:
        episodes = run["episodes"]
        n = max(len(episodes), 1)
        means = [sum(e["seconds"].get(p, 0.0) for e in episodes) / n for p in TIME_PARTS]
        steps = sum(e["steps"] for e in episodes) / n
        rows.append([_label(run), str(len(episodes)), *(f"{m:.2f}" for m in means), f"{steps:.1f}"])
    return rows


def epsilon_rows(results: dict[str, Any]) -> list[list[str]]:
    """Each run's stop threshold and where it came from (:data:`EPSILON_HEADER`'s columns)."""
    return [[_label(r), f"{r['epsilon']:.3f}", r["epsilon_source"]] for r in results["runs"]]


def markdown(results: dict[str, Any]) -> str:
    """``navigate_<split>.md``: the paper-rule table, its failure split, the ``--replan``
    table when run, time per episode, each run's epsilon."""
    rules = RULES if results.get("replan") else RULES[:1]
    lines = [
        f"# Navigation test on {results['split']} (paper Table II)",
        "",
        f"{results['episodes_per_case_and_room']} episodes per case and room, k_max "
        f"{results['k_max']}, map spacing {results['spacing']}, seed {results['seed']}, "
        f"navigator {results['navigator']}; N: neighbour sub-nodes, A: arbitrary sub-nodes. "
        f"Each cell: percent [{INTERVAL}], N / A.",
    ]
    memory = results.get("map_memory", "off")
    titles = {
        "paper": "The paper's rule (a collision ends the episode)"
        if not any("stop_rule" in run for run in results["runs"])
        else f"Each run's chosen stop rule, map memory {memory} (beyond the paper)",
        "replan": "Bump and replan (beyond the paper)",
    }
    for rule in rules:
        lines += ["", f"## {titles[rule]}", "", *table(RATE_HEADER, rate_rows(results, rule))]
        lines += ["", *table(SPLIT_HEADER, rate_rows(results, rule, split=True))]
    lines += ["", "## Time per episode", "", *table(TIME_HEADER, time_rows(results))]
    lines += ["", *table(EPSILON_HEADER, epsilon_rows(results))]
    return "\n".join(lines) + "\n"


def _times_path(path: Path) -> Path:
    return path.with_name(f"{path.stem}_times.json")


def write_results(results: dict[str, Any], path: Path) -> None:
    """``path`` (every episode without its wall times: the same bytes for the same settings)
    and ``<stem>_times.json`` (the times, per run, in episode order), each atomically."""
    plain = copy.deepcopy({k: v for k, v in results.items() if k != "written"})
    times = []
    for run in plain["runs"]:
        times.append(
            {"label": run["label"], "seconds": [e.pop("seconds") for e in run["episodes"]]}
        )
    atomic_write_text(path, json.dumps(plain, indent=1))
    atomic_write_text(_times_path(path), json.dumps({"runs": times}, indent=1))


def read_results(path: Path) -> dict[str, Any]:
    """A results file with its wall times put back (:func:`write_results`).

    Raises:
        NavigationError: either file is missing or unreadable, or they do not match.
    """
    try:
        results = json.loads(path.read_text())
        times = json.loads(_times_path(path).read_text())["runs"]
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise NavigationError(f"{path}: unreadable navigation results ({exc})") from None
    for run, timed in zip(results["runs"], times, strict=True):
        if run["label"] != timed["label"] or len(run["episodes"]) != len(timed["seconds"]):
            raise NavigationError(f"{_times_path(path)}: does not match {path.name}")
        for episode, seconds in zip(run["episodes"], timed["seconds"], strict=True):
            episode["seconds"] = seconds
    return results
