"""Stop rules for the navigation test, judged on traced episodes, and their choice on val.

The paper stops when S(current view, goal sub-node) > epsilon. The goal's view was stored in
layout 0, and after people moved things S at the goal can stay under epsilon while the robot
stands on it (a *missed goal*). A stop rule here may also weigh *relative* evidence: is the
goal a better match than its rivals?

- ``paper``: S to the goal > epsilon (the paper's rule; epsilon chosen on val here, or the
  eval epsilon for the paper's own row);
- ``local``: S to the goal > epsilon and it beats the segment's start sub-node and the plan's
  next sub-node by more than ``margin``;
- ``map``: S to the goal > epsilon and it beats every other sub-node of the map by more than
  ``margin``: the goal is the map's best match.

Each may average its evidence over the last ``window`` views of the segment (temporal
consistency). A rule is judged on a traced episode (:func:`seannet.navigation.episodes.
run_episode` with ``trace``): the outcome is the one a run under the rule would have had,
so every candidate is scored on the same val episodes without running them again, and the
one with the best mean success over N and A is kept (:func:`choose_rule`). Test episodes are
judged once, by the chosen rule and by the paper's rule at the eval epsilon.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from typing import Any

from seannet.errors import NavigationError
from seannet.navigation.config import K_MAX
from seannet.navigation.episodes import CASES, FALSE_STOP, MISSED_GOAL, REACHED

__all__ = [
    "KINDS",
    "MARGINS",
    "OFFSETS",
    "WINDOWS",
    "StopRule",
    "candidates",
    "choose_rule",
    "judge_traced",
    "judged",
    "success_by_case",
]

KINDS = ("paper", "local", "map")
# the grid a rule is chosen from: epsilon as offsets from the localizer's eval epsilon (its
# own first, so a tie keeps it), margins of the relative rules, windows of views
OFFSETS = (0.0, 0.05, -0.05, -0.1, -0.15, -0.2, -0.3, -0.4, -0.6, -0.8, -1.0)
MARGINS = (0.0, -0.05, 0.02, 0.05, 0.1, 0.15, 0.2, 0.3)
WINDOWS = (1, 2)

# a traced step's evidence (EpisodeResult.evidence): its fields' positions
_GOAL, _START, _NEXT, _OTHER, _ON_GOAL, _CAUSE = range(6)


@dataclass(frozen=True)
class StopRule:
    """When the robot stops on a segment's goal (see the module doc)."""

    kind: str = "paper"
    epsilon: float = 0.0
    margin: float = 0.0  # local and map only
    window: int = 1  # the last views of the segment the evidence is averaged over

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise NavigationError(f"stop rule {self.kind!r}: expected one of {', '.join(KINDS)}")
        if self.window < 1:
            raise NavigationError(f"stop rule window {self.window}: expected >= 1 view")

    def label(self) -> str:
        """A short name: ``paper e0.714``, ``local e0.614 m0.05 w2``."""
        parts = [self.kind, f"e{self.epsilon:.3f}"]
        if self.kind != "paper":
            parts.append(f"m{self.margin:g}")
        if self.window > 1:
            parts.append(f"w{self.window}")
        return " ".join(parts)

    def stops(self, history: Sequence[Sequence[Any]]) -> bool:
        """Whether the robot stops after the last of ``history``, the segment's steps so far
        (traced evidence rows, none of them a collision)."""
        last = history[-self.window :]
        goal = _mean([row[_GOAL] for row in last])
        if not goal > self.epsilon:
            return False
        if self.kind == "paper":
            return True
        if self.kind == "local":
            rivals = [_best(row[_START], row[_NEXT]) for row in last]
        else:
            rivals = [row[_OTHER] for row in last]
        rival = _mean(rivals)
        return math.isnan(rival) or goal - rival > self.margin

    def verdict(self, history: Sequence[Sequence[Any]]) -> tuple[str, str | None] | None:
        """What the last of ``history`` (a segment's evidence rows so far) decides under this
        rule: ``(REACHED, None)``, a failure ``(outcome, detail)``, or None (go on)."""
        row = history[-1]
        if row[_CAUSE]:
            return "collision", row[_CAUSE]
        if self.stops(history):
            return (REACHED, None) if row[_ON_GOAL] else ("localization", FALSE_STOP)
        if row[_ON_GOAL]:  # on the goal without stopping: the robot passes it
            return "localization", MISSED_GOAL
        return None


