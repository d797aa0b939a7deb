"""``seannet results plan`` and ``run``: the units a design still needs, what each is
estimated to take, and running them until a time limit, never starting one that cannot finish.

An estimate is read from the records (the slowest of the same network or method, per budget
second of training and per evaluation pass), or a prior before there is one. A unit
estimated above the design's limit (45 min) is refused, with its estimate: cut it (fewer
evaluations, a smaller budget) rather than lose it to a stopped machine.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from seannet.data.opening import open_dataset
from seannet.protocol.design import Design, Plan, Unit, plan_units
from seannet.protocol.docs import Records, write_docs  # at start: the code a long run began with
from seannet.protocol.records import Found, dataset_identity, read_records, recipe_folder
from seannet.protocol.unit import run_unit

__all__ = ["Estimate", "Status", "estimate", "plan_text", "run_for", "status"]

# Priors before a network or method has a record (2 cores of the docs' machine, `medium`):
TRAIN_PER_BUDGET_S = 1.0  # wall seconds per budget second (the budget is one thread's)
PASS_S = 120.0  # one evaluation pass: val and test embedded, or test under one noise level
FULL_MAP_S = 900.0  # rendering and embedding every sub-node of the test rooms
METHOD_S = 300.0  # a method that is not a bundled network, fit and evaluation
# the navigation test of one localizer, oracle navigator: val and test episodes rendered live
NAVIGATION_S = 900.0


@dataclass(frozen=True)
class Status:
    """Where a design stands on a dataset: its records and the plan they give."""

    design: Design
    data: Path
    folder: Path  # the recipe's records folder
    found: Found
    plan: Plan


def status(design: Design, data: Path, records: Path) -> Status:
    """The plan of ``design`` on the dataset at ``data`` given the records under ``records``."""
    identity = dataset_identity(open_dataset(data))
    folder = recipe_folder(records, identity)
    found = (
        read_records(folder, identity["recipe"])
        if folder.is_dir()
        else Found(folder, identity["recipe"])
    )
    return Status(design, data, folder, found, plan_units(design, found.units))


@dataclass(frozen=True)
class Estimate:
    seconds: float
    source: str  # "records" or "prior"


def estimate(unit: Unit, found: Found) -> Estimate:
    """How long ``unit`` should take, from the slowest record of the same training, else a
    prior."""
    same = [r for r in found.units.values() if r["trains"] == unit.trains]
    passes = sum(1 + len(e.noise) for e in unit.evaluations)
    maps = sum(e.full_map for e in unit.evaluations)
    tests = sum(e.navigation for e in unit.evaluations)
    navigation_s = max((_extra_s(r, "navigation") for r in found.units.values()
                        if _extra_s(r, "navigation")), default=NAVIGATION_S)  # fmt: skip
    if not unit.network:
        if same:
            base = max(r["seconds"]["wall"] - _extra_s(r, "navigation") for r in same)
            return Estimate(base + tests * navigation_s, "records")
        return Estimate(METHOD_S + FULL_MAP_S * maps + tests * navigation_s, "prior")
    assert unit.budget_s is not None
    train_rate, pass_s, map_s, source = TRAIN_PER_BUDGET_S, PASS_S, FULL_MAP_S, "prior"
    if same:
        source = "records"
        train_rate = max(_fit_s(r) / r["budget_s"] for r in same)
        pass_s = max(_pass_s(r) for r in same)
        maps_seen = [m["full_map"]["seconds"] for r in same for m in r["results"].values()
                     if "full_map" in m]  # fmt: skip
        map_s = max(maps_seen, default=FULL_MAP_S)
    return Estimate(
        unit.budget_s * train_rate + passes * pass_s + maps * map_s + tests * navigation_s, source
    )


def _fit_s(record: dict[str, Any]) -> float:
    return max(m["cost"]["fit_s"] for m in record["results"].values())


def _extra_s(record: dict[str, Any], part: str) -> float:
    """A record's seconds in ``part`` (``full_map``, ``navigation``) of its evaluations."""
    return sum(m[part]["seconds"] for m in record["results"].values() if part in m)


