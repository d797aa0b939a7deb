"""Recipes for fixtures and structure-bound objects: counters, sinks, stoves, windows, ..."""

from __future__ import annotations

import math

from sgdata.world.shapes.base import (
    DARK,
    GLASS,
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
    elliptic_cylinder,
    hollow_box,
    recipe,
    shade,
    slab,
    tube,
)

# Depth of the strip on a unit's front face that holds doors, drawers, knobs and handles: the
# body stops behind it so fronts never overlap the body (no z-fighting in renders).
FRONT = 0.03
COUNTER = 0.04  # thickness of the CounterTop slab a Cabinet carries
STONE: Color = (0.82, 0.8, 0.76)


def _top(w: float, d: float, z: float, *, inside: bool = False, clearance: float = math.inf):
    """The full-footprint top surface at height ``z``."""
    return Surface(-w / 2, -d / 2, w / 2, d / 2, z, clearance=clearance, inside=inside)


def _basin(size: Size, color: Color) -> ShapeBuild:
    """An open-top basin whose floor is an inside surface (sink and bathtub basins)."""
    w, d, h = size
    wall = min(0.03, w / 6, d / 6, h / 3)
    parts = hollow_box(size, (0.0, 0.0, 0.0), wall, color, inner=shade(color, 0.9))
    inner = Surface(
        -w / 2 + wall,
        -d / 2 + wall,
        w / 2 - wall,
        d / 2 - wall,
        wall,
        clearance=h - wall,
        inside=True,
    )
    return ShapeBuild(parts=parts, surfaces=[inner])


def _doors(
    x0: float, x1: float, z0: float, z1: float, y_front: float, n: int, color: Color
) -> list[Part]:
    """``n`` door panels side by side on a front face, each with a vertical bar handle."""
    parts: list[Part] = []
    gap = 0.006
    width = (x1 - x0) / n
    for i in range(n):
        a, b = x0 + i * width + gap / 2, x0 + (i + 1) * width - gap / 2
        parts.append(slab((a, y_front + 0.012, z0), (b, y_front + FRONT, z1), color))
        # handles sit near the meeting edge of a pair, or at the right edge of a single door
        hx = b - 0.04 if (n == 1 or i == 0) else a + 0.04
        hz = z1 - min(0.12, (z1 - z0) * 0.3)
        parts.append(
            slab((hx - 0.008, y_front, hz - 0.05), (hx + 0.008, y_front + 0.012, hz + 0.05), METAL)
        )
    return parts


