"""Recipes for household objects that stand on the floor or on furniture: bins, lamps,
plants, screens, ..."""

from __future__ import annotations

import math

import numpy as np
import trimesh

from sgdata.world.shapes.base import (
    DARK,
    METAL,
    Color,
    Part,
    ShapeBuild,
    Size,
    Surface,
    box,
    cone,
    cylinder,
    elliptic_cylinder,
    frustum,
    hollow_box,
    open_cylinder,
    recipe,
    shade,
    slab,
    sphere,
    tube,
)

SOIL: Color = (0.25, 0.17, 0.1)
LEAF: Color = (0.2, 0.45, 0.18)


def _inside(w: float, d: float, wall: float, h: float, *, round_: bool = False) -> Surface:
    """The floor of an open container of outer footprint w x d and wall thickness ``wall``."""
    a, b = w / 2 - wall, d / 2 - wall
    if round_:
        a = b = min(a, b) * 0.7  # the square inscribed in the round floor
    return Surface(-a, -b, a, b, wall, clearance=h - wall, inside=True)


@recipe("garbage_can")
def garbage_can(size: Size, variant: int, color: Color) -> ShapeBuild:
    """An open bin whose floor is an inside surface; variant 0 round with a rim, 1 square."""
    w, d, h = size
    wall = min(0.015, w / 10)
    if variant % 2 == 0:
        r = min(w, d) / 2
        parts = open_cylinder(r * 0.92, h - 0.03, (0.0, 0.0, 0.0), wall, color, sections=20)
        parts.append(tube(r * 0.85, r, 0.03, (0.0, 0.0, h - 0.03), shade(color, 0.8), sections=20))
        return ShapeBuild(parts=parts, surfaces=[_inside(2 * r, 2 * r, r * 0.15, h, round_=True)])
    parts = hollow_box((w, d, h), (0.0, 0.0, 0.0), wall, color)
    # a darker band round the top, like a rim
    parts.append(slab((-w / 2, -d / 2, h - 0.03), (w / 2, -d / 2 + wall, h), shade(color, 0.8)))
    return ShapeBuild(parts=parts, surfaces=[_inside(w, d, wall, h)])


@recipe("laundry_hamper")
def laundry_hamper(size: Size, variant: int, color: Color) -> ShapeBuild:
    """An open basket with woven bands and two hand holes; its floor is an inside surface."""
    w, d, h = size
    wall = min(0.02, w / 10)
    parts = hollow_box((w, d, h), (0.0, 0.0, 0.0), wall, color, inner=shade(color, 0.8))
    for k in range(1, 4):
        z = h * k / 4
        parts.append(
            slab((-w / 2, -d / 2, z - 0.012), (w / 2, -d / 2 + wall, z + 0.012), shade(color, 0.75))
        )
    if variant % 2 == 1:
        # some laundry heaped inside
        parts.append(
            sphere(
                0.5,
                (0.0, 0.0, h * 0.75),
                (0.85, 0.85, 0.9),
                scale=(w - 2 * wall, d - 2 * wall, h * 0.5),
            )
        )
    return ShapeBuild(parts=parts, surfaces=[_inside(w, d, wall, h)])


