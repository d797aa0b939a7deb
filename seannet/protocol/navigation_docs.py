"""results.md's navigation section and the leaderboard's navigation cell, from the
protocol's navigation records: success per rule and case over a method's seeds, where the
failed episodes ended, and what holds the aim back."""

from __future__ import annotations

from typing import Any

import numpy as np

from seannet.protocol.reading import Records, seeds_cell, strongest_baseline, table

__all__ = ["COLLISION_AIM", "NAVIGATION_AIM", "navigation_section", "navigation_summary"]

NAVIGATION_AIM = {"N": 80.0, "A": 65.0}  # success % the chosen stop rule aims at (paper Table II)
COLLISION_AIM = {"N": 5.0, "A": 10.0}  # collisions % under the paper's rule (issue 48)
RULES = ("paper", "chosen")


def _seeds_rate(found: list[dict[str, Any]], rule: str, case: str, outcome: str) -> tuple[
    float, float, float
]:  # fmt: skip
    """An outcome's rate over a method's seeds: their mean, and the lowest and highest of the
    seeds' 95 % intervals clustered by room."""
    got = [f["rates"][rule][case][outcome] for f in found]
    return (float(np.mean([g["percent"] for g in got])), min(g["low"] for g in got),
            max(g["high"] for g in got))  # fmt: skip


def _rate_cell(rate: tuple[float, float, float]) -> str:
    mean, low, high = rate
    return f"{mean:.1f} [{low:.0f}, {high:.0f}]"


def navigation_section(r: Records) -> list[str]:
    """Success per rule and case, each method's seeds: their mean and an interval holding
    every seed's (the lowest and highest of the seeds' 95 % intervals clustered by room);
    the chosen rules, and the aim against the best chosen row; then where the episodes that
    failed ended, and what holds the aim back."""
    nav = r.design.navigation
    if nav is None:
        return []
    navigator = "the oracle navigator" if nav.navigator is None else f"navigator `{nav.navigator}`"
    rows, rules, best = [], [], {}
    measured = {method: r.navigation(method) for method in nav.methods}
    for method, found in measured.items():
        seeds = seeds_cell(len(found), min(nav.seeds, r.design.row(method).seeds))
        if not found:
            rows.append([f"`{method}`", seeds, "", "", "", ""])
            continue
        cells = []
        for rule in RULES:
            for case in ("N", "A"):
                rate = _seeds_rate(found, rule, case, "success")
                cells.append(_rate_cell(rate))
                if rule == "chosen" and rate[0] >= best.get(case, ("", -1.0))[1]:
                    best[case] = (method, rate[0])
        rows.append([f"`{method}`", seeds, *cells])
        rules.append(f"- `{method}`: " + "; ".join(f["stop_rule"]["label"] for f in found))
    aim = " and ".join(
        f"{case} {best[case][1]:.1f} % (`{best[case][0]}`) against {goal:.0f} % "
        f"({'met' if best[case][1] >= goal else 'missed'})"
        for case, goal in NAVIGATION_AIM.items() if case in best
    )  # fmt: skip
    header = ["localizer", "seeds", "paper rule N %", "paper rule A %", "chosen rule N %",
              "chosen rule A %"]  # fmt: skip
    return [
        f"Each localizer's navigation test, with {navigator}, {nav.episodes} test episodes per "
        "case and test room: the paper's rule (epsilon chosen on val triplets, the first "
        f"failure ends the episode) and the stop rule chosen on {nav.val_episodes} val "
        "episodes per case and val room for navigation success. Cells: the seeds' mean "
        "success and an interval holding every seed's 95 % interval clustered by room.",
        "",
        *table(header, rows),
        "",
        *([f"Aim (success with the chosen rule, best localizer): {aim}.", ""] if best else []),
        "The rule each seed chose:",
        "",
        *(rules or ["- none recorded yet"]),
        *_failures(r, {m: found for m, found in measured.items() if found}, best),
    ]


def _failures(r: Records, measured: dict[str, list[dict[str, Any]]],
              best: dict[str, tuple[str, float]]) -> list[str]:  # fmt: skip
    """Where the failed episodes ended (localization: a stop missed or made at the wrong
    place; collision: the path blocked), the collision aim, the failure class that holds the
    A aim back with the bound a perfect stop decision would reach, and SeanNet's localization
    failures against the strongest baseline's (:func:`strongest_baseline`)."""
    if not measured:
        return []
    rows = []
    for method, found in measured.items():
        for rule in RULES:
            rows.append([f"`{method}`", rule] + [
                _rate_cell(_seeds_rate(found, rule, case, outcome))
                for outcome in ("localization", "collision") for case in ("N", "A")
            ])  # fmt: skip
    header = ["localizer", "rule", "localization N %", "localization A %", "collision N %",
              "collision A %"]  # fmt: skip
    worst = {case: max(_seeds_rate(found, "paper", case, "collision")[0]
                       for found in measured.values()) for case in COLLISION_AIM}  # fmt: skip
    collisions = " and ".join(
        f"{case} {worst[case]:.1f} % against <= {goal:.0f} % "
        f"({'met' if worst[case] <= goal else 'missed'})"
        for case, goal in COLLISION_AIM.items()
    )
    lines = [
        "",
        "Where the failed episodes ended (localization: the robot stopped at the wrong place "
        "or passed its sub-goal; collision: it bumped into an object on its path), mean of "
        "the seeds and an interval holding every seed's:",
        "",
        *table(header, rows),
        "",
        f"Collisions under the paper's rule, the worst localizer: {collisions}.",
    ]
    if "A" in best:
        method = best["A"][0]
        found = measured[method]
        loc = _seeds_rate(found, "chosen", "A", "localization")
        hit = _seeds_rate(found, "chosen", "A", "collision")
        lines.append(
            f"What holds A back (`{method}`, chosen rule): localization failures "
            f"{_rate_cell(loc)} % against collisions {_rate_cell(hit)} %; a perfect stop "
            f"decision would succeed in at most {100 - hit[0]:.1f} % of A episodes (those "
            "that did not collide)."
        )
    rival = strongest_baseline(r, list(measured))
    if r.first in measured and rival is not None:
        ours = _seeds_rate(measured[r.first], "chosen", "A", "localization")
        theirs = _seeds_rate(measured[rival], "chosen", "A", "localization")
        verdict = (
            "below, intervals apart" if ours[2] < theirs[1]
            else "below, intervals overlap" if ours[0] < theirs[0]
            else "not below"
        )  # fmt: skip
        lines.append(
            f"SeanNet's (`{r.first}`) A localization failures under the chosen rule, "
            f"{_rate_cell(ours)} %, against the strongest baseline's (`{rival}`, chosen on val), "
            f"{_rate_cell(theirs)} %: {verdict}."
        )
    return lines


def navigation_summary(found: list[dict[str, Any]]) -> dict[str, Any]:
    """A card's navigation summary (the leaderboard's cell) from a method's seeds: per rule
    and case, their mean success."""
    return {"rates": {
        rule: {case: {"success": {"percent": _seeds_rate(found, rule, case, "success")[0]}}
               for case in ("N", "A")}
        for rule in RULES
    }}  # fmt: skip