@recipe("counter_top")
def counter_top(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A counter slab; its whole top is a surface."""
    w, d, h = size
    return ShapeBuild(parts=[box((w, d, h), (0.0, 0.0, h / 2), color)], surfaces=[_top(w, d, h)])


@recipe("base_cabinet")
def base_cabinet(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A kitchen base cabinet: body, plinth, doors; attaches a CounterTop and a top Drawer.

    Variant 0 has one door below narrow drawers (two when wider than 0.6 m), variant 1 always
    two doors.
    """
    w, d, h = size
    body_h = h - COUNTER
    kick = 0.08
    drawer_h = min(0.15, body_h * 0.2)
    drawer_z = body_h - drawer_h - 0.02
    yf = -d / 2
    parts = [
        slab((-w / 2, yf + FRONT, 0.0), (w / 2, d / 2, body_h), color),
        slab((-w / 2 + 0.01, yf + 0.02, 0.0), (w / 2 - 0.01, yf + FRONT, kick), DARK),
        # frame strip around the drawer so the front reads as one carcass
        slab(
            (-w / 2, yf + 0.012, drawer_z - 0.012),
            (w / 2, yf + FRONT, drawer_z - 0.006),
            shade(color, 0.8),
        ),
    ]
    n = 2 if (variant % 2 == 1 or w > 0.6) else 1
    parts += _doors(-w / 2 + 0.01, w / 2 - 0.01, kick + 0.005, drawer_z - 0.015, yf, n, color)
    attachments = [
        Attachment("CounterTop", (w, d, COUNTER), 0.0, 0.0, body_h),
        Attachment("Drawer", (w - 0.06, FRONT, drawer_h), 0.0, yf + FRONT / 2, drawer_z),
    ]
    return ShapeBuild(parts=parts, attachments=attachments)


@recipe("drawer")
def drawer(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A drawer front: a panel with a horizontal bar handle proud of it."""
    w, d, h = size
    lip = min(0.012, d * 0.4)
    hw = min(0.16, w * 0.4)
    parts = [
        slab((-w / 2, -d / 2 + lip, 0.0), (w / 2, d / 2, h), color),
        slab((-hw / 2, -d / 2, h / 2 - 0.008), (hw / 2, -d / 2 + lip, h / 2 + 0.008), METAL),
    ]
    return ShapeBuild(parts=parts)


@recipe("sink")
def sink(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A sink unit with a faucet; attaches a SinkBasin recessed into its top.

    Variant 0 is a cabinet vanity with two doors, variant 1 a pedestal wash basin.
    """
    w, d, h = size
    faucet_h = min(0.25, 0.2 * h)
    top_z = h - faucet_h
    bw, bd = min(w - 0.16, 0.6), min(d - 0.2, 0.45)
    bh = min(0.2, top_z * 0.25)
    by = -d / 2 + 0.07 + bd / 2
    bx0, bx1, by0, by1 = -bw / 2, bw / 2, by - bd / 2, by + bd / 2
    ring_z = top_z - bh - 0.01
    parts: list[Part] = []
    # the counter ring around the basin opening: a band in the body colour, a stone top layer
    for z0, z1, c in ((ring_z, top_z - COUNTER, color), (top_z - COUNTER, top_z, STONE)):
        parts += [
            slab((-w / 2, -d / 2 + (FRONT if c is color else 0.0), z0), (w / 2, by0, z1), c),
            slab((-w / 2, by1, z0), (w / 2, d / 2, z1), c),
            slab((-w / 2, by0, z0), (bx0, by1, z1), c),
            slab((bx1, by0, z0), (w / 2, by1, z1), c),
        ]
    if variant % 2 == 0:
        parts.append(slab((-w / 2, -d / 2 + FRONT, 0.0), (w / 2, d / 2, ring_z), color))
        parts.append(
            slab((-w / 2 + 0.01, -d / 2 + 0.02, 0.0), (w / 2 - 0.01, -d / 2 + FRONT, 0.08), DARK)
        )
        parts += _doors(
            -w / 2 + 0.01, w / 2 - 0.01, 0.085, top_z - COUNTER - 0.01, -d / 2, 2, color
        )
    else:
        r = min(w, d) * 0.14
        parts.append(cylinder(r, ring_z, (0.0, by, ring_z / 2), STONE))
    # faucet: a column behind the basin and a spout reaching over it
    fy = (by1 + d / 2) / 2
    fr = min(0.02, (d / 2 - by1) / 3)
    col_h = faucet_h * 0.9
    parts.append(cylinder(fr, col_h, (0.0, fy, top_z + col_h / 2), METAL, sections=12))
    reach = min(0.16, fy - by0 - 0.05)
    parts.append(
        slab((-fr * 0.8, fy - reach, top_z + col_h - 2 * fr), (fr * 0.8, fy, top_z + col_h), METAL)
    )
    for sx in (-1, 1):
        parts.append(
            cylinder(
                fr * 0.9,
                faucet_h * 0.3,
                (sx * 0.09, fy, top_z + faucet_h * 0.15),
                METAL,
                sections=12,
            )
        )
    attachments = [Attachment("SinkBasin", (bw, bd, bh), 0.0, by, top_z - bh)]
    return ShapeBuild(parts=parts, attachments=attachments)


@recipe("sink_basin")
def sink_basin(size: Size, variant: int, color: Color) -> ShapeBuild:
    """An open-top sink basin; its floor is an inside surface."""
    return _basin(size, color)


@recipe("stove")
def stove(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A freestanding range: oven with a glazed door and handle, a control strip; attaches
    four StoveBurners on the cooktop and four StoveKnobs on the front.

    Variant 0 has a black cooktop, variant 1 a cooktop in the body colour.
    """
    w, d, h = size
    top_z = h - 0.02
    yf = -d / 2
    cook = DARK if variant % 2 == 0 else shade(color, 0.85)
    panel_z = top_z - 0.13
    parts = [
        slab((-w / 2, yf + FRONT, 0.0), (w / 2, d / 2, top_z - 0.01), color),
        slab((-w / 2, -d / 2, top_z - 0.01), (w / 2, d / 2, top_z), cook),
        slab((-w / 2, yf + 0.012, panel_z), (w / 2, yf + FRONT, top_z - 0.01), shade(color, 0.75)),
        slab((-w / 2 + 0.01, yf + 0.02, 0.0), (w / 2 - 0.01, yf + FRONT, 0.09), DARK),
        # oven door, its window and a bar handle across the top
        slab((-w / 2 + 0.02, yf + 0.012, 0.1), (w / 2 - 0.02, yf + FRONT, panel_z - 0.015), color),
        slab((-w / 2 + 0.1, yf + 0.006, 0.22), (w / 2 - 0.1, yf + 0.012, panel_z - 0.12), DARK),
        cylinder(0.008, w - 0.16, (0.0, yf + 0.008, panel_z - 0.05), METAL, axis="x", sections=10),
    ]
    r = min(w, d) * 0.13
    burners = [
        Attachment("StoveBurner", (2 * r, 2 * r, 0.02), sx * w / 4, sy * d / 4.5, top_z)
        for sy in (-1, 1)
        for sx in (-1, 1)
    ]
    kz = (panel_z + top_z - 0.01) / 2 - 0.0225
    knobs = [
        Attachment("StoveKnob", (0.045, FRONT, 0.045), x, yf + FRONT / 2, kz)
        for x in (-0.3 * w, -0.15 * w, 0.15 * w, 0.3 * w)
    ]
    return ShapeBuild(parts=parts, attachments=burners + knobs)


@recipe("stove_burner")
def stove_burner(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A burner: a dark disc inside a grate ring; its top holds pots and pans."""
    w, d, h = size
    r = min(w, d) / 2
    parts = [
        cylinder(r * 0.55, h * 0.6, (0.0, 0.0, h * 0.3), shade(color, 0.6)),
        tube(r * 0.8, r, h, (0.0, 0.0, 0.0), color),
        box((2 * r * 0.8, 0.01, h * 0.5), (0.0, 0.0, h * 0.75), color),
        box((0.01, 2 * r * 0.8, h * 0.5), (0.0, 0.0, h * 0.75), color),
    ]
    return ShapeBuild(parts=parts, surfaces=[Surface(-r * 0.7, -r * 0.7, r * 0.7, r * 0.7, h)])


@recipe("stove_knob")
def stove_knob(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A control knob on a stove front: a cylinder along -Y with a pointer ridge."""
    w, d, h = size
    r = min(w, h) / 2
    parts = [
        cylinder(r, d * 0.6, (0.0, d / 2 - d * 0.3, h / 2), color, axis="y", sections=12),
        box((r * 0.3, d * 0.4, r * 1.6), (0.0, -d / 2 + d * 0.2, h / 2), shade(color, 0.6)),
    ]
    return ShapeBuild(parts=parts)


@recipe("fridge")
def fridge(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A fridge: body with a freezer/fridge door split and bar handles; its top is a surface.

    Variant 0 has the freezer on top, variant 1 at the bottom.
    """
    w, d, h = size
    yf = -d / 2
    split = h * (0.68 if variant % 2 == 0 else 0.36)
    parts = [
        slab((-w / 2, yf + 0.04, 0.0), (w / 2, d / 2, h), color),
        slab((-w / 2 + 0.02, yf + 0.03, 0.0), (w / 2 - 0.02, yf + 0.04, 0.06), DARK),
        slab((-w / 2, yf + 0.015, 0.06), (w / 2, yf + 0.04, split - 0.008), color),
        slab((-w / 2, yf + 0.015, split + 0.008), (w / 2, yf + 0.04, h), color),
        slab((-w / 2, yf + 0.02, split - 0.008), (w / 2, yf + 0.04, split + 0.008), DARK),
    ]
    hx = w / 2 - 0.06
    for z0, z1 in ((0.06, split - 0.008), (split + 0.008, h)):
        length = min(0.5, (z1 - z0) * 0.6)
        zc = split + 0.04 + length / 2 if z0 > split - 0.01 else split - 0.04 - length / 2
        parts.append(
            slab(
                (hx - 0.012, yf, zc - length / 2), (hx + 0.012, yf + 0.015, zc + length / 2), METAL
            )
        )
    return ShapeBuild(parts=parts, surfaces=[_top(w, d, h)])


@recipe("window")
def window(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A window: frame, light-blue glass and glazing bars; the wall side is +Y.

    Variant 0 has a cross (four panes), 1 a single vertical bar, 2 a 3x2 grid.
    """
    w, d, h = size
    f = min(0.06, w / 10, h / 10)
    bar = f * 0.5
    parts = [
        slab((-w / 2, -d / 2, 0.0), (w / 2, d / 2, f * 1.3), color),
        slab((-w / 2, -d / 2, h - f), (w / 2, d / 2, h), color),
        slab((-w / 2, -d / 2, 0.0), (-w / 2 + f, d / 2, h), color),
        slab((w / 2 - f, -d / 2, 0.0), (w / 2, d / 2, h), color),
        box((w - 2 * f, 0.006, h - 2.3 * f), (0.0, 0.0, (h + 0.3 * f) / 2), GLASS),
    ]
    cols, rows = ((2, 2), (2, 1), (3, 2))[variant % 3]
    y0, y1 = -d * 0.3, d * 0.3
    for i in range(1, cols):
        x = -w / 2 + w * i / cols
        parts.append(slab((x - bar / 2, y0, f), (x + bar / 2, y1, h - f), color))
    for j in range(1, rows):
        z = h * j / rows
        parts.append(slab((-w / 2 + f, y0, z - bar / 2), (w / 2 - f, y1, z + bar / 2), color))
    return ShapeBuild(parts=parts)


@recipe("toilet")
def toilet(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A toilet: pedestal, bowl, seat ring and a tank at the back whose lid is a surface.

    Variant 0 has the seat lid up (open bowl visible), variant 1 the lid down.
    """
    w, d, h = size
    tank_d = min(0.2, d * 0.3)
    seat_z = min(0.42, h * 0.55)
    bowl_d = d - tank_d
    by = -d / 2 + bowl_d / 2
    rx, ry = w * 0.45, bowl_d / 2
    parts = [
        elliptic_cylinder(
            w * 0.22, bowl_d * 0.25, seat_z - 0.15, (0.0, by + 0.05, (seat_z - 0.15) / 2), color
        ),
        elliptic_cylinder(rx, ry, 0.18, (0.0, by, seat_z - 0.03 - 0.09), color),
        slab((-w * 0.45, d / 2 - tank_d, seat_z - 0.1), (w * 0.45, d / 2, h - 0.03), color),
        slab((-w / 2, d / 2 - tank_d, h - 0.03), (w / 2, d / 2, h), shade(color, 0.95)),
        box((0.05, 0.012, 0.015), (w * 0.3, d / 2 - tank_d - 0.006, h - 0.08), METAL),
    ]
    seat = tube(0.6, 1.0, 0.03, (0.0, 0.0, 0.0), shade(color, 0.97), sections=20)
    seat.mesh.apply_transform(
        [[rx, 0, 0, 0], [0, ry * 0.98, 0, by], [0, 0, 1, seat_z - 0.03], [0, 0, 0, 1]]
    )
    parts.append(seat)
    parts.append(
        elliptic_cylinder(rx * 0.55, ry * 0.5, 0.004, (0.0, by, seat_z - 0.028), (0.6, 0.75, 0.85))
    )
    if variant % 2 == 1:
        parts.append(
            elliptic_cylinder(
                rx * 0.98, ry * 0.96, 0.02, (0.0, by, seat_z + 0.01), shade(color, 0.97)
            )
        )
    surfaces = [Surface(-w / 2, d / 2 - tank_d, w / 2, d / 2, h)]
    return ShapeBuild(parts=parts, surfaces=surfaces)


@recipe("bathtub")
def bathtub(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A built-in bathtub: apron and rim around a BathtubBasin attachment."""
    w, d, h = size
    rim = min(0.08, w / 8, d / 8)
    floor = 0.06
    parts = [
        slab((-w / 2, -d / 2, 0.0), (w / 2, -d / 2 + rim, h), color),
        slab((-w / 2, d / 2 - rim, 0.0), (w / 2, d / 2, h), color),
        slab((-w / 2, -d / 2 + rim, 0.0), (-w / 2 + rim, d / 2 - rim, h), color),
        slab((w / 2 - rim, -d / 2 + rim, 0.0), (w / 2, d / 2 - rim, h), color),
        slab((-w / 2 + rim, -d / 2 + rim, 0.0), (w / 2 - rim, d / 2 - rim, floor), color),
    ]
    basin = (w - 2 * rim, d - 2 * rim, h - floor)
    return ShapeBuild(parts=parts, attachments=[Attachment("BathtubBasin", basin, 0.0, 0.0, floor)])


@recipe("bathtub_basin")
def bathtub_basin(size: Size, variant: int, color: Color) -> ShapeBuild:
    """The tub of a bathtub; its floor is an inside surface."""
    return _basin(size, color)


@recipe("mirror")
def mirror(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A wall mirror: frame and a silver glass panel; variant 1 is oval."""
    w, d, h = size
    f = min(0.04, w / 10, h / 10)
    silver = (0.8, 0.84, 0.88)
    if variant % 2 == 1:
        parts = [
            elliptic_cylinder(
                w / 2, h / 2, d * 0.6, (0.0, d * 0.2, h / 2), color, axis="y", sections=24
            ),
            elliptic_cylinder(
                w / 2 - f, h / 2 - f, d * 0.4, (0.0, -d * 0.3, h / 2), silver, axis="y", sections=24
            ),
        ]
    else:
        parts = [
            slab((-w / 2, -d / 2, 0.0), (w / 2, d / 2, f), color),
            slab((-w / 2, -d / 2, h - f), (w / 2, d / 2, h), color),
            slab((-w / 2, -d / 2, f), (-w / 2 + f, d / 2, h - f), color),
            slab((w / 2 - f, -d / 2, f), (w / 2, d / 2, h - f), color),
            slab((-w / 2 + f, -d / 4, f), (w / 2 - f, d / 2, h - f), silver),
        ]
    return ShapeBuild(parts=parts)


@recipe("painting")
def painting(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A framed picture: frame, canvas and a few shapes painted on it.

    Variant 0 is a landscape (sky, ground, sun), variant 1 abstract colour blocks.
    """
    w, d, h = size
    f = min(0.05, w / 10, h / 10)
    frame = (0.45, 0.3, 0.15) if variant % 2 == 0 else (0.12, 0.1, 0.08)
    parts = [
        slab((-w / 2, -d / 2, 0.0), (w / 2, d / 2, f), frame),
        slab((-w / 2, -d / 2, h - f), (w / 2, d / 2, h), frame),
        slab((-w / 2, -d / 2, f), (-w / 2 + f, d / 2, h - f), frame),
        slab((w / 2 - f, -d / 2, f), (w / 2, d / 2, h - f), frame),
    ]
    cy0, cy1 = -d / 2 + d * 0.4, d / 2  # canvas recessed behind the frame front
    iw, ih = w - 2 * f, h - 2 * f
    if variant % 2 == 0:
        parts += [
            slab((-iw / 2, cy0, f + ih * 0.4), (iw / 2, cy1, h - f), (0.55, 0.75, 0.92)),
            slab((-iw / 2, cy0, f), (iw / 2, cy1, f + ih * 0.4), shade(color, 0.8)),
            cylinder(
                min(iw, ih) * 0.1,
                d * 0.2,
                (iw * 0.25, cy0 - d * 0.1, f + ih * 0.75),
                (0.98, 0.85, 0.3),
                axis="y",
            ),
        ]
    else:
        parts += [
            slab((-iw / 2, cy0, f), (iw / 2, cy1, h - f), (0.93, 0.91, 0.86)),
            slab((-iw * 0.4, cy0 - d * 0.2, f + ih * 0.1), (0.0, cy0, f + ih * 0.6), color),
            slab(
                (iw * 0.05, cy0 - d * 0.2, f + ih * 0.35),
                (iw * 0.4, cy0, f + ih * 0.9),
                (0.85, 0.25, 0.2),
            ),
        ]
    return ShapeBuild(parts=parts)


@recipe("light_switch")
def light_switch(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A switch plate with a rocker."""
    w, d, h = size
    parts = [
        slab((-w / 2, -d / 2 + d * 0.4, 0.0), (w / 2, d / 2, h), color),
        slab((-w * 0.2, -d / 2, h * 0.3), (w * 0.2, -d / 2 + d * 0.4, h * 0.7), shade(color, 0.85)),
    ]
    return ShapeBuild(parts=parts)


@recipe("towel_holder")
def towel_holder(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A towel bar: two wall brackets and a round bar in front of the wall; variant 1 a ring."""
    w, d, h = size
    r = min(0.012, h / 6, d / 6)
    if variant % 2 == 1:
        ring = tube(0.75, 1.0, 1.0, (0.0, 0.0, 0.0), color, sections=20)
        rr = min(w / 2, h / 2 - 0.01)
        ring.mesh.apply_transform(
            [[rr, 0, 0, 0], [0, 0, -r, -d / 2 + r], [0, rr, 0, h / 2], [0, 0, 0, 1]]
        )
        plate = slab((-0.03, d / 2 - 0.01, h / 2 - 0.03), (0.03, d / 2, h / 2 + 0.03), color)
        arm = slab((-0.01, -d / 2 + r, h / 2 - 0.01), (0.01, d / 2, h / 2 + 0.01), color)
        return ShapeBuild(parts=[ring, plate, arm])
    parts = [cylinder(r, w - 0.02, (0.0, -d / 2 + r, h - r - 0.005), color, axis="x")]
    for sx in (-1, 1):
        x = sx * (w / 2 - 0.015)
        parts.append(slab((x - 0.015, d / 2 - 0.012, 0.0), (x + 0.015, d / 2, h), color))
        parts.append(
            slab((x - 0.008, -d / 2, h - 2 * r - 0.01), (x + 0.008, d / 2, h - 0.005), color)
        )
    return ShapeBuild(parts=parts)


@recipe("toilet_paper_hanger")
def toilet_paper_hanger(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A wall plate and arm carrying a roll of paper."""
    w, d, h = size
    r = min(h / 2, d * 0.45)
    parts = [
        slab((-w / 2, d / 2 - 0.01, 0.0), (-w / 2 + 0.03, d / 2, h), color),
        slab((-w / 2, -d / 2 + r, h / 2 - 0.01), (-w / 2 + 0.03, d / 2, h / 2 + 0.01), color),
        cylinder(r, w - 0.035, (0.0175, -d / 2 + r, r + (h / 2 - r)), WHITE, axis="x"),
        cylinder(r * 0.3, w - 0.03, (0.015, -d / 2 + r, h / 2), color, axis="x", sections=10),
    ]
    return ShapeBuild(parts=parts)
