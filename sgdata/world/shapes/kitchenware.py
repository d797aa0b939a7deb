"""Recipes for kitchenware and kitchen appliances: dishes, cookware, utensils, bottles, ..."""

from __future__ import annotations

import math

from sgdata.world.shapes.base import (
    DARK,
    GLASS,
    METAL,
    WHITE,
    Color,
    Part,
    ShapeBuild,
    Size,
    Surface,
    box,
    cylinder,
    frustum,
    open_cylinder,
    recipe,
    shade,
    slab,
    sphere,
    tube,
)

WOOD: Color = (0.55, 0.38, 0.22)
LIQUID: Color = (0.25, 0.14, 0.07)


def _round_inside(r: float, wall: float, z: float, h: float) -> Surface:
    """The square inscribed in a round container's floor, as an inside surface."""
    a = (r - wall) * 0.7
    return Surface(-a, -a, a, a, z, clearance=h - z, inside=True)


def _loop_handle(x0: float, x1: float, y: float, z0: float, z1: float, t: float, c: Color):
    """A C-shaped handle on the +X side of a body, from three bars in the XZ plane."""
    return [
        slab((x0, y - t / 2, z1 - t), (x1, y + t / 2, z1), c),
        slab((x0, y - t / 2, z0), (x1, y + t / 2, z0 + t), c),
        slab((x1 - t, y - t / 2, z0), (x1, y + t / 2, z1), c),
    ]