def _pass_s(record: dict[str, Any]) -> float:
    """A record's evaluation seconds per pass (its wall less its training, maps and
    navigation tests)."""
    rest = record["seconds"]["wall"] - _fit_s(record)
    extras = _extra_s(record, "full_map") + _extra_s(record, "navigation")
    passes = sum(1 + len(e["noise"]) for e in record["evaluations"])
    return max(rest - extras, 0.0) / passes


def _minutes(seconds: float) -> str:
    return f"{seconds / 60:.0f} min" if seconds >= 60 else f"{seconds:.0f} s"


def plan_text(s: Status) -> str:
    """The plan as a reader wants it: what is recorded, each unit still to run with its
    estimate (refused ones say so), what waits on a choice, and the time left."""
    lines = [
        f"records: {s.folder}",
        f"{len(s.plan.done)} of {s.plan.total}{'+' if s.plan.open_ended else ''} units recorded"
        + (f"; {len(s.found.left_out)} file(s) left out" if s.found.left_out else ""),
    ]
    lines += [f"  left out {why}" for why in s.found.left_out]
    total = 0.0
    for unit in s.plan.todo:
        got = estimate(unit, s.found)
        what = ", ".join(_evaluation_text(e) for e in unit.evaluations)
        if got.seconds > s.design.limit_s:
            lines.append(
                f"  refused {unit.name}: estimated {_minutes(got.seconds)} ({got.source}), above "
                f"the {_minutes(s.design.limit_s)} limit of a unit [{what}]"
            )
            continue
        total += got.seconds
        lines.append(f"  to run  {unit.name}: ~{_minutes(got.seconds)} ({got.source}) [{what}]")
    if s.plan.pending:
        lines.append(
            f"  pending {s.plan.pending}{'+' if s.plan.open_ended else ''} units: they train "
            "at the lr seed 0's records choose"
        )
    lines.append(f"time left: ~{_minutes(total)} for the units planned now")
    return "\n".join(lines)


def _evaluation_text(e: Any) -> str:
    extras = []
    if e.noise:
        extras.append(f"{len(e.noise)} noise")
    if e.full_map:
        extras.append("full map")
    if e.navigation:
        extras.append("navigation")
    return e.method + (f" ({', '.join(extras)})" if extras else "")


def run_for(
    design: Design,
    data: Path,
    records: Path,
    work: Path,
    *,
    seconds: float | None = None,
    units: int | None = None,
    say: Callable[[str], None] = lambda _text: None,
    docs: Path | None = None,
) -> list[Path]:
    """Run the units still missing, in the plan's order, until ``seconds`` are spent or
    ``units`` are run: a unit starts only if its estimate fits the time left (a smaller
    one later in the plan may still). The plan is read again after each unit, so a choice
    made by seed 0's records plans the units that wait on it; with ``docs``, the docs are
    written there after each unit. Returns the records written."""
    deadline = None if seconds is None else time.monotonic() + seconds
    written: list[Path] = []
    skipped: set[str] = set()
    while units is None or len(written) < units:
        s = status(design, data, records)
        startable = [u for u in s.plan.todo if u.name not in skipped]
        if not startable:
            break
        unit = None
        for candidate in startable:
            got = estimate(candidate, s.found)
            if got.seconds > design.limit_s:
                say(f"refused {candidate.name}: estimated {_minutes(got.seconds)}, above the "
                    f"{_minutes(design.limit_s)} limit")  # fmt: skip
                skipped.add(candidate.name)
                continue
            left = None if deadline is None else deadline - time.monotonic()
            if left is not None and got.seconds > left:
                say(f"not starting {candidate.name}: ~{_minutes(got.seconds)} needed, "
                    f"{_minutes(max(left, 0))} left")  # fmt: skip
                skipped.add(candidate.name)
                continue
            unit = candidate
            break
        if unit is None:
            break
        say(f"unit {unit.name}: started")
        clock = time.perf_counter()
        path = run_unit(unit, design, data, s.folder, work / unit.name, say)
        say(f"unit {unit.name}: recorded in {_minutes(time.perf_counter() - clock)}: {path}")
        written.append(path)
        if docs is not None:
            _write_docs(design, data, records, docs)
    return written


def _write_docs(design: Design, data: Path, records: Path, out: Path) -> None:
    write_docs(Records(design, status(design, data, records).found), out)
