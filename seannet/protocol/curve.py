"""docs/learning-curve.md and its plot: accuracy on val and test against the training budget,
from the records of the curve's budgets (each scaling the one calibration at the design's
budget, at the lr val chose there)."""

from __future__ import annotations

import math
from typing import Any

from PIL import Image, ImageDraw, ImageFont

from seannet.evaluation.intervals import t_interval
from seannet.protocol.reading import Records, header, seeds_cell, table

__all__ = ["CURVE_BASE_SEEDS", "curve_doc", "curve_points", "draw_curve"]

CURVE_BASE_SEEDS = 3  # the curve's seeds at the design's own budget (its other budgets: design)


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
    out = header(
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
                f"{budget:g}", seeds_cell(p["seeds"], seeds),
                f"{t['batches_per_epoch']} x {t['epochs']}" if t.get("batches_per_epoch") else "",
                f"{p['lr']:g}", _cell(p["val"]), _cell(p["test"]),
            ])  # fmt: skip
        out += [
            f"## `{method}`",
            "",
            _flattens(points.get(method, [])),
            "",
            *table(["budget (s)", "seeds", "batches x epochs", "lr", "val %", "test %"], rows),
            "",
        ]
    return "\n".join(out)


COLOURS = ((70, 110, 200), (200, 90, 60), (60, 160, 90), (140, 90, 170))


def draw_curve(points: dict[str, list[dict[str, Any]]]) -> Image.Image:
    """Test (solid) and val (thin) accuracy against budget on a log axis, one colour a model;
    a seed's spread as a vertical bar."""
    font = ImageFont.load_default(size=12)
    width, height, left, top = 560, 320, 50, 30
    image = Image.new("RGB", (left + width + 220, top + height + 50), "white")
    draw = ImageDraw.Draw(image)
    budgets = sorted({p["budget_s"] for series in points.values() for p in series})
    values = [p[s]["mean"] for series in points.values() for p in series for s in ("val", "test")]
    low = math.floor(20 * min(values) - 1) / 20
    high = math.ceil(20 * max(values) + 1) / 20
    span = math.log(budgets[-1] / budgets[0]) or 1.0

    def x(b: float) -> float:
        return (
            left
            + 20
            + (width - 40) * (math.log(b / budgets[0]) / span if len(budgets) > 1 else 0.5)
        )

    def y(v: float) -> float:
        return top + height * (high - v) / (high - low)

    draw.rectangle([left, top, left + width, top + height], outline="black")
    for k in range(round((high - low) * 20) + 1):
        v = low + k / 20
        draw.line([left, y(v), left + width, y(v)], fill=(225, 225, 225))
        draw.text((6, y(v) - 7), f"{100 * v:.0f} %", fill="black", font=font)
    for b in budgets:
        draw.text((x(b) - 14, top + height + 6), f"{b:g} s", fill="black", font=font)
    draw.text(
        (left, 8), "triplet accuracy (test solid, val thin) against budget", fill="black", font=font
    )
    for k, (model, series) in enumerate(points.items()):
        colour = COLOURS[k % len(COLOURS)]
        for split, line_width in (("test", 3), ("val", 1)):
            xy = [(x(p["budget_s"]), y(p[split]["mean"])) for p in series]
            if len(xy) > 1:
                draw.line(xy, fill=colour, width=line_width)
            for p, (px, py) in zip(series, xy, strict=True):
                draw.ellipse([px - 3, py - 3, px + 3, py + 3], fill=colour)
                half = p[split]["ci95"]
                if split == "test" and not math.isnan(half):
                    draw.line(
                        [px, y(p[split]["mean"] - half), px, y(p[split]["mean"] + half)],
                        fill=colour,
                    )
        draw.text((left + width + 14, top + 10 + 20 * k), model, fill=colour, font=font)
    return image