@recipe("mug")
def mug(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A mug: an open cylinder with a loop handle on +X; variant 1 holds coffee."""
    w, d, h = size
    r = min(d / 2, w * 0.38)
    cx = -w / 2 + r
    wall = min(0.006, r * 0.2)
    parts = open_cylinder(r, h, (cx, 0.0, 0.0), wall, color, sections=16)
    if variant % 2 == 1:
        parts.append(cylinder(r - wall, 0.004, (cx, 0.0, h * 0.8), LIQUID, sections=16))
    t = min(0.01, h * 0.15)
    parts += _loop_handle(cx + r * 0.9, w / 2, 0.0, h * 0.2, h * 0.8, t, color)
    return ShapeBuild(parts=parts)


@recipe("cup")
def cup(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A drinking cup: an open tumbler; variant 1 is clear glass."""
    w, d, h = size
    r = min(w, d) / 2
    c = GLASS if variant % 2 == 1 else color
    wall = min(0.004, r * 0.15)
    return ShapeBuild(parts=open_cylinder(r, h, (0.0, 0.0, 0.0), wall * 2, c, sections=16))


@recipe("bowl")
def bowl(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A bowl: a foot, a flared body and a rim; the floor inside the rim is an inside surface."""
    w, d, h = size
    r = min(w, d) / 2
    wall = min(0.006, r * 0.1)
    foot = h * 0.15
    inside_z = h * 0.55
    parts = [
        frustum(r * 0.45, r * 0.55, foot, (0.0, 0.0, 0.0), color),
        frustum(r * 0.55, r * 0.97, inside_z - foot, (0.0, 0.0, foot), shade(color, 0.92)),
        tube(r - wall, r, h - inside_z + 0.005, (0.0, 0.0, inside_z - 0.005), color),
    ]
    return ShapeBuild(parts=parts, surfaces=[_round_inside(r, wall, inside_z, h)])


@recipe("plate")
def plate(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A plate: a disc with a raised rim; its top is a (non-inside) surface."""
    w, d, h = size
    r = min(w, d) / 2
    parts = [
        cylinder(r * 0.6, h * 0.5, (0.0, 0.0, h * 0.25), color, sections=20),
        tube(r * 0.55, r, h, (0.0, 0.0, 0.0), shade(color, 0.95), sections=20),
    ]
    a = r * 0.55 * 0.7
    return ShapeBuild(parts=parts, surfaces=[Surface(-a, -a, a, a, h * 0.5)])


@recipe("pot")
def pot(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A cooking pot: an open cylinder with handles; its floor is an inside surface.

    Variant 0 is a stock pot with two side handles, variant 1 a saucepan with one long
    handle on +X.
    """
    w, d, h = size
    ear = min(0.035, w * 0.12) if variant % 2 == 0 else w * 0.35
    r = min(d / 2, (w - 2 * ear) / 2) if variant % 2 == 0 else min(d / 2, (w - ear) / 2)
    cx = 0.0 if variant % 2 == 0 else -w / 2 + r
    wall = min(0.006, r * 0.08)
    parts = open_cylinder(r, h * 0.9, (cx, 0.0, 0.0), wall, color, sections=20)
    sides = (-1, 1) if variant % 2 == 0 else (1,)
    for sx in sides:
        x0, x1 = sorted((cx + sx * (r - wall), sx * w / 2))
        parts.append(slab((x0, -0.02, h * 0.75), (x1, 0.02, h * 0.83), DARK))
    s = _round_inside(r, wall, wall, h)
    return ShapeBuild(
        parts=parts,
        surfaces=[
            Surface(s.x0 + cx, s.y0, s.x1 + cx, s.y1, s.z, clearance=s.clearance, inside=True)
        ],
    )


@recipe("pan")
def pan(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A frying pan: a shallow round body with a long handle along -X; its floor is inside."""
    w, d, h = size
    r = min(d / 2, w * 0.33)
    cx = w / 2 - r
    body_h = min(h, 0.06)
    wall = min(0.005, r * 0.06)
    parts = open_cylinder(r, body_h, (cx, 0.0, 0.0), wall, color, sections=20)
    ht = min(0.018, body_h * 0.35)
    parts.append(
        slab(
            (-w / 2, -0.012, body_h - ht),
            (cx - r + wall, 0.012, body_h),
            DARK if variant % 2 == 0 else WOOD,
        )
    )
    s = _round_inside(r, wall, wall, body_h)
    moved = Surface(s.x0 + cx, s.y0, s.x1 + cx, s.y1, s.z, clearance=math.inf, inside=True)
    return ShapeBuild(parts=parts, surfaces=[moved])


@recipe("kettle")
def kettle(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A kettle: a rounded body, a lid knob, a spout on -X and an arched handle on top."""
    w, d, h = size
    r = min(d / 2, w * 0.36)
    body_h = h * 0.7
    spout = w / 2 - r
    parts = [
        frustum(r, r * 0.75, body_h, (spout / 2, 0.0, 0.0), color, sections=18),
        cylinder(r * 0.2, 0.02, (spout / 2, 0.0, body_h + 0.01), DARK, sections=10),
        # spout: a bar rising from the body side towards -X
        box(
            (spout + r * 0.3, 0.02, 0.02),
            (-w / 2 + (spout + r * 0.3) / 2, 0.0, body_h * 0.55),
            color,
        ),
    ]
    hx0, hx1 = spout / 2 - r * 0.55, spout / 2 + r * 0.55
    t = 0.018
    parts += [
        slab((hx0, -t / 2, h - t), (hx1, t / 2, h), DARK),
        slab((hx0, -t / 2, body_h - 0.01), (hx0 + t, t / 2, h), DARK),
        slab((hx1 - t, -t / 2, body_h - 0.01), (hx1, t / 2, h), DARK),
    ]
    return ShapeBuild(parts=parts)


def _utensil(w: float, d: float, h: float, head: float, color: Color) -> list[Part]:
    """A handle along +X, ending where the head (the -X ``head`` metres) begins."""
    t = min(h, 0.012)
    return [slab((-w / 2 + head, -min(d, 0.02) / 2, 0.0), (w / 2, min(d, 0.02) / 2, t), color)]


@recipe("knife")
def knife(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A knife lying flat: handle (palette colour) on +X, a steel blade on -X.

    Variant 0 is a kitchen knife with a pointed blade, variant 1 a round-ended table knife.
    """
    w, d, h = size
    blade = w * 0.6
    parts = [slab((-w / 2 + blade, -d / 2, 0.0), (w / 2, d / 2, h), color)]
    bd = d * (0.9 if variant % 2 == 0 else 0.55)
    parts.append(
        slab((-w / 2 + blade * 0.15, -bd / 2, 0.0), (-w / 2 + blade, bd / 2, h * 0.3), METAL)
    )
    tip = blade * 0.15
    parts.append(
        cylinder(bd / 2, h * 0.3, (-w / 2 + tip, 0.0, h * 0.15), METAL, sections=12)
        if variant % 2 == 1
        else slab((-w / 2, -bd / 2, 0.0), (-w / 2 + tip, 0.0, h * 0.3), METAL)
    )
    return ShapeBuild(parts=parts)


@recipe("butter_knife")
def butter_knife(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A table knife: the round-ended knife."""
    return knife(size, 1, color)


@recipe("fork")
def fork(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A fork lying flat: handle on +X, four tines on -X."""
    w, d, h = size
    head = w * 0.35
    parts = _utensil(w, d, h, head, color)
    parts.append(slab((-w / 2 + head * 0.55, -d / 2, 0.0), (-w / 2 + head, d / 2, h * 0.6), color))
    tw = d / 7
    for i in range(4):
        y0 = -d / 2 + i * 2 * tw
        parts.append(slab((-w / 2, y0, 0.0), (-w / 2 + head * 0.6, y0 + tw, h * 0.6), color))
    return ShapeBuild(parts=parts)


@recipe("spoon")
def spoon(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A spoon lying flat: handle on +X, an oval bowl on -X."""
    w, d, h = size
    head = w * 0.32
    parts = _utensil(w, d, h, head * 0.9, color)
    parts.append(
        sphere(0.5, (-w / 2 + head / 2, 0.0, h / 2), color, scale=(head, d, h), subdivisions=2)
    )
    return ShapeBuild(parts=parts)


@recipe("spatula")
def spatula(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A spatula lying flat: a handle on +X, a broad flat blade on -X."""
    w, d, h = size
    head = w * 0.3
    parts = [
        slab((-w / 2 + head, -0.012, 0.0), (w / 2, 0.012, h), color),
        slab((-w / 2, -d / 2, 0.0), (-w / 2 + head, d / 2, h * 0.35), shade(color, 0.8)),
    ]
    return ShapeBuild(parts=parts)


@recipe("ladle")
def ladle(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A ladle lying on its side: a deep round bowl on -X and a long handle."""
    w, d, h = size
    r = min(d / 2, h / 2, w * 0.2)
    parts = [
        sphere(r, (-w / 2 + r, 0.0, r), METAL),
        slab((-w / 2 + r * 1.5, -0.01, h - 0.012), (w / 2, 0.01, h), color),
        slab((-w / 2 + r * 1.5, -0.006, r), (-w / 2 + r * 1.5 + 0.012, 0.006, h), METAL),
    ]
    return ShapeBuild(parts=parts)


@recipe("bottle")
def bottle(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A bottle standing up: body, shoulder, neck and cap, with a label band.

    Variant 0 has a short neck with a screw cap (water, oil), variant 1 a long neck (wine).
    """
    w, d, h = size
    r = min(w, d) / 2
    long_neck = variant % 2 == 1
    body_h = h * (0.6 if long_neck else 0.75)
    shoulder = h * (0.12 if long_neck else 0.1)
    nr = r * 0.32
    neck_h = h - body_h - shoulder
    parts = [
        cylinder(r * 0.96, body_h, (0.0, 0.0, body_h / 2), color),
        frustum(r * 0.96, nr, shoulder, (0.0, 0.0, body_h), color),
        cylinder(nr, neck_h, (0.0, 0.0, body_h + shoulder + neck_h / 2), color, sections=12),
        # the label: a band just proud of the body
        cylinder(r, body_h * 0.35, (0.0, 0.0, body_h * 0.45), (0.93, 0.9, 0.8)),
        cylinder(
            nr * 1.15,
            h * 0.05,
            (0.0, 0.0, h - h * 0.025),
            DARK if long_neck else WHITE,
            sections=12,
        ),
    ]
    return ShapeBuild(parts=parts)


@recipe("wine_bottle")
def wine_bottle(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A wine bottle: the long-necked bottle with a dark capsule."""
    return bottle(size, 1, color)


@recipe("pump_bottle")
def pump_bottle(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A soap dispenser: body, collar and a pump head with a nozzle towards -Y."""
    w, d, h = size
    r = min(w, d) / 2
    body_h = h * 0.72
    parts = [
        cylinder(r, body_h, (0.0, 0.0, body_h / 2), color),
        cylinder(r * 0.4, h * 0.12, (0.0, 0.0, body_h + h * 0.06), WHITE, sections=12),
        slab((-r * 0.35, -d / 2, h - h * 0.16), (r * 0.35, r * 0.35, h), WHITE),
    ]
    return ShapeBuild(parts=parts)


@recipe("spray_bottle")
def spray_bottle(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A trigger spray bottle: body, a trigger head with its nozzle towards -Y."""
    w, d, h = size
    r = min(w / 2, d * 0.35)
    body_h = h * 0.7
    by = d / 2 - r
    head = WHITE if variant % 2 == 0 else DARK
    parts = [
        cylinder(r, body_h, (0.0, by, body_h / 2), color),
        cylinder(r * 0.45, h * 0.06, (0.0, by, body_h + h * 0.03), head, sections=12),
        slab((-r * 0.4, -d / 2, h * 0.8), (r * 0.4, by + r * 0.4, h), head),
        slab((-r * 0.15, by - r * 1.2, h * 0.66), (r * 0.15, by - r * 0.8, h * 0.82), head),
    ]
    return ShapeBuild(parts=parts)


@recipe("dish_sponge")
def dish_sponge(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A kitchen sponge: a soft block with a green scouring layer on top."""
    w, d, h = size
    parts = [
        box((w, d, h * 0.7), (0.0, 0.0, h * 0.35), color),
        box((w, d, h * 0.3), (0.0, 0.0, h * 0.85), (0.15, 0.45, 0.2)),
    ]
    return ShapeBuild(parts=parts)


@recipe("paper_towel_roll")
def paper_towel_roll(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A paper towel roll upright on a holder: base disc, roll and centre post."""
    w, d, h = size
    r = min(w, d) / 2
    parts = [
        cylinder(r, 0.012, (0.0, 0.0, 0.006), METAL if variant % 2 == 0 else WOOD),
        tube(r * 0.25, r * 0.92, h - 0.04, (0.0, 0.0, 0.012), color),
        cylinder(r * 0.1, h - 0.012, (0.0, 0.0, 0.012 + (h - 0.012) / 2), METAL, sections=8),
    ]
    return ShapeBuild(parts=parts)


@recipe("shaker")
def shaker(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A salt or pepper shaker: a glass or ceramic body with a metal cap (the palette colours
    the contents)."""
    w, d, h = size
    r = min(w, d) / 2
    body_h = h * 0.75
    parts = [
        cylinder(r, body_h, (0.0, 0.0, body_h / 2), color, sections=14),
        frustum(r, r * 0.7, h - body_h, (0.0, 0.0, body_h), METAL, sections=14),
    ]
    return ShapeBuild(parts=parts)


@recipe("toaster")
def toaster(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A two-slot toaster: body, two dark slots on top, a lever on the front."""
    w, d, h = size
    parts = [
        slab((-w / 2, -d / 2 + 0.015, 0.0), (w / 2, d / 2, h - 0.002), color),
        slab((-w * 0.1, -d / 2, h * 0.5), (w * 0.1, -d / 2 + 0.015, h * 0.6), DARK),
    ]
    for sx in (-1, 1):
        parts.append(
            slab(
                (sx * w * 0.22 - w * 0.1, -d * 0.35, h - 0.004),
                (sx * w * 0.22 + w * 0.1, d * 0.35, h),
                DARK,
            )
        )
    parts.append(
        slab((-w / 2 + 0.005, -d / 2 + 0.015, 0.0), (w / 2 - 0.005, d / 2 - 0.005, 0.015), DARK)
    )
    return ShapeBuild(parts=parts)


@recipe("microwave")
def microwave(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A microwave: a box with a dark glazed door on the left and a control panel on the
    right of its front; its top is a surface."""
    w, d, h = size
    yf = -d / 2
    panel = w * 0.25
    parts = [
        slab((-w / 2, yf + 0.01, 0.0), (w / 2, d / 2, h), color),
        slab(
            (-w / 2 + 0.02, yf + 0.004, 0.03),
            (w / 2 - panel - 0.01, yf + 0.01, h - 0.03),
            (0.05, 0.05, 0.06),
        ),
        slab(
            (w / 2 - panel + 0.01, yf + 0.004, 0.03),
            (w / 2 - 0.02, yf + 0.01, h - 0.03),
            shade(color, 0.75),
        ),
        slab(
            (w / 2 - panel * 0.7, yf, h * 0.55),
            (w / 2 - panel * 0.3, yf + 0.004, h * 0.7),
            (0.1, 0.3, 0.2),
        ),
        slab(
            (w / 2 - panel - 0.01, yf, 0.05), (w / 2 - panel + 0.005, yf + 0.004, h - 0.05), METAL
        ),
    ]
    top = Surface(-w / 2, -d / 2, w / 2, d / 2, h)
    return ShapeBuild(parts=parts, surfaces=[top])


@recipe("coffee_machine")
def coffee_machine(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A drip coffee maker: base with a hot plate, a back tower, an overhanging head and a
    glass carafe under it."""
    w, d, h = size
    tower_d = d * 0.4
    base_h = min(0.04, h * 0.12)
    head_h = h * 0.25
    parts = [
        slab((-w / 2, -d / 2, 0.0), (w / 2, d / 2, base_h), color),
        slab((-w / 2, d / 2 - tower_d, base_h), (w / 2, d / 2, h - head_h), color),
        slab((-w / 2, -d / 2, h - head_h), (w / 2, d / 2, h), color),
        slab(
            (-w * 0.2, -d / 2, h - head_h * 0.6), (w * 0.2, -d / 2 + 0.005, h - head_h * 0.3), DARK
        ),
    ]
    cr = min(w * 0.38, (d - tower_d) / 2 - 0.005)
    cy = -d / 2 + 0.005 + cr
    carafe_h = h - head_h - base_h - 0.01
    parts.append(cylinder(cr, carafe_h, (0.0, cy, base_h + carafe_h / 2), GLASS))
    parts.append(
        cylinder(cr * 0.98, carafe_h * 0.45, (0.0, cy, base_h + carafe_h * 0.45 / 2), LIQUID)
    )
    return ShapeBuild(parts=parts)
