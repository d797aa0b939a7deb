"""Recipes for bathroom and linen items: towels, cloths, toilet paper, soap, brushes, ..."""

from __future__ import annotations

from sgdata.world.shapes.base import (
    WHITE,
    Color,
    ShapeBuild,
    Size,
    cylinder,
    elliptic_cylinder,
    frustum,
    recipe,
    shade,
    slab,
    sphere,
    tube,
)


@recipe("tissue_box")
def tissue_box(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A tissue box with an oval opening on top and a tissue poking out."""
    w, d, h = size
    body = h * 0.8
    parts = [
        slab((-w / 2, -d / 2, 0.0), (w / 2, d / 2, body), color),
        elliptic_cylinder(w * 0.3, d * 0.2, 0.002, (0.0, 0.0, body), shade(color, 0.5)),
        sphere(
            0.5,
            (0.0, 0.0, body + (h - body) / 2),
            WHITE,
            scale=(w * 0.3, d * 0.15, h - body),
            subdivisions=1,
        ),
    ]
    return ShapeBuild(parts=parts)


@recipe("folded_cloth")
def folded_cloth(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A towel or cloth: variant 0 folded in stacked layers, variant 1 rolled up along X."""
    w, d, h = size
    if variant % 2 == 1:
        r = min(d, h) / 2
        return ShapeBuild(
            parts=[
                cylinder(r, w * 0.98, (0.0, 0.0, r), color, axis="x", sections=14),
                cylinder(r * 0.5, w, (0.0, 0.0, r), shade(color, 0.8), axis="x", sections=10),
            ]
        )
    n = 3
    lh = h / n
    parts = []
    for k in range(n):
        inset = 0.004 * (k % 2)
        parts.append(
            slab(
                (-w / 2 + inset, -d / 2 + inset, k * lh),
                (w / 2 - inset, d / 2 - inset, (k + 1) * lh - 0.0005),
                shade(color, 1.0 - 0.08 * (k % 2)),
            )
        )
    return ShapeBuild(parts=parts)


@recipe("toilet_paper")
def toilet_paper(size: Size, variant: int, color: Color) -> ShapeBuild:
    """An upright roll of toilet paper with a brown cardboard core."""
    w, d, h = size
    r = min(w, d) / 2
    parts = [
        tube(r * 0.35, r, h, (0.0, 0.0, 0.0), color, sections=18),
        tube(r * 0.3, r * 0.36, h * 0.999, (0.0, 0.0, 0.0), (0.6, 0.45, 0.3), sections=12),
    ]
    return ShapeBuild(parts=parts)


@recipe("soap_bar")
def soap_bar(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A bar of soap: a rounded slab."""
    w, d, h = size
    parts = [
        slab((-w / 2 + 0.005, -d / 2 + 0.005, 0.0), (w / 2 - 0.005, d / 2 - 0.005, h * 0.5), color),
        sphere(0.5, (0.0, 0.0, h / 2), color, scale=(w, d, h)),
    ]
    return ShapeBuild(parts=parts)


@recipe("plunger")
def plunger(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A plunger standing on its rubber cup, with a wooden handle."""
    w, d, h = size
    r = min(w, d) / 2
    cup_h = min(h * 0.15, r * 1.2)
    parts = [
        frustum(r, r * 0.45, cup_h, (0.0, 0.0, 0.0), color, sections=16),
        cylinder(
            0.012, h - cup_h, (0.0, 0.0, cup_h + (h - cup_h) / 2), (0.6, 0.42, 0.22), sections=8
        ),
    ]
    return ShapeBuild(parts=parts)


@recipe("toilet_brush")
def toilet_brush(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A toilet scrub brush standing in its holder: a cup-like holder and a handle."""
    w, d, h = size
    r = min(w, d) / 2
    holder = h * 0.4
    parts = [
        cylinder(r, holder, (0.0, 0.0, holder / 2), color, sections=16),
        tube(r * 0.85, r, 0.01, (0.0, 0.0, holder), shade(color, 0.8), sections=16),
        cylinder(
            0.01, h - holder, (0.0, 0.0, holder + (h - holder) / 2), shade(color, 0.8), sections=8
        ),
        sphere(
            0.5, (0.0, 0.0, h - 0.015), shade(color, 0.8), scale=(0.03, 0.03, 0.03), subdivisions=1
        ),
    ]
    return ShapeBuild(parts=parts)
