"""Recipes for furniture: tables, chairs, sofas, beds, shelving units, ..."""

from __future__ import annotations

import math

from sgdata.world.shapes.base import (
    DARK,
    METAL,
    WHITE,
    Attachment,
    Color,
    Part,
    ShapeBuild,
    Size,
    Surface,
    box,
    cylinder,
    recipe,
    shade,
    slab,
    sphere,
    tube,
)


def _legs(
    w: float, d: float, height: float, t: float, color: Color, *, inset: float = 0.0
) -> list[Part]:
    """Four square legs of side ``t`` at the corners of a w x d footprint, from the floor up."""
    xs = w / 2 - inset - t / 2
    ys = d / 2 - inset - t / 2
    return [
        box((t, t, height), (sx * xs, sy * ys, height / 2), color)
        for sx in (-1, 1)
        for sy in (-1, 1)
    ]


def _top(w: float, d: float, z: float, *, clearance: float = math.inf) -> Surface:
    """A full-footprint top surface at height ``z``."""
    return Surface(-w / 2, -d / 2, w / 2, d / 2, z, clearance=clearance)


def _knob(x: float, y_front: float, z: float, r: float = 0.012) -> Part:
    """A small metal pull knob standing proud of a front at ``y_front``."""
    return cylinder(r, 0.015, (x, y_front + 0.0075, z), METAL, axis="y", sections=10)


