"""The learning curve's plot: test (solid) and val (thin) accuracy against budget."""

from __future__ import annotations

import math
from typing import Any

from PIL import Image, ImageDraw, ImageFont

__all__ = ["draw_curve"]

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