def _mean(values: Sequence[float | None]) -> float:
    numbers = [v for v in values if v is not None and not math.isnan(v)]
    return sum(numbers) / len(numbers) if numbers else math.nan


def _best(*values: float | None) -> float:
    numbers = [v for v in values if v is not None and not math.isnan(v)]
    return max(numbers) if numbers else math.nan


def judge_traced(
    evidence: Sequence[Sequence[Sequence[Any]]], rule: StopRule, *, k_max: int = K_MAX
) -> tuple[str, int, str | None]:
    """(outcome, failed segment or -1, detail) of a traced episode's ``evidence`` under
    ``rule``: per segment, the first step that collides, stops, or stands on the goal without
    stopping decides it; ``k_max`` steps that decide nothing are a navigation failure."""
    for n, steps in enumerate(evidence):
        verdict: tuple[str, str | None] = ("navigation", None)
        for k in range(min(len(steps), k_max)):
            decided = rule.verdict(steps[: k + 1])
            if decided is not None:
                verdict = decided
                break
        if verdict[0] != REACHED:
            return verdict[0], n, verdict[1]
    return "success", -1, None


def judged(records: Sequence[dict[str, Any]], rule: StopRule, k_max: int) -> list[dict]:
    """Copies of traced episode records whose paper-rule ending is ``rule``'s, for the
    navigation tables (:func:`seannet.navigation.tables.case_rates`)."""
    out = []
    for record in records:
        if "evidence" not in record:
            raise NavigationError(
                f"episode {record.get('room_id')} {record.get('case')} #{record.get('index')}: "
                "not traced; a stop rule is judged on traced episodes"
            )
        outcome, failed, detail = judge_traced(record["evidence"], rule, k_max=k_max)
        copied = copy.copy(record)
        copied["paper"] = {"outcome": outcome, "failed_segment": failed, "detail": detail}
        out.append(copied)
    return out


def success_by_case(
    records: Sequence[dict[str, Any]], rule: StopRule, k_max: int = K_MAX
) -> dict[str, float]:
    """Per case (N, A): the share of traced ``records`` that succeed under ``rule``."""
    out = {}
    for case in CASES:
        mine = [r for r in records if r["case"] == case]
        wins = [judge_traced(r["evidence"], rule, k_max=k_max)[0] == "success" for r in mine]
        out[case] = sum(wins) / len(wins) if wins else math.nan
    return out


def candidates(epsilon: float) -> list[StopRule]:
    """Every rule tried on val around a localizer's eval ``epsilon``, the paper's rule at it
    first (ties keep the earlier rule: the simpler kind, the smaller window)."""
    rules = []
    for kind in KINDS:
        for window in WINDOWS:
            for offset in OFFSETS:
                e = round(epsilon + offset, 4)
                margins = (0.0,) if kind == "paper" else MARGINS
                rules += [StopRule(kind, e, m, window) for m in margins]
    return rules


def choose_rule(
    records: Sequence[dict[str, Any]], epsilon: float, *, k_max: int = K_MAX
) -> dict[str, Any]:
    """The rule of :func:`candidates` with the best mean success over N and A on the traced
    val ``records``, with every candidate's val success (the curve that chose it), and the
    best rule of the paper's kind (``paper``: its epsilon chosen on these episodes).

    Raises:
        NavigationError: no traced episode of a case.
    """
    for case in CASES:
        if not any(r["case"] == case for r in records):
            raise NavigationError(f"no traced val episode of case {case}: nothing to choose on")
    scored = []
    for rule in candidates(epsilon):
        success = success_by_case(records, rule, k_max)
        scored.append({"rule": asdict(rule), "label": rule.label(), "success": success,
                       "mean": sum(success.values()) / len(success)})  # fmt: skip
    best = max(scored, key=lambda row: row["mean"])  # the first of equals
    # the paper's rule with its epsilon chosen on the same episodes: how much of the chosen
    # rule's gain is the threshold's place, not the kind of rule
    paper = max((row for row in scored if row["rule"]["kind"] == "paper"),
                key=lambda row: row["mean"])  # fmt: skip
    return {"chosen": best["rule"], "label": best["label"], "val": best["success"],
            "paper": paper["rule"], "paper_label": paper["label"],
            "eval_epsilon": epsilon, "episodes": len(records), "grid": scored}  # fmt: skip
