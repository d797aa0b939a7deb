"""``seannet results doc``: docs/results.md, docs/learning-curve.md (with its plot) and
docs/leaderboard.md written from the records of one dataset recipe alone, no training.

A doc whose units are not all recorded says "k of N units measured" in its header and leaves
the cells of the missing ones empty (a row with some of its seeds says how many); it never
falls back to a figure of another recipe, protocol version or an older doc. Counts and words
("20 rooms", "3 seeds") come from the records. Nothing here depends on when or how fast a
record was made, so records made in several calls, on several machines, give the same doc as
one uninterrupted run.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from seannet.evaluation.covisibility_oracle import DIRECTIONS
from seannet.evaluation.intervals import (
    per_room_matrix,
    t_interval,
    two_level_difference,
    welch_difference,
    wilson_interval,
)
from seannet.methods.benchmark import summarize
from seannet.methods.cards import leaderboard_rows
from seannet.protocol.curve_plot import draw_curve
from seannet.protocol.design import (
    ABLATIONS,
    COVISIBILITY,
    FC,
    PROTOCOL_VERSION,
    SEANNET,
    Design,
    Plan,
    Unit,
    chosen_lrs,
    diagnostic_unit,
    network_of,
    plan_units,
)
from seannet.protocol.records import Found
from sgdata.fileio import atomic_write_bytes, atomic_write_text, save_png

__all__ = ["Records", "write_docs"]

CONTACT_SHEET = "images/covisibility-disagreements.png"  # under the docs folder
CURVE_BASE_SEEDS = 3  # the curve's seeds at the design's own budget (its other budgets: design)


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


# ------------------------------------------------------------------------------ cells


def _pct(x: float | None) -> str:
    return "" if x is None or (isinstance(x, float) and math.isnan(x)) else f"{100 * x:.1f}"


def _pm(entry: dict[str, float]) -> str:
    half = entry.get("ci95", float("nan"))
    return _pct(entry["mean"]) + ("" if math.isnan(half) else f" ± {_pct(half)}")


def _span(entry: dict[str, float], sign: bool = True) -> str:
    if math.isnan(entry.get("low", float("nan"))):
        return f"{100 * entry['mean']:+.1f}" if sign else _pct(entry["mean"])
    f = (lambda x: f"{100 * x:+.1f}") if sign else (lambda x: f"{100 * x:.1f}")
    return f"{f(entry['mean'])} [{f(entry['low'])}, {f(entry['high'])}]"


def _table(header: Sequence[str], rows: Sequence[Sequence[str]]) -> list[str]:
    return [
        "| " + " | ".join(header) + " |",
        "|" + "---|" * len(header),
        *("| " + " | ".join(r) + " |" for r in rows),
    ]


def _seeds_cell(got: int, asked: int) -> str:
    return str(got) if got == asked else f"{got} of {asked}"


def _weight(runs: list[dict[str, Any]]) -> tuple[list[str], np.ndarray]:
    rooms = sorted(runs[0]["per_room"])
    return rooms, np.array([runs[0]["room_triplets"][r] for r in rooms], dtype=np.float64)


def _difference(a: list[dict[str, Any]], b: list[dict[str, Any]]) -> dict[str, Any]:
    """A minus B on the same rooms: two-level (paired on rooms) and Welch over seeds."""
    rooms, weight = _weight(a)
    return {
        "rooms_seeds": two_level_difference(
            per_room_matrix(a, rooms), per_room_matrix(b, rooms), weight
        ),
        "seeds": welch_difference([r["accuracy"] for r in a], [r["accuracy"] for r in b]),
    }


def _verdict(d: dict[str, float], first: str) -> str:
    if d["low"] > 0:
        return f"{first} is above it"
    if d["high"] < 0:
        return f"{first} is below it"
    return "the two are not apart (the interval holds 0)"


# ------------------------------------------------------------------------------ results.md


def _header(r: Records, title: str, what: str) -> list[str]:
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


def _row_cells(r: Records, method: str) -> list[str]:
    """method | seeds | lr | val % | test % | rooms x seeds | recall@1 | tiers 0, 1 | training"""
    runs = r.runs(method)
    asked = r.design.row(method).seeds
    lr = r.lr(method)
    if not runs:
        return [f"`{method}`", f"0 of {asked}", "" if lr is None else f"{lr:g}", *[""] * 7]
    s = summarize(runs)
    record = r.unit_records(method)[0]
    training = record["training"]
    got = (
        f"{training['batches_per_epoch']} x {training['epochs']}"
        if training.get("batches_per_epoch")
        else ("its own fit" if runs[0]["trained"] else "no training")
    )
    return [
        f"`{method}`",
        _seeds_cell(len(runs), asked),
        "" if lr is None else f"{lr:g}",
        _pct(float(np.mean([x["val_accuracy"] for x in runs]))),
        _pm(s["accuracy"]),
        _span(s["accuracy_rooms_seeds"], sign=False),
        _pct(s["recall1"]["mean"]),
        _pct(s["per_tier"].get("0")),
        _pct(s["per_tier"].get("1")),
        got,
    ]


HEADLINE_HEADER = (
    "method", "seeds", "lr (val)", "val %", "test % (seeds, t)", "rooms x seeds 95 %",
    "recall@1 %", "tier 0 %", "tier 1 %", "batches x epochs",
)  # fmt: skip


def _differences(r: Records, first: str, others: Sequence[str]) -> list[str]:
    """``first`` minus each of ``others`` on the same rooms, with a verdict; empty cells for
    a pair not measured yet."""
    a = r.runs(first)
    rows = []
    for other in others:
        b = r.runs(other)
        if not a or not b:
            rows.append([f"`{other}`", "", "", ""])
            continue
        d = _difference(a, b)
        rows.append([
            f"`{other}`", _span(d["rooms_seeds"]), _span(d["seeds"]),
            _verdict(d["rooms_seeds"], first) if not math.isnan(d["rooms_seeds"]["low"]) else "",
        ])  # fmt: skip
    header = ["model", f"{first} minus it, rooms x seeds 95 % (points)", "seeds, Welch", "reading"]
    return _table(header, rows)


def _moved_table(r: Records, methods: Sequence[str]) -> list[str]:
    rows, bins = [], None
    for m in methods:
        runs = r.runs(m)
        if not runs:
            continue
        change = summarize(runs)["change"]["moved_objects"]
        bins = bins or list(change)
        rows.append([f"`{m}`", *(_pct(change[b]["accuracy"]) for b in bins)])
    if bins is None:
        return ["Not measured yet."]
    return _table(["model", *(f"{b} moved" for b in bins)], rows)


def _tier_table(r: Records, methods: Sequence[str]) -> list[str]:
    rows, tiers = [], None
    for m in methods:
        runs = r.runs(m)
        if not runs:
            continue
        per_tier = summarize(runs)["per_tier"]
        tiers = tiers or sorted(per_tier, key=int)
        rows.append([f"`{m}`", *(_pct(per_tier.get(t)) for t in tiers)])
    if tiers is None:
        return ["Not measured yet."]
    return _table(["model", *(f"tier {t}" for t in tiers)], rows)


def _noise_levels(run: dict[str, Any]) -> dict[str, float]:
    return {level["label"]: level["accuracy"] for level in run.get("box_noise", [])}


def _noise_table(r: Records) -> tuple[list[str], dict[str, float | None]]:
    """Accuracy under each noise level (the grid on one seed, the aim's point on every seed)
    and each noisy row's loss at the aim's point over the seeds that have it."""
    design = r.design
    labels = [n.label() for n in design.noise_grid]
    aim = design.aim.label()
    rows, losses = [], {}
    for row in (x for x in design.rows if x.noise):
        runs = r.runs(row.method)
        grid = next((_noise_levels(x) for x in runs if len(_noise_levels(x)) > 1), {})
        at_aim = [(x["accuracy"], _noise_levels(x)[aim]) for x in runs if aim in _noise_levels(x)]
        loss = float(np.mean([c - n for c, n in at_aim])) if at_aim else None
        losses[row.method] = loss
        cells = [_pct(grid.get(label)) for label in labels if label != aim]
        aim_cell = (
            f"{_pct(float(np.mean([n for _, n in at_aim])))} ({len(at_aim)} seeds)"
            if at_aim
            else ""
        )
        loss_cell = "" if loss is None else f"{100 * loss:.1f}"
        rows.append([f"`{row.method}`", *cells, aim_cell, loss_cell])
    header = ["model", *(label for label in labels if label != aim), f"{aim} (aim)",
              "loss at the aim, points"]  # fmt: skip
    return _table(header, rows), losses


def _full_map_table(r: Records) -> tuple[list[str], dict[str, float]]:
    rows, recall = [], {}
    for row in (x for x in r.design.rows if x.full_map):
        found = [x["full_map"] for x in r.runs(row.method) if "full_map" in x]
        if not found:
            rows.append([f"`{row.method}`", "", "", "", "", ""])
            continue
        f = found[0]
        recall[row.method] = f["recall@1"]
        by = " / ".join(f"{b}: {_pct(v['recall@1'])}" for b, v in f["by_moved"].items())
        rows.append([f"`{row.method}`", str(f["rooms"]), str(f["queries"]),
                     _pct(f["recall@1"]), _pct(f["recall@5"]), by])  # fmt: skip
    header = ["model", "rooms", "queries", "recall@1 %", "recall@5 %", "recall@1 by moved in view"]
    return _table(header, rows), recall


def _budget_table(r: Records) -> list[str]:
    """What each network's budget bought, and the calibration it rests on."""
    rows = []
    for name, record in sorted(r.found.calibrations.items()):
        c = record["calibration"]
        rows.append([
            f"`{record['network']}`", f"{c['budget_s']:g}", str(c["batches"]),
            f"{c['step_s']:.3f}", f"{100 * c['spread']:.0f} %", c.get("clock", ""),
            record["machine"]["cpu"], f"`{name}.json`",
        ])  # fmt: skip
    if not rows:
        return ["No calibration recorded yet."]
    header = ["network", "budget (s)", "batches / epoch", "step (s)", "rounds apart", "clock",
              "timed on", "record"]  # fmt: skip
    return _table(header, rows)


def _aims(r: Records, baseline: str | None, losses: dict[str, float | None],
          recall: dict[str, float]) -> list[str]:  # fmt: skip
    first = r.first
    ours = r.runs(first)
    rows = []
    mean = summarize(ours)["accuracy"]["mean"] if ours else None
    rows.append([f"{first} >= 90 %", _pct(mean), "" if mean is None else
                 ("yes" if mean >= 0.9 else "no")])  # fmt: skip
    if baseline and ours and r.runs(baseline):
        d = _difference(ours, r.runs(baseline))["rooms_seeds"]
        met = "yes" if d["mean"] >= 0.03 and d["low"] > 0 else "no"
        rows.append([f">= +3 points over {baseline}, interval clear of 0", _span(d), met])
    else:
        rows.append([">= +3 points over the strongest baseline, interval clear of 0", "", ""])
    loss = losses.get(first)
    rows.append(["loses <= 3 points at the aim's box noise",
                 "" if loss is None else f"{100 * loss:.1f} points",
                 "" if loss is None else ("yes" if loss <= 0.03 else "no")])  # fmt: skip
    got = recall.get(first)
    rows.append(["full-map recall@1 >= 90 %", _pct(got),
                 "" if got is None else ("yes" if got >= 0.9 else "no")])  # fmt: skip
    return _table(["aim", "measured", "met"], rows)


def strongest_baseline(r: Records, methods: Sequence[str]) -> str | None:
    """The headline baseline with the best val accuracy (every choice on val), among those
    with all their seeds recorded."""
    complete = [m for m in methods if m != r.first and
                len(r.runs(m)) == r.design.row(m).seeds]  # fmt: skip
    if not complete:
        return None
    return max(complete, key=lambda m: float(np.mean([x["val_accuracy"] for x in r.runs(m)])))


def _covisibility(r: Records, baseline: str | None) -> list[str]:
    """The covisibility oracle per tier and direction beside the thumbnail, the first row and
    the strongest baseline (each triplet's outcome from their records, mean over seeds), the
    share of triplets covisibility disagrees with, and the contact sheet."""
    record = r.found.units.get(diagnostic_unit(COVISIBILITY).name)
    if record is None:
        return ["Not measured yet (the `covisibility-oracle` unit)."]
    o = record["results"][COVISIBILITY]
    methods = [m for m in dict.fromkeys(("tiny-image", r.first, baseline)) if m and r.runs(m)]
    outcomes = {m: np.array([[c == "1" for c in x["test_correct"]] for x in r.runs(m)
                             if "test_correct" in x], dtype=float).mean(axis=0)
                for m in methods}  # fmt: skip
    tiers = np.array([int(t) for t in o["tier"]])
    directions = np.array(list(o["direction"]))
    right = np.array([c == "1" for c in o["correct"]])
    rows = []
    cells = [(t, d) for t in sorted(set(tiers)) for d in DIRECTIONS
             if ((tiers == t) & (directions == d)).any()]  # fmt: skip
    for t, d in [*cells, (None, None)]:
        mask = np.ones(len(tiers), bool) if t is None else (tiers == t) & (directions == d)
        w = wilson_interval(int(right[mask].sum()), int(mask.sum()))
        rows.append([
            "all" if t is None else str(t), "" if d is None else DIRECTIONS[d], str(w["n"]),
            _span(w, sign=False), f"{100 * (1 - w['mean']):.1f}",
            *(_pct(float(outcomes[m][mask].mean())) for m in methods),
        ])  # fmt: skip
    header = ["tier", "positive's step", "triplets", "oracle % (Wilson 95 %)",
              "covisibility disagrees %", *(f"`{m}` %" for m in methods)]  # fmt: skip
    overall = o["accuracy"]
    decidable = [
        [f"`{m}`", _pct(float(outcomes[m].mean())), _pct(float(outcomes[m][right].mean())),
         _pct(float(outcomes[m][~right].mean())) if (~right).any() else ""]
        for m in methods
    ]  # fmt: skip
    distance = [
        f"- `{m}` on all test triplets: {_pct(float(outcomes[m].mean()))} %, "
        f"{100 * (overall - float(outcomes[m].mean())):+.1f} points to the oracle's "
        f"{_pct(overall)} %."
        for m in methods if m != "tiny-image"
    ]  # fmt: skip
    return [
        'The oracle answers "the positive" when covisibility(anchor, positive) > '
        "covisibility(anchor, negative): the share of each view's pixels whose 3D point the "
        "other sees (depth rendered from the rooms, depth-consistent within 5 %, symmetric; "
        "`sgdata/render/covisibility.py`). Where it disagrees with the label, the label's "
        "metric order (k cells against k + 1) is not what the views share: an appearance-only "
        "method can only decide such a triplet by other cues. It reads poses and geometry, so "
        "it is a diagnostic, not a method. Models: each triplet's outcome from their records, "
        "mean over seeds.",
        "",
        *_table(header, rows),
        "",
        *distance,
        "",
        "Accuracy on the triplets the views decide (covisibility agrees with the label: "
        f"{int(right.sum())} of {len(right)}) beside the paper's, all triplets, and on the "
        "others:",
        "",
        *_table(["model", "all %", "decidable %", "not decidable %"], decidable),
        "",
        f"![triplets where covisibility disagrees with the label]({CONTACT_SHEET})",
        "",
        f"{len(o['disagreements'])} of the {o['triplets'] - int(right.sum())} triplets where "
        "covisibility disagrees with the label (anchor, positive, negative), spread evenly "
        "over them.",
    ]


def results_doc(r: Records) -> str:
    design = r.design
    # the headline: every row but the fc's and the ablations', in the design's order
    others = {x.method for x in FC + ABLATIONS}
    shown = [row.method for row in design.rows if row.method not in others]
    baseline = strongest_baseline(r, shown)
    noise, losses = _noise_table(r)
    full_map, recall = _full_map_table(r)
    out = _header(
        r,
        "Results: SeanNet against the strongest simple baselines",
        f"Every row is measured against the first, `{r.first}`"
        + (
            ": SeanNet as the `cpu` preset trains it (the paper's GCN fc, 4,096 wide, is "
            "`seannet`: its section below)."
            if r.first == SEANNET
            else "."
        ),
    )
    out += ["## Aims", "", *_aims(r, baseline, losses, recall), ""]
    out += [
        "## Headline",
        "",
        f"The strongest baseline, chosen on val among the complete rows: "
        f"{f'`{baseline}`' if baseline else 'not known yet'}. Intervals: seeds t (95 %) and "
        "rooms x seeds (a room bootstrap's variance plus the seeds', t on seeds - 1 dof).",
        "",
        *_table(HEADLINE_HEADER, [_row_cells(r, m) for m in shown]),
        "",
        f"### {r.first} minus each",
        "",
        *_differences(r, r.first, [m for m in shown if m != r.first]),
        "",
        "### By moved objects in view (mean over seeds, %)",
        "",
        *_moved_table(r, shown),
        "",
        "### By cascade tier (tier 0: same pose, another layout, against one step; %)",
        "",
        *_tier_table(r, shown),
        "",
        "## What the views can decide: the covisibility oracle",
        "",
        *_covisibility(r, baseline),
        "",
        "## Under labeler / detector box noise",
        "",
        "Triplet accuracy (%) on test with the boxes a labeler or detector would give: corners "
        "jittered by S x the box's size, objects missed with probability P; epsilon and lambda "
        "as chosen on clean val. The grid on one seed (the first trained after the lr was "
        "chosen), the aim's point on every seed; the loss is the clean accuracy minus the "
        "noisy one over the same seeds.",
        "",
        *noise,
        "",
        "## Full-map recall",
        "",
        "Each test query (a view of a layout other than 0) ranked against every sub-node of "
        f"its room's map: every reachable cell of layout 0 at spacing {design.map_spacing} x 4 "
        "headings, rendered live and embedded by the run; one seed per model.",
        "",
        *full_map,
    ]
    fc = [row.method for row in FC if row.method in {x.method for x in design.rows}]
    if fc:
        out += [
            "",
            "## The paper's GCN fc (4,096 wide) against fc512",
            "",
            *_table(HEADLINE_HEADER, [_row_cells(r, m) for m in [r.first, *fc]]),
            "",
            *_differences(r, r.first, fc),
        ]
    ablations = [row.method for row in ABLATIONS if row.method in {x.method for x in design.rows}]
    if ablations and fc:
        out += [
            "",
            "## Ablations: what each branch of the paper's SeanNet adds",
            "",
            "`seannet-image`: the image branch alone; `seannet-nolayout`: the paper's graph "
            "branch (GCN pathways, no layout pathway); `seannet-graph`: no image vector in the "
            "fusion. The same budget and selection as every row.",
            "",
            *_table(HEADLINE_HEADER, [_row_cells(r, m) for m in [fc[0], *ablations]]),
            "",
            *_differences(r, fc[0], ablations),
        ]
    out += [
        "",
        "## What each budget bought",
        "",
        "Each network's calibration (timed once, on one thread, on the machine named; every "
        "unit of the network trains its batches, whichever machine runs it):",
        "",
        *_budget_table(r),
        "",
        "## Accuracy against the training budget",
        "",
        "[learning-curve.md](learning-curve.md) holds the curve's tables.",
        "",
        *(["![accuracy against budget](learning-curve.png)", ""] if curve_points(r) else []),
        "## Not measured by this protocol",
        "",
        "- Navigation with each network as localizer (docs/navigation.md has its own runs).",
        "- The `paper` preset on a GPU (ResNet-50 at 224 px).",
        "",
    ]
    return "\n".join(out)


# ------------------------------------------------------------------------------ the curve


def curve_points(r: Records) -> dict[str, list[dict[str, Any]]]:
    """Per curve method, one point per budget with records: seeds, val and test intervals,
    what the budget bought; budgets ascending."""
    budgets = sorted([(r.design.budget_s, CURVE_BASE_SEEDS), *r.design.curve])
    points: dict[str, list[dict[str, Any]]] = {}
    for method in r.design.curve_methods:
        for budget, seeds in budgets:
            records = r.unit_records(method, budget)[:seeds]
            if not records:
                continue
            runs = [x["results"][method] for x in records]
            points.setdefault(method, []).append({
                "budget_s": budget, "seeds": len(runs), "asked": seeds,
                "lr": records[0]["lr"], "training": records[0]["training"],
                "val": t_interval([x["val_accuracy"] for x in runs]),
                "test": t_interval([x["accuracy"] for x in runs]),
            })  # fmt: skip
    return points


def _cell(interval: dict[str, float]) -> str:
    if interval["n"] < 2:
        return f"{100 * interval['mean']:.1f} (1 seed)"
    return f"{100 * interval['mean']:.1f} ± {100 * interval['ci95']:.1f}"


def _flattens(points: list[dict[str, Any]]) -> str:
    """Where val accuracy stops gaining a point per budget step (read on val, not test)."""
    if len(points) < 2:
        return "One budget only so far."
    pairs = list(zip(points, points[1:], strict=False))
    gains = [100 * (b["val"]["mean"] - a["val"]["mean"]) for a, b in pairs]
    steps = "; ".join(f"{a['budget_s']:g} to {b['budget_s']:g} s: {g:+.1f}"
                      for (a, b), g in zip(pairs, gains, strict=True))  # fmt: skip
    for (a, _), g in zip(pairs, gains, strict=True):
        if g < 1.0:
            return f"Flat from {a['budget_s']:g} s (val gains, points: {steps})."
    return f"Still rising at {points[-1]['budget_s']:g} s (val gains, points: {steps})."


def curve_doc(r: Records, plot: str) -> str:
    points = curve_points(r)
    out = _header(
        r,
        "Learning curve: accuracy against the training budget",
        "Each budget trains a network the batches its calibration at "
        f"{r.design.budget_s:g} s bought, scaled by the budget (no second timing), at the lr "
        f"val chose at {r.design.budget_s:g} s. Intervals: 95 % t over seeds.",
    )
    if points:
        out += [f"![accuracy against budget]({plot})", ""]
    budgets = sorted([(r.design.budget_s, CURVE_BASE_SEEDS), *r.design.curve])
    for method in r.design.curve_methods:
        have = {p["budget_s"]: p for p in points.get(method, [])}
        rows = []
        for budget, seeds in budgets:
            p = have.get(budget)
            if p is None:
                rows.append([f"{budget:g}", f"0 of {seeds}", "", "", "", ""])
                continue
            t = p["training"]
            rows.append([
                f"{budget:g}", _seeds_cell(p["seeds"], seeds),
                f"{t['batches_per_epoch']} x {t['epochs']}" if t.get("batches_per_epoch") else "",
                f"{p['lr']:g}", _cell(p["val"]), _cell(p["test"]),
            ])  # fmt: skip
        out += [
            f"## `{method}`",
            "",
            _flattens(points.get(method, [])),
            "",
            *_table(["budget (s)", "seeds", "batches x epochs", "lr", "val %", "test %"], rows),
            "",
        ]
    return "\n".join(out)


# ------------------------------------------------------------------------------ leaderboard


def leaderboard_doc(r: Records) -> str:
    cards = []
    for row in r.design.rows:
        runs = r.runs(row.method)
        if runs:
            cards.append({"method": row.method, "trained": runs[0]["trained"],
                          "summary": summarize(runs)})  # fmt: skip
    out = _header(
        r,
        "Leaderboard",
        "Every method of the protocol under the benchmark's measures (`seannet benchmark`), "
        "best test accuracy first; a method on fewer seeds than asked says so in results.md.",
    )
    if not cards:
        return "\n".join([*out, "No method measured yet.", ""])
    return "\n".join([*out, *leaderboard_rows(cards, timing=False), ""])


def write_docs(r: Records, out: Path) -> list[Path]:
    """results.md, learning-curve.md (+ .png) and leaderboard.md into ``out``, atomically."""
    out.mkdir(parents=True, exist_ok=True)
    written = []
    points = curve_points(r)
    plot = out / "learning-curve.png"
    if points:
        save_png(draw_curve(points), plot)
        written.append(plot)
    else:  # a plot of other records would be a stale figure
        plot.unlink(missing_ok=True)
    diagnostic = r.found.units.get(diagnostic_unit(COVISIBILITY).name)
    if diagnostic is not None:  # the record's contact sheet, where the doc shows it
        sheet = r.found.folder / diagnostic["results"][COVISIBILITY]["contact_sheet"]
        atomic_write_bytes(out / CONTACT_SHEET, sheet.read_bytes())
        written.append(out / CONTACT_SHEET)
    else:
        (out / CONTACT_SHEET).unlink(missing_ok=True)
    for name, text in (
        ("results.md", results_doc(r)),
        ("learning-curve.md", curve_doc(r, "learning-curve.png")),
        ("leaderboard.md", leaderboard_doc(r)),
    ):
        atomic_write_text(out / name, text)
        written.append(out / name)
    return written
