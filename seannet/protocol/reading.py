"""The records of one recipe read through a design (each method's runs at the lr val chose),
and what every generated doc shares: its cells, its tables and its header (status, protocol,
stamp)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from seannet import markdown
from seannet.evaluation.intervals import per_room_matrix, two_level_difference, welch_difference
from seannet.markdown import table
from seannet.protocol.design import (
    PROTOCOL_VERSION,
    Design,
    Plan,
    Unit,
    chosen_lrs,
    navigation_unit,
    network_of,
    plan_units,
)
from seannet.protocol.records import Found

__all__ = [
    "Records",
    "difference",
    "header",
    "pct",
    "pm",
    "seeds_cell",
    "span",
    "strongest_baseline",
    "table",
    "verdict",
]


@dataclass
class Records:
    """The records of one recipe, read through the design: each method's runs at its chosen
    lr, per budget."""

    design: Design
    found: Found

    def __post_init__(self) -> None:
        self.plan: Plan = plan_units(self.design, self.found.units)
        self._lrs: dict[str, dict[str, float] | None] = {}
        self.first = self.design.rows[0].method  # every other row is measured against it

    def lr(self, method: str) -> float | None:
        """The lr val chose for a model spec (None: not chosen yet, or not a network)."""
        network = network_of(method)
        if network is None:
            return None
        if network not in self._lrs:
            self._lrs[network] = chosen_lrs(self.design, network, self.found.units)
        chosen = self._lrs[network]
        return None if chosen is None else chosen[method]

    def unit_records(self, method: str, budget: float | None = None) -> list[dict[str, Any]]:
        """The records of ``method``'s seeds at ``budget`` (default: the design's) at its
        chosen lr, seed order, those recorded only."""
        if method not in {r.method for r in self.design.rows}:
            return []
        row = self.design.row(method)
        network = network_of(method)
        if network is None:
            names = [Unit(method, s, None, None, (), False).name for s in range(row.seeds)]
        else:
            lr = self.lr(method)
            if lr is None:
                return []
            budget = self.design.budget_s if budget is None else budget
            names = [
                Unit(network, s, budget, lr, ()).name for s in range(self.seeds(method, budget))
            ]
        return [self.found.units[n] for n in names if method in self.found.units.get(n, {}).get(
            "results", {})]  # fmt: skip

    def seeds(self, method: str, budget: float | None = None) -> int:
        """Seeds the design asks of ``method`` at ``budget``."""
        if budget is None or budget == self.design.budget_s:
            return self.design.row(method).seeds
        return dict(self.design.curve)[budget]

    def runs(self, method: str, budget: float | None = None) -> list[dict[str, Any]]:
        """``method``'s per-seed results (the benchmark harness's) at its chosen lr."""
        return [r["results"][method] for r in self.unit_records(method, budget)]

    def navigation(self, method: str) -> list[dict[str, Any]]:
        """``method``'s navigation tests, seed order, those recorded only (at its chosen lr)."""
        nav = self.design.navigation
        if nav is None or method not in nav.methods:
            return []
        lr = self.lr(method)
        if network_of(method) is not None and lr is None:
            return []
        names = [navigation_unit(self.design, method, s, lr).name for s in range(nav.seeds)]
        results = [self.found.units.get(n, {}).get("results", {}).get(method, {}) for n in names]
        return [r["navigation"] for r in results if "navigation" in r]


# ------------------------------------------------------------------------------ cells


def pct(x: float | None) -> str:
    """A share as a percent cell; empty for a figure not measured (never a dash or a zero)."""
    return "" if x is None or (isinstance(x, float) and math.isnan(x)) else markdown.pct(x)


def pm(entry: dict[str, float]) -> str:
    half = entry.get("ci95", float("nan"))
    return pct(entry["mean"]) + ("" if math.isnan(half) else f" ± {pct(half)}")