@recipe("garbage_bag")
def garbage_bag(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A full bin bag: a bulging body and a tied neck."""
    w, d, h = size
    body_h = h * 0.8
    parts = [
        sphere(0.5, (0.0, 0.0, body_h / 2), color, scale=(w, d, body_h)),
        frustum(
            min(w, d) * 0.18,
            min(w, d) * 0.05,
            h * 0.12,
            (0.0, 0.0, body_h - 0.02),
            color,
            sections=10,
        ),
        # the knot: two ears of the tied bag
        sphere(
            0.5, (0.0, 0.0, h * 0.94), color, scale=(w * 0.25, d * 0.12, h * 0.12), subdivisions=1
        ),
    ]
    return ShapeBuild(parts=parts)


@recipe("vacuum_cleaner")
def vacuum_cleaner(size: Size, variant: int, color: Color) -> ShapeBuild:
    """An upright vacuum: floor head at the front, a body canister, a pole and a grip."""
    w, d, h = size
    head_h = min(0.08, h * 0.08)
    parts = [
        slab((-w / 2, -d / 2, 0.0), (w / 2, -d / 2 + d * 0.45, head_h), DARK),
        box((w * 0.6, d * 0.5, head_h * 0.6), (0.0, d * 0.05, head_h * 0.3), DARK),
        cylinder(min(w, d) * 0.3, h * 0.45, (0.0, d * 0.15, head_h + h * 0.225), color),
        cylinder(0.015, h * 0.45, (0.0, d * 0.15, h * 0.5 + h * 0.225 - 0.04), METAL, sections=10),
        box((0.05, 0.03, 0.12), (0.0, d * 0.15, h - 0.06), DARK),
    ]
    return ShapeBuild(parts=parts)


@recipe("dog_bed")
def dog_bed(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A pet bed: a padded rim around a cushion; variant 0 round, 1 rectangular."""
    w, d, h = size
    if variant % 2 == 0:
        r = min(w, d) / 2
        parts = [
            tube(r * 0.65, r, h, (0.0, 0.0, 0.0), color, sections=24),
            cylinder(r * 0.7, h * 0.45, (0.0, 0.0, h * 0.225), shade(color, 1.2), sections=24),
        ]
        return ShapeBuild(parts=parts)
    rim = min(w, d) * 0.15
    parts = hollow_box((w, d, h), (0.0, 0.0, 0.0), rim, color)
    parts[0] = slab(
        (-w / 2 + rim, -d / 2 + rim, 0.0), (w / 2 - rim, d / 2 - rim, h * 0.45), shade(color, 1.2)
    )
    parts[1] = slab((-w / 2, -d / 2, 0.0), (w / 2, -d / 2 + rim, h * 0.6), color)
    return ShapeBuild(parts=parts)


@recipe("safe")
def safe(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A strongbox: body, a door on the front with a dial and a lever handle."""
    w, d, h = size
    yf = -d / 2
    parts = [
        slab((-w / 2, yf + 0.02, 0.0), (w / 2, d / 2, h), color),
        slab(
            (-w / 2 + 0.03, yf + 0.01, 0.03),
            (w / 2 - 0.03, yf + 0.02, h - 0.03),
            shade(color, 1.15),
        ),
        cylinder(min(w, h) * 0.1, 0.01, (-w * 0.12, yf + 0.005, h * 0.55), METAL, axis="y"),
        slab((w * 0.15, yf, h * 0.5 - 0.01), (w * 0.32, yf + 0.01, h * 0.5 + 0.01), METAL),
    ]
    return ShapeBuild(parts=parts)


@recipe("floor_vase")
def floor_vase(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A decorative floor vase with dry branches sticking out (room decor)."""
    w, d, h = size
    r = min(w, d) / 2
    vase_h = h * 0.55
    parts = [
        frustum(r * 0.6, r, vase_h * 0.6, (0.0, 0.0, 0.0), color, sections=16),
        frustum(r, r * 0.4, vase_h * 0.4, (0.0, 0.0, vase_h * 0.6), color, sections=16),
    ]
    stem = (0.35, 0.25, 0.15)
    for k in range(5):
        a = k * 2 * math.pi / 5
        lean = 0.25 if variant % 2 == 0 else 0.12
        length = (h - vase_h) / math.cos(lean) * 0.98
        cx = math.cos(a) * math.sin(lean) * length / 2
        cy = math.sin(a) * math.sin(lean) * length / 2
        part = cylinder(0.006, length, (0.0, 0.0, 0.0), stem, sections=6)
        part.mesh.apply_transform(_tilt(a, lean))
        part.mesh.apply_translation((cx, cy, vase_h + (h - vase_h) / 2 - 0.01))
        parts.append(part)
    return ShapeBuild(parts=parts)


def _tilt(azimuth: float, lean: float) -> np.ndarray:
    """A rotation leaning +Z by ``lean`` towards the horizontal direction ``azimuth``."""
    axis = [-math.sin(azimuth), math.cos(azimuth), 0.0]
    return trimesh.transformations.rotation_matrix(lean, axis)


@recipe("house_plant")
def house_plant(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A potted plant (the palette colours the pot).

    Variant 0: a bushy clump of leaf balls; 1: a small tree with a trunk and a round crown;
    2: a spiky plant of upright leaf cones.
    """
    w, d, h = size
    r = min(w, d) / 2
    pot_h = min(h * 0.3, 0.4)
    pr = r * 0.6
    parts = [
        frustum(pr * 0.75, pr, pot_h, (0.0, 0.0, 0.0), color),
        cylinder(pr * 0.92, 0.01, (0.0, 0.0, pot_h - 0.005), SOIL),
    ]
    v = variant % 3
    if v == 0:
        fr = min(r * 0.55, (h - pot_h) * 0.35)
        for k in range(5):
            a = k * 2 * math.pi / 5
            off = r - fr
            parts.append(
                sphere(
                    fr, (off * math.cos(a), off * math.sin(a), h - fr * 1.9), LEAF, subdivisions=1
                )
            )
        parts.append(sphere(fr, (0.0, 0.0, h - fr), shade(LEAF, 1.15), subdivisions=1))
    elif v == 1:
        cr = min(r, (h - pot_h) * 0.4)
        parts.append(
            cylinder(
                0.02,
                h - pot_h - cr,
                (0.0, 0.0, pot_h + (h - pot_h - cr) / 2),
                (0.35, 0.24, 0.14),
                sections=8,
            )
        )
        parts.append(sphere(cr, (0.0, 0.0, h - cr), LEAF, subdivisions=2))
    else:
        lr = min(pr * 0.35, r * 0.3)
        for k in range(6):
            a = k * 2 * math.pi / 6
            lh = (h - pot_h) * (0.75 + 0.25 * (k % 2))
            parts.append(
                cone(
                    lr,
                    lh,
                    (pr * 0.45 * math.cos(a), pr * 0.45 * math.sin(a), pot_h),
                    shade(LEAF, 0.9 + 0.1 * (k % 3)),
                    sections=8,
                )
            )
        parts.append(cone(lr, h - pot_h, (0.0, 0.0, pot_h), LEAF, sections=8))
    return ShapeBuild(parts=parts)


@recipe("lamp")
def lamp(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A lamp: weighted base, pole and shade (the palette colours the shade); used by desk and
    floor lamps alike. Variant 0 has a tapered shade, variant 1 a drum shade."""
    w, d, h = size
    r = min(w, d) / 2
    shade_h = min(h * 0.3, r * 1.5)
    base_r = r * 0.6
    parts = [
        cylinder(base_r, h * 0.03, (0.0, 0.0, h * 0.015), METAL, sections=16),
        cylinder(
            min(0.012, r * 0.1),
            h - shade_h * 0.6,
            (0.0, 0.0, (h - shade_h * 0.6) / 2),
            METAL,
            sections=8,
        ),
    ]
    top_r = r * (0.6 if variant % 2 == 0 else 0.95)
    parts.append(frustum(r, top_r, shade_h, (0.0, 0.0, h - shade_h), color, sections=18))
    return ShapeBuild(parts=parts)


@recipe("television")
def television(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A flat-screen TV: a bezel panel with a black screen on -Y and a stand.

    Variant 0 stands on a central pedestal, variant 1 on two feet.
    """
    w, d, h = size
    stand_h = min(0.1, h * 0.15)
    pd = min(0.05, d * 0.5)
    parts = [
        slab((-w / 2, -pd / 2 + 0.003, stand_h), (w / 2, pd / 2, h), color),
        # the screen: a dark glass face just proud of the bezel
        slab(
            (-w / 2 + 0.015, -pd / 2, stand_h + 0.015),
            (w / 2 - 0.015, -pd / 2 + 0.003, h - 0.015),
            (0.02, 0.03, 0.05),
        ),
    ]
    if variant % 2 == 0:
        parts.append(slab((-0.04, -0.02, 0.0), (0.04, 0.02, stand_h), color))
        parts.append(slab((-w * 0.2, -d / 2, 0.0), (w * 0.2, d / 2, 0.015), color))
    else:
        for sx in (-1, 1):
            x = sx * w * 0.38
            parts.append(slab((x - 0.02, -d / 2, 0.0), (x + 0.02, d / 2, 0.015), color))
            parts.append(slab((x - 0.01, -0.01, 0.0), (x + 0.01, 0.01, stand_h), color))
    return ShapeBuild(parts=parts)


@recipe("monitor")
def monitor(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A desktop computer: monitor on a stand at the back, a keyboard in front."""
    w, d, h = size
    pd = 0.03
    sy = d / 2 - 0.06
    screen_z = min(0.1, h * 0.25)
    parts = [
        slab((-w / 2, sy - pd / 2 + 0.004, screen_z), (w / 2, sy + pd / 2, h), color),
        slab(
            (-w / 2 + 0.01, sy - pd / 2, screen_z + 0.01),
            (w / 2 - 0.01, sy - pd / 2 + 0.004, h - 0.01),
            (0.02, 0.03, 0.05),
        ),
        slab((-0.02, sy + pd / 2, 0.0), (0.02, sy + pd / 2 + 0.02, screen_z + 0.1), color),
        slab((-0.1, d / 2 - 0.12, 0.0), (0.1, d / 2, 0.012), color),
    ]
    kw = min(w * 0.9, 0.44)
    kd = min(0.15, d - 0.14)
    parts.append(slab((-kw / 2, -d / 2, 0.0), (kw / 2, -d / 2 + kd, 0.02), shade(color, 0.9)))
    parts.append(
        slab(
            (-kw / 2 + 0.01, -d / 2 + 0.01, 0.02),
            (kw / 2 - 0.01, -d / 2 + kd - 0.01, 0.025),
            (0.75, 0.75, 0.75),
        )
    )
    return ShapeBuild(parts=parts)


@recipe("shoes")
def shoes(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A pair of shoes side by side, toes to the front (-Y), on dark soles: variant 0 laced
    shoes with a rounded toe cap and a tongue, variant 1 slippers open at the heel."""
    w, d, h = size
    sw = w * 0.44  # one shoe's width
    sole = min(0.02, h * 0.2)
    toe = min(sw / 2, d * 0.3)
    parts: list[Part] = []
    for sx in (-1.0, 1.0):
        x = sx * w / 4
        parts.append(slab((x - sw / 2, -d / 2, 0.0), (x + sw / 2, d / 2, sole), DARK))
        cap = (h - sole) * (0.6 if variant % 2 == 0 else 0.8)
        parts.append(
            elliptic_cylinder(sw * 0.45, toe, cap, (x, -d / 2 + toe, sole + cap / 2), color)
        )
        if variant % 2 == 0:
            parts.append(
                slab((x - sw * 0.45, -d / 2 + toe, sole), (x + sw * 0.45, d / 2, h), color)
            )
            parts.append(
                slab(
                    (x - sw * 0.15, -d / 2 + toe * 0.8, sole + cap * 0.8),
                    (x + sw * 0.15, -d / 2 + toe + d * 0.2, h),
                    shade(color, 1.3),
                )
            )
        else:
            parts.append(
                slab(
                    (x - sw * 0.45, -d / 2 + toe, sole), (x + sw * 0.45, d * 0.1, sole + cap), color
                )
            )
    return ShapeBuild(parts=parts)


@recipe("picture_frame")
def picture_frame(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A standing photo frame facing the front (-Y), propped up by a stand behind it: variant
    0 holds a landscape (sky over green), variant 1 a portrait (a face on grey)."""
    w, d, h = size
    t = min(0.015, d * 0.3)  # frame thickness
    f = min(0.02, w * 0.12, h * 0.12)  # border width
    y0 = -d / 2
    parts = [
        slab((-w / 2, y0, 0.0), (w / 2, y0 + t, f), color),
        slab((-w / 2, y0, h - f), (w / 2, y0 + t, h), color),
        slab((-w / 2, y0, f), (-w / 2 + f, y0 + t, h - f), color),
        slab((w / 2 - f, y0, f), (w / 2, y0 + t, h - f), color),
    ]
    px0, px1, pz0, pz1 = -w / 2 + f, w / 2 - f, f, h - f
    py0 = y0 + t * 0.4  # the photo is recessed behind the border's front
    if variant % 2 == 0:
        mid = pz0 + (pz1 - pz0) * 0.45
        parts += [
            slab((px0, py0, mid), (px1, y0 + t, pz1), (0.55, 0.75, 0.92)),
            slab((px0, py0, pz0), (px1, y0 + t, mid), (0.3, 0.55, 0.25)),
        ]
    else:
        r = min(px1 - px0, pz1 - pz0) * 0.25
        parts += [
            slab((px0, py0, pz0), (px1, y0 + t, pz1), (0.6, 0.6, 0.62)),
            cylinder(
                r,
                t * 0.3,
                (0.0, py0 - t * 0.15, pz0 + (pz1 - pz0) * 0.6),
                (0.85, 0.68, 0.55),
                axis="y",
                sections=14,
            ),
        ]
    # the stand: a strut from the back of the frame to a foot resting on the surface behind it
    sw = min(0.03, w * 0.2)
    parts += [
        slab((-sw / 2, y0 + t, h * 0.3), (sw / 2, d / 2, h * 0.3 + 0.006), shade(color, 0.8)),
        slab((-sw / 2, d / 2 - 0.006, 0.0), (sw / 2, d / 2, h * 0.3 + 0.006), shade(color, 0.8)),
    ]
    return ShapeBuild(parts=parts)


@recipe("backpack")
def backpack(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A backpack standing upright, straps at the back (+Y): a rounded body, a front pocket
    and a carry loop on top."""
    w, d, h = size
    loop = min(0.04, h * 0.1)
    hb = h - loop  # the body's height
    body_d = d * 0.7
    cy = d / 2 - body_d / 2
    parts = [
        elliptic_cylinder(w / 2, body_d / 2, hb * 0.85, (0.0, cy, hb * 0.425), color),
        sphere(0.5, (0.0, cy, hb * 0.85), color, scale=(w, body_d, hb * 0.3), subdivisions=1),
        slab((-w * 0.35, -d / 2, hb * 0.1), (w * 0.35, cy, hb * 0.5), shade(color, 0.85)),
        slab((-0.03, cy - 0.008, hb - 0.01), (0.03, cy + 0.008, h), shade(color, 0.6)),
    ]
    for sx in (-1.0, 1.0):
        x = sx * w * 0.25
        parts.append(
            slab(
                (x - 0.02, d / 2 - 0.015, hb * 0.1), (x + 0.02, d / 2, hb * 0.8), shade(color, 0.6)
            )
        )
    return ShapeBuild(parts=parts)