@recipe("table")
def table(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A table whose top is a surface.

    Variant 0: rectangular top on four legs with an apron; 1: round top on a pedestal;
    2: rectangular top on four legs with a lower shelf (a coffee table look).
    """
    w, d, h = size
    t = min(0.04, h * 0.08)
    v = variant % 3
    if v == 1:
        r = min(w, d) / 2
        parts = [
            cylinder(r, t, (0.0, 0.0, h - t / 2), color, sections=24),
            cylinder(min(0.05, r * 0.15), h - t, (0.0, 0.0, (h - t) / 2), shade(color, 0.8)),
            cylinder(r * 0.45, 0.03, (0.0, 0.0, 0.015), shade(color, 0.8), sections=20),
        ]
        a = r * 0.7
        return ShapeBuild(parts=parts, surfaces=[Surface(-a, -a, a, a, h)])
    leg = min(0.06, w * 0.08, d * 0.08)
    parts = [box((w, d, t), (0.0, 0.0, h - t / 2), color)]
    parts += _legs(w, d, h - t, leg, shade(color, 0.85), inset=0.03)
    apron = min(0.08, (h - t) * 0.2)
    if v == 0:
        parts.append(
            slab(
                (-w / 2 + 0.04, -d / 2 + 0.04, h - t - apron),
                (w / 2 - 0.04, d / 2 - 0.04, h - t),
                shade(color, 0.85),
            )
        )
    else:
        sz = min(0.12, h * 0.3)
        parts.append(
            slab(
                (-w / 2 + 0.03, -d / 2 + 0.03, sz),
                (w / 2 - 0.03, d / 2 - 0.03, sz + t * 0.6),
                color,
            )
        )
    return ShapeBuild(parts=parts, surfaces=[_top(w, d, h)])


@recipe("side_table")
def side_table(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A small table or nightstand whose top is a surface.

    Variant 0: a nightstand box with a drawer over an open niche; 1: four legs and a lower
    shelf; 2: a round top on a pedestal.
    """
    w, d, h = size
    v = variant % 3
    if v == 2:
        return table(size, 1, color)
    if v == 1:
        return table(size, 2, color)
    yf = -d / 2
    parts = [
        slab((-w / 2, yf + 0.02, 0.0), (w / 2, d / 2, h), color),
        slab((-w / 2 + 0.03, yf, 0.06), (w / 2 - 0.03, yf + 0.02, h * 0.45), DARK),
        slab(
            (-w / 2 + 0.02, yf + 0.01, h * 0.55),
            (w / 2 - 0.02, yf + 0.02, h - 0.03),
            shade(color, 1.1),
        ),
        _knob(0.0, yf, h * 0.775),
    ]
    return ShapeBuild(parts=parts, surfaces=[_top(w, d, h)])


@recipe("desk")
def desk(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A desk whose top is a surface.

    Variant 0: top on two side panels with a modesty panel; 1: four legs and a drawer pedestal
    on the right.
    """
    w, d, h = size
    t = min(0.04, h * 0.06)
    p = 0.03
    parts = [box((w, d, t), (0.0, 0.0, h - t / 2), color)]
    if variant % 2 == 0:
        parts += [
            slab((-w / 2, -d / 2 + 0.02, 0.0), (-w / 2 + p, d / 2, h - t), shade(color, 0.85)),
            slab((w / 2 - p, -d / 2 + 0.02, 0.0), (w / 2, d / 2, h - t), shade(color, 0.85)),
            slab(
                (-w / 2 + p, d / 2 - 0.05, h * 0.35),
                (w / 2 - p, d / 2 - 0.03, h - t),
                shade(color, 0.85),
            ),
        ]
    else:
        leg = 0.045
        parts += _legs(w, d, h - t, leg, METAL, inset=0.02)
        pw = min(0.42, w * 0.35)
        x0 = w / 2 - 0.02 - pw
        parts.append(
            slab((x0, -d / 2 + 0.04, 0.02), (w / 2 - 0.07, d / 2 - 0.04, h - t), shade(color, 0.9))
        )
        n = 3
        fh = (h - t - 0.04) / n
        for i in range(n):
            z0 = 0.03 + i * fh
            parts.append(
                slab(
                    (x0 + 0.01, -d / 2 + 0.02, z0 + 0.005),
                    (w / 2 - 0.08, -d / 2 + 0.04, z0 + fh - 0.005),
                    color,
                )
            )
            parts.append(_knob((x0 + w / 2 - 0.07) / 2, -d / 2 + 0.005, z0 + fh / 2))
    return ShapeBuild(parts=parts, surfaces=[_top(w, d, h)])


@recipe("dresser")
def dresser(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A chest of drawers whose top is a surface: rows of drawer fronts with knobs.

    Variant 0 stands on a plinth, variant 1 on four short legs.
    """
    w, d, h = size
    yf = -d / 2
    foot = 0.08
    parts: list[Part] = []
    if variant % 2 == 0:
        parts.append(slab((-w / 2 + 0.02, yf + 0.04, 0.0), (w / 2 - 0.02, d / 2, foot), DARK))
    else:
        parts += _legs(w, d - 0.04, foot, 0.04, shade(color, 0.7), inset=0.02)
        for p in parts:
            p.mesh.apply_translation((0.0, 0.02, 0.0))  # legs sit behind the drawer fronts
    parts.append(slab((-w / 2, yf + 0.02, foot), (w / 2, d / 2, h), color))
    rows = max(2, min(5, int((h - foot) / 0.22)))
    cols = 2 if w > 0.9 else 1
    fh = (h - foot - 0.03) / rows
    fw = (w - 0.04) / cols
    for i in range(rows):
        for j in range(cols):
            x0 = -w / 2 + 0.02 + j * fw
            z0 = foot + 0.01 + i * fh
            parts.append(
                slab(
                    (x0 + 0.004, yf + 0.005, z0 + 0.004),
                    (x0 + fw - 0.004, yf + 0.02, z0 + fh - 0.004),
                    shade(color, 1.08),
                )
            )
            parts.append(
                cylinder(
                    0.012,
                    0.005,
                    (x0 + fw / 2, yf + 0.0025, z0 + fh / 2),
                    METAL,
                    axis="y",
                    sections=10,
                )
            )
    return ShapeBuild(parts=parts, surfaces=[_top(w, d, h)])


@recipe("tv_stand")
def tv_stand(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A low media cabinet with open compartments and side doors; its top is a surface."""
    w, d, h = size
    yf = -d / 2
    foot = min(0.06, h * 0.15)
    parts = [
        slab((-w / 2, yf + 0.02, foot), (w / 2, d / 2, h), color),
        slab((-w / 2 + 0.03, yf + 0.03, 0.0), (w / 2 - 0.03, d / 2 - 0.03, foot), DARK),
    ]
    n = 3 if w > 1.2 else 2
    cw = (w - 0.04) / n
    for i in range(n):
        x0 = -w / 2 + 0.02 + i * cw
        if i in (0, n - 1) and variant % 2 == 0 and n == 3:
            parts.append(
                slab(
                    (x0 + 0.005, yf + 0.005, foot + 0.02),
                    (x0 + cw - 0.005, yf + 0.02, h - 0.02),
                    shade(color, 1.1),
                )
            )
            parts.append(
                slab(
                    (x0 + cw / 2 - 0.04, yf, h - 0.08),
                    (x0 + cw / 2 + 0.04, yf + 0.005, h - 0.065),
                    METAL,
                )
            )
        else:
            # an open niche: a dark recess face set back into the front
            parts.append(
                slab(
                    (x0 + 0.015, yf + 0.0, foot + 0.02),
                    (x0 + cw - 0.015, yf + 0.02, h - 0.02),
                    shade(color, 0.35),
                )
            )
    return ShapeBuild(parts=parts, surfaces=[_top(w, d, h)])


@recipe("chair")
def chair(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A dining chair: four legs, a seat and a back at +Y; the seat is a surface.

    Variant 0 has a solid back panel, variant 1 a slatted back.
    """
    w, d, h = size
    seat_z = min(0.47, h * 0.52)
    t = 0.04
    leg = min(0.04, w * 0.1)
    back = 0.03
    parts = _legs(w, d, seat_z - t, leg, shade(color, 0.8), inset=0.01)
    parts.append(box((w, d, t), (0.0, 0.0, seat_z - t / 2), color))
    by = d / 2 - back / 2 - 0.01
    for sx in (-1, 1):
        parts.append(
            box(
                (leg, back, h - seat_z),
                (sx * (w / 2 - 0.01 - leg / 2), by, (h + seat_z) / 2),
                shade(color, 0.8),
            )
        )
    if variant % 2 == 0:
        parts.append(
            box(
                (w - 0.04, back * 0.8, (h - seat_z) * 0.55),
                (0.0, by, h - (h - seat_z) * 0.3),
                color,
            )
        )
    else:
        parts.append(box((w - 0.04, back, 0.06), (0.0, by, h - 0.03), color))
        for sx in (-0.25, 0.0, 0.25):
            parts.append(
                box(
                    (0.03, back * 0.6, h - seat_z - 0.06),
                    (sx * w, by, (h + seat_z) / 2 - 0.03),
                    shade(color, 0.9),
                )
            )
    seat = Surface(-w / 2, -d / 2, w / 2, d / 2 - back - 0.01, seat_z)
    return ShapeBuild(parts=parts, surfaces=[seat])


@recipe("stool")
def stool(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A stool: a seat on legs with a foot rest; the seat is a surface.

    Variant 0 is a round bar stool with a foot ring, variant 1 a square stool with rails.
    """
    w, d, h = size
    t = min(0.05, h * 0.1)
    if variant % 2 == 0:
        r = min(w, d) / 2
        parts = [cylinder(r, t, (0.0, 0.0, h - t / 2), color, sections=20)]
        lr = r * 0.7
        for k in range(4):
            a = math.pi / 4 + k * math.pi / 2
            parts.append(
                cylinder(
                    0.015,
                    h - t,
                    (lr * math.cos(a), lr * math.sin(a), (h - t) / 2),
                    METAL,
                    sections=10,
                )
            )
        parts.append(tube(lr - 0.012, lr + 0.012, 0.02, (0.0, 0.0, h * 0.3), METAL, sections=20))
        a = r * 0.7
        return ShapeBuild(parts=parts, surfaces=[Surface(-a, -a, a, a, h)])
    leg = min(0.04, w * 0.12)
    parts = [box((w, d, t), (0.0, 0.0, h - t / 2), color)]
    parts += _legs(w, d, h - t, leg, shade(color, 0.8), inset=0.01)
    z = h * 0.3
    parts.append(
        slab(
            (-w / 2 + 0.02, -d / 2 + 0.025, z),
            (w / 2 - 0.02, -d / 2 + 0.045, z + 0.02),
            shade(color, 0.8),
        )
    )
    parts.append(
        slab(
            (-w / 2 + 0.02, d / 2 - 0.045, z),
            (w / 2 - 0.02, d / 2 - 0.025, z + 0.02),
            shade(color, 0.8),
        )
    )
    return ShapeBuild(parts=parts, surfaces=[_top(w, d, h)])


def _upholstered(size: Size, variant: int, color: Color, cushions: int) -> ShapeBuild:
    """Sofa and armchair: legs, base, back at +Y, two arms and seat/back cushions."""
    w, d, h = size
    leg_h = 0.07
    seat_z = min(0.46, h * 0.55)
    arm_w = min(0.18, w * 0.14)
    arm_h = min(seat_z + 0.22, h * 0.8)
    back_d = min(0.22, d * 0.25)
    cush_t = 0.12
    dark = shade(color, 0.8)
    parts = _legs(w - 0.06, d - 0.06, leg_h, 0.05, (0.2, 0.14, 0.1))
    parts.append(slab((-w / 2, -d / 2, leg_h), (w / 2, d / 2, seat_z - cush_t), dark))
    parts.append(slab((-w / 2, d / 2 - back_d, seat_z - cush_t), (w / 2, d / 2, h - 0.06), dark))
    for sx in (-1, 1):
        x0, x1 = sorted((sx * w / 2, sx * (w / 2 - arm_w)))
        top = arm_h - (arm_w / 2 if variant % 2 == 1 else 0.0)
        parts.append(slab((x0, -d / 2, leg_h), (x1, d / 2 - back_d, top), color))
        if variant % 2 == 1:
            # rolled arm: a bolster along the arm top
            parts.append(
                cylinder(
                    arm_w / 2,
                    d - back_d,
                    ((x0 + x1) / 2, -back_d / 2, top),
                    color,
                    axis="y",
                    sections=14,
                )
            )
    inner = w - 2 * arm_w
    cw = inner / cushions
    for i in range(cushions):
        x0 = -inner / 2 + i * cw
        parts.append(
            slab(
                (x0 + 0.005, -d / 2 + 0.01, seat_z - cush_t),
                (x0 + cw - 0.005, d / 2 - back_d, seat_z),
                color,
            )
        )
        parts.append(
            slab(
                (x0 + 0.01, d / 2 - back_d - 0.12, seat_z),
                (x0 + cw - 0.01, d / 2 - back_d, h - 0.02),
                shade(color, 1.08),
            )
        )
    # the back frame's top rail so the silhouette has a rounded crest
    parts.append(box((w, back_d, 0.06), (0.0, d / 2 - back_d / 2, h - 0.03), color))
    seat = Surface(-inner / 2, -d / 2 + 0.02, inner / 2, d / 2 - back_d - 0.12, seat_z)
    return ShapeBuild(parts=parts, surfaces=[seat])


@recipe("sofa")
def sofa(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A sofa with two or three seat cushions (by width); variant 1 has rolled arms."""
    return _upholstered(size, variant, color, 3 if size[0] > 1.9 else 2)


@recipe("armchair")
def armchair(size: Size, variant: int, color: Color) -> ShapeBuild:
    """An armchair: a one-cushion sofa; variant 1 has rolled arms."""
    return _upholstered(size, variant, color, 1)


@recipe("ottoman")
def ottoman(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A footstool; variant 0 is a tufted box on short legs, variant 1 a round pouf."""
    w, d, h = size
    if variant % 2 == 1:
        r = min(w, d) / 2
        parts = [
            cylinder(r, h - 0.02, (0.0, 0.0, (h - 0.02) / 2), color, sections=24),
            cylinder(r * 0.96, 0.02, (0.0, 0.0, h - 0.01), shade(color, 1.1), sections=24),
        ]
        a = r * 0.7
        return ShapeBuild(parts=parts, surfaces=[Surface(-a, -a, a, a, h)])
    leg_h = min(0.08, h * 0.25)
    parts = _legs(w - 0.04, d - 0.04, leg_h, 0.04, (0.2, 0.14, 0.1))
    parts.append(slab((-w / 2, -d / 2, leg_h), (w / 2, d / 2, h - 0.03), color))
    parts.append(
        slab(
            (-w / 2 + 0.02, -d / 2 + 0.02, h - 0.03),
            (w / 2 - 0.02, d / 2 - 0.02, h),
            shade(color, 1.1),
        )
    )
    return ShapeBuild(parts=parts, surfaces=[_top(w, d, h)])


@recipe("bed")
def bed(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A bed: frame, mattress, blanket, a headboard at +Y and pillows; the bed top (foot of the
    pillows) is a surface. Variant 1 adds a low footboard."""
    w, d, h = size
    head = 0.06
    frame_h = min(0.3, h * 0.3)
    mat_top = min(0.58, h * 0.55)
    wood = color
    blanket = ((0.45, 0.55, 0.7), (0.7, 0.45, 0.4))[variant % 2]
    x_in = w / 2 - 0.03
    foot = 0.04 if variant % 2 == 1 else 0.0
    parts = [
        slab((-w / 2, -d / 2, 0.0), (w / 2, d / 2 - head, frame_h), wood),
        slab((-w / 2, d / 2 - head, 0.0), (w / 2, d / 2, h), shade(wood, 0.9)),
        slab((-x_in, -d / 2 + 0.02 + foot, frame_h), (x_in, d / 2 - head, mat_top - 0.03), WHITE),
        # blanket over the foot two thirds, a touch thicker than the bare mattress
        slab(
            (-w / 2 + 0.01, -d / 2 + 0.01 + foot, frame_h + 0.05),
            (w / 2 - 0.01, d / 2 - head - (d - head) * 0.3, mat_top),
            blanket,
        ),
    ]
    if foot:
        parts.append(
            slab((-w / 2, -d / 2, 0.0), (w / 2, -d / 2 + foot, mat_top + 0.1), shade(wood, 0.9))
        )
    n = 2 if w > 1.1 else 1
    pw = (2 * x_in - 0.1) / n - 0.05
    for i in range(n):
        cx = -x_in + 0.05 + (i + 0.5) * (2 * x_in - 0.1) / n
        parts.append(
            sphere(
                0.5, (cx, d / 2 - head - 0.2, mat_top - 0.03 + 0.06), WHITE, scale=(pw, 0.3, 0.12)
            )
        )
    surf = Surface(-x_in, -d / 2 + 0.02 + foot, x_in, d / 2 - head - 0.4, mat_top)
    return ShapeBuild(parts=parts, surfaces=[surf])


@recipe("shelving_unit")
def shelving_unit(size: Size, variant: int, color: Color) -> ShapeBuild:
    """An open bookcase frame (sides, back, top) that attaches 2-4 Shelf boards.

    Each Shelf attachment spans its compartment: board at the bottom, height = spacing to the
    next board. Variant 0 has solid sides, variant 1 a corner-post frame.
    """
    w, d, h = size
    side = 0.025
    back = 0.015
    kick = 0.05
    t_top = 0.025
    parts = [
        slab((-w / 2, -d / 2, h - t_top), (w / 2, d / 2, h), color),
        slab(
            (-w / 2 + side, d / 2 - back, 0.0), (w / 2 - side, d / 2, h - t_top), shade(color, 0.75)
        ),
        slab(
            (-w / 2 + side, -d / 2 + 0.02, 0.0),
            (w / 2 - side, d / 2 - back, kick),
            shade(color, 0.8),
        ),
    ]
    if variant % 2 == 0:
        for sx in (-1, 1):
            x0, x1 = sorted((sx * w / 2, sx * (w / 2 - side)))
            parts.append(slab((x0, -d / 2, 0.0), (x1, d / 2, h - t_top), color))
    else:
        parts += _legs(w, d, h - t_top, side, color)
    n = max(2, min(4, int(h / 0.4)))
    spacing = (h - t_top - kick) / n
    inner = (w - 2 * side, d - back, spacing)
    attachments = [Attachment("Shelf", inner, 0.0, -back / 2, kick + i * spacing) for i in range(n)]
    return ShapeBuild(parts=parts, surfaces=[_top(w, d, h)], attachments=attachments)


@recipe("shelf")
def shelf(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A shelf board at the bottom of its compartment; its top is a surface whose clearance is
    the compartment height (the part's own height)."""
    w, d, h = size
    t = min(0.025, h * 0.2)
    parts = [box((w, d, t), (0.0, 0.0, t / 2), color)]
    return ShapeBuild(parts=parts, surfaces=[_top(w, d, t, clearance=h - t)])