def span(entry: dict[str, float], sign: bool = True) -> str:
    if math.isnan(entry.get("low", float("nan"))):
        return f"{100 * entry['mean']:+.1f}" if sign else pct(entry["mean"])
    f = (lambda x: f"{100 * x:+.1f}") if sign else (lambda x: f"{100 * x:.1f}")
    return f"{f(entry['mean'])} [{f(entry['low'])}, {f(entry['high'])}]"


def seeds_cell(got: int, asked: int) -> str:
    return str(got) if got == asked else f"{got} of {asked}"


def _weight(runs: list[dict[str, Any]]) -> tuple[list[str], np.ndarray]:
    rooms = sorted(runs[0]["per_room"])
    return rooms, np.array([runs[0]["room_triplets"][r] for r in rooms], dtype=np.float64)


def difference(a: list[dict[str, Any]], b: list[dict[str, Any]]) -> dict[str, Any]:
    """A minus B on the same rooms: two-level (paired on rooms) and Welch over seeds."""
    rooms, weight = _weight(a)
    return {
        "rooms_seeds": two_level_difference(
            per_room_matrix(a, rooms), per_room_matrix(b, rooms), weight
        ),
        "seeds": welch_difference([r["accuracy"] for r in a], [r["accuracy"] for r in b]),
    }


def verdict(d: dict[str, float], first: str) -> str:
    if d["low"] > 0:
        return f"{first} is above it"
    if d["high"] < 0:
        return f"{first} is below it"
    return "the two are not apart (the interval holds 0)"


def header(r: Records, title: str, what: str) -> list[str]:
    """Title, the status (complete, or k of N units), the protocol and the stamp."""
    plan, found, design = r.plan, r.found, r.design
    total = f"{plan.total}{'+' if plan.open_ended else ''}"
    if not plan.todo and not plan.pending:
        state = f"**Complete**: all {plan.total} units of the protocol are recorded."
    else:
        state = (
            f"**{len(plan.done)} of {total} units measured**: empty cells wait on the others "
            "(`seannet results plan` lists them; `seannet results run --for 50m` runs them)."
        )
    identity = next(iter(found.units.values()), {}).get("dataset", {})
    commits = ", ".join(
        f"`{c[:10]}`" + (" (with uncommitted changes)" if d else "") for c, d in found.commits
    )
    shas = ", ".join(f"`{s[:16]}…`" for s in found.content_sha256s)
    lines = [
        f"# {title}",
        "",
        f"Written by `seannet results doc` from the records of `{found.folder.name}` alone "
        f"(a folder of `results/records/`); no figure is typed. {what}",
        "",
        state,
        "",
        f"- Protocol version {PROTOCOL_VERSION}: every training run gets {design.budget_s:g} s of "
        "one thread's compute (batches per epoch from one calibration per network, recorded); "
        "each network's lr chosen on val with seed 0 from "
        f"{{{', '.join(f'{lr:g}' for lr in design.lrs)}}} (per method spec, ties: the smaller), "
        "its other seeds at that lr; every choice of a method (epsilon, lambda, a kernel) on "
        "val; test read once per run, and shown at the chosen lr only.",
    ]
    if identity:
        lines.append(
            f"- Dataset `{identity['name']}`, seed {identity['seed']}, format "
            f"{identity['format_version']}, recipe `{found.recipe[:16]}…`; content sha256 of "
            f"the records: {shas}."
        )
    if commits:
        lines.append(f"- Records made at commit {commits}.")
    if found.left_out:
        lines.append(
            f"- Left out: {len(found.left_out)} file(s) of the folder: "
            + "; ".join(found.left_out)
            + "."
        )
    return [*lines, ""]


def strongest_baseline(r: Records, methods: Sequence[str]) -> str | None:
    """The baseline with the best val accuracy (every choice on val) among the rows that are
    not the first row's own network (its +boxes and +box-kernel are it, with a scene term)
    and have a record."""
    own = network_of(r.first)
    candidates = [m for m in methods if m != r.first and r.runs(m)
                  and (own is None or network_of(m) != own)]  # fmt: skip
    if not candidates:
        return None
    return max(candidates, key=lambda m: float(np.mean([x["val_accuracy"] for x in r.runs(m)])))
