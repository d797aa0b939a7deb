"""Recipes for small pickupable objects (fruit, books, gadgets, toys, bathroom items, ...)."""

from __future__ import annotations

import math

from sgdata.world.shapes.base import (
    DARK,
    METAL,
    WHITE,
    Color,
    ShapeBuild,
    Size,
    Surface,
    box,
    cone,
    cylinder,
    elliptic_cylinder,
    frustum,
    hollow_box,
    recipe,
    rotated_box,
    shade,
    slab,
    sphere,
    tube,
)

LEAF: Color = (0.25, 0.5, 0.15)
STEM: Color = (0.35, 0.25, 0.12)
SCREEN: Color = (0.04, 0.06, 0.1)


@recipe("block")
def block(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A plain box: the fallback for objects with no better recipe yet."""
    w, d, h = size
    return ShapeBuild(parts=[box((w, d, h), (0.0, 0.0, h / 2), color)])


@recipe("fruit")
def fruit(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A round fruit: variant 0 an apple with a stem and leaf, variant 1 a tomato with a green
    calyx."""
    w, d, h = size
    body_h = h * 0.88
    parts = [sphere(0.5, (0.0, 0.0, body_h / 2), color, scale=(w, d, body_h))]
    if variant % 2 == 0:
        parts.append(cylinder(0.003, h * 0.2, (0.0, 0.0, h - h * 0.1), STEM, sections=6))
        parts.append(
            sphere(
                0.5,
                (w * 0.12, 0.0, h - h * 0.06),
                LEAF,
                scale=(w * 0.22, w * 0.1, h * 0.04),
                subdivisions=1,
            )
        )
    else:
        parts.append(
            cone(
                min(w, d) * 0.2,
                h - body_h + h * 0.04,
                (0.0, 0.0, body_h - h * 0.04),
                LEAF,
                sections=5,
            )
        )
    return ShapeBuild(parts=parts)


@recipe("ovoid")
def ovoid(size: Size, variant: int, color: Color) -> ShapeBuild:
    """An egg or a potato: an ellipsoid; variant 1 is lumpy (two overlapping lobes)."""
    w, d, h = size
    if variant % 2 == 0:
        return ShapeBuild(parts=[sphere(0.5, (0.0, 0.0, h / 2), color, scale=(w, d, h))])
    parts = [
        sphere(0.5, (-w * 0.15, 0.0, h / 2), color, scale=(w * 0.7, d, h)),
        sphere(
            0.5, (w * 0.18, 0.0, h * 0.45), shade(color, 0.95), scale=(w * 0.64, d * 0.9, h * 0.9)
        ),
    ]
    return ShapeBuild(parts=parts)


@recipe("lettuce")
def lettuce(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A head of lettuce: a pale core wrapped in darker leaf lobes."""
    w, d, h = size
    parts = [sphere(0.5, (0.0, 0.0, h / 2), shade(color, 1.2), scale=(w * 0.8, d * 0.8, h))]
    for k in range(5):
        a = k * 2 * math.pi / 5
        parts.append(
            sphere(
                0.5,
                (w * 0.18 * math.cos(a), d * 0.18 * math.sin(a), h * 0.42),
                shade(color, 0.85 + 0.05 * (k % 3)),
                scale=(w * 0.62, d * 0.62, h * 0.8),
                subdivisions=1,
            )
        )
    return ShapeBuild(parts=parts)


@recipe("bread")
def bread(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A loaf of bread lying along X: a box base under a domed crust; variant 1 a round loaf."""
    w, d, h = size
    if variant % 2 == 1:
        return ShapeBuild(
            parts=[
                sphere(0.5, (0.0, 0.0, h / 2), color, scale=(w, d, h)),
                sphere(
                    0.5,
                    (0.0, 0.0, h * 0.53),
                    shade(color, 1.15),
                    scale=(w * 0.5, d * 0.12, h * 0.92),
                ),
            ]
        )
    base = h * 0.55
    parts = [
        slab((-w / 2, -d / 2, 0.0), (w / 2, d / 2, base), color),
        elliptic_cylinder(
            d / 2, h - base, w, (0.0, 0.0, base), shade(color, 0.85), axis="x", sections=16
        ),
    ]
    # only the upper half of the crust is outside the base box; cut the lower half off by
    # clamping its vertices up to the base top (keeps the mesh closed)
    v = parts[1].mesh.vertices.copy()
    v[:, 2] = v[:, 2].clip(min=base - 0.001)
    parts[1].mesh.vertices = v
    for k in (-1, 0, 1):
        parts.append(
            rotated_box(
                (0.012, d * 0.35, 0.01), (k * w * 0.25, 0.0, h - 0.005), shade(color, 1.25), rz=0.5
            )
        )
    return ShapeBuild(parts=parts)


@recipe("book")
def book(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A closed book lying flat: hard covers, a spine on -X and cream page edges."""
    w, d, h = size
    c = min(0.004, h * 0.15)
    paper = (0.95, 0.92, 0.82)
    parts = [
        slab((-w / 2, -d / 2, 0.0), (w / 2, d / 2, c), color),
        slab((-w / 2, -d / 2, h - c), (w / 2, d / 2, h), color),
        slab((-w / 2, -d / 2, c), (-w / 2 + c, d / 2, h - c), shade(color, 0.85)),
        slab((-w / 2 + c, -d / 2 + 0.004, c), (w / 2 - 0.004, d / 2 - 0.004, h - c), paper),
    ]
    if variant % 2 == 1:
        parts.append(
            slab((-w * 0.3, -d * 0.3, h - 0.0005), (w * 0.3, -d * 0.1, h), (0.9, 0.8, 0.4))
        )
    return ShapeBuild(parts=parts)


@recipe("laptop")
def laptop(size: Size, variant: int, color: Color) -> ShapeBuild:
    """An open laptop: base with a dark keyboard, the screen tilted back at the rear."""
    w, d, h = size
    bt = min(0.02, h * 0.1)
    lean = math.radians(15)
    pt = 0.008
    # the screen is as long as the height allows; the hinge moves forward so that the screen,
    # leaning back, still ends inside the box
    length = (h - bt - pt) / math.cos(lean)
    length = min(length, (d - pt) * 0.5 / math.sin(lean))
    hinge = d / 2 - length * math.sin(lean) - pt
    bd = hinge + d / 2
    cy = hinge + length / 2 * math.sin(lean)
    cz = bt + length / 2 * math.cos(lean)
    parts = [
        slab((-w / 2, -d / 2, 0.0), (w / 2, hinge, bt), color),
        slab(
            (-w / 2 + 0.02, -d / 2 + bd * 0.45, bt - 0.0005),
            (w / 2 - 0.02, hinge - 0.01, bt + 0.001),
            DARK,
        ),
        rotated_box((w * 0.98, pt, length), (0.0, cy, cz), color, rx=-lean),
    ]
    off = pt / 2 + 0.001
    n = (-math.cos(lean), math.sin(lean))
    screen = rotated_box(
        (w * 0.9, 0.002, length * 0.85), (0.0, cy + n[0] * off, cz + n[1] * off), SCREEN, rx=-lean
    )
    parts.append(screen)
    return ShapeBuild(parts=parts)


@recipe("remote")
def remote(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A remote control lying along Y: a slim body with a power button and button rows."""
    w, d, h = size
    bh = h * 0.75
    parts = [
        slab((-w / 2, -d / 2, 0.0), (w / 2, d / 2, bh), color),
        cylinder(
            w * 0.12,
            h - bh,
            (0.0, -d / 2 + d * 0.1, bh + (h - bh) / 2),
            (0.8, 0.1, 0.1),
            sections=8,
        ),
    ]
    for k in range(3):
        y = -d / 2 + d * (0.3 + 0.18 * k)
        parts.append(slab((-w * 0.3, y, bh), (w * 0.3, y + d * 0.1, h), (0.6, 0.6, 0.62)))
    return ShapeBuild(parts=parts)


@recipe("phone")
def phone(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A smartphone lying flat (long side along Y): the case colour, a black screen on top."""
    w, d, h = size
    parts = [
        slab((-w / 2, -d / 2, 0.0), (w / 2, d / 2, h * 0.85), color),
        slab(
            (-w / 2 + 0.003, -d / 2 + 0.006, h * 0.85 - 0.0005),
            (w / 2 - 0.003, d / 2 - 0.006, h),
            SCREEN,
        ),
    ]
    return ShapeBuild(parts=parts)


@recipe("keychain")
def keychain(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A key ring lying flat with two keys and a fob."""
    w, d, h = size
    r = min(w, d) * 0.25
    t = min(h, 0.004)
    parts = [tube(r * 0.8, r, t, (-w / 2 + r, 0.0, 0.0), METAL, sections=16)]
    for k, angle in enumerate((-0.35, 0.35)):
        kx = -w / 2 + 2 * r + (w - 2 * r) * 0.38
        ky = math.sin(angle) * d * 0.25
        parts.append(
            rotated_box(
                ((w - 2 * r) * 0.7, d * 0.18, t),
                (kx, ky, t / 2 + k * t * 0.5),
                (0.8, 0.7, 0.35) if k else METAL,
                rz=angle * 0.5,
            )
        )
    parts.append(
        slab((-w / 2 + r * 0.5, -d / 2, 0.0), (-w / 2 + r * 1.5, -d / 2 + d * 0.3, h), color)
    )
    return ShapeBuild(parts=parts)


@recipe("pillow")
def pillow(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A pillow: variant 0 a plump rounded cushion, variant 1 a square cushion with piping."""
    w, d, h = size
    if variant % 2 == 0:
        return ShapeBuild(parts=[sphere(0.5, (0.0, 0.0, h / 2), color, scale=(w, d, h))])
    parts = [
        box((w * 0.98, d * 0.98, h * 0.4), (0.0, 0.0, h / 2), shade(color, 0.8)),
        sphere(0.5, (0.0, 0.0, h / 2), color, scale=(w * 0.96, d * 0.96, h)),
    ]
    return ShapeBuild(parts=parts)


@recipe("cardboard_box")
def cardboard_box(size: Size, variant: int, color: Color) -> ShapeBuild:
    """An open cardboard box with tape along the rim; its floor is an inside surface."""
    w, d, h = size
    wall = min(0.008, w / 10, d / 10)
    parts = hollow_box((w, d, h), (0.0, 0.0, 0.0), wall, color, inner=shade(color, 0.8))
    parts.append(
        slab((-w * 0.08, -d / 2, h * 0.6), (w * 0.08, -d / 2 + wall, h), (0.85, 0.75, 0.5))
    )
    if variant % 2 == 1:
        # a flap standing up at the back
        parts.append(
            slab(
                (-w / 2 + wall, d / 2 - wall, h * 0.5), (w / 2 - wall, d / 2, h), shade(color, 1.1)
            )
        )
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


@recipe("vase")
def vase(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A vase: variant 0 a tall tapered vase with a neck, variant 1 a round-bellied vase."""
    w, d, h = size
    r = min(w, d) / 2
    if variant % 2 == 0:
        parts = [
            frustum(r * 0.6, r, h * 0.7, (0.0, 0.0, 0.0), color),
            frustum(r, r * 0.45, h * 0.15, (0.0, 0.0, h * 0.7), color),
            tube(r * 0.35, r * 0.5, h * 0.15, (0.0, 0.0, h * 0.85), color),
        ]
    else:
        parts = [
            sphere(0.5, (0.0, 0.0, h * 0.35), color, scale=(2 * r, 2 * r, h * 0.7)),
            tube(r * 0.3, r * 0.45, h * 0.35, (0.0, 0.0, h * 0.65), color),
        ]
    return ShapeBuild(parts=parts)


@recipe("statue")
def statue(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A figurine on a plinth: variant 0 a standing figure, variant 1 an abstract twist."""
    w, d, h = size
    plinth = h * 0.12
    parts = [slab((-w / 2, -d / 2, 0.0), (w / 2, d / 2, plinth), (0.2, 0.2, 0.2))]
    s = min(w, d)
    if variant % 2 == 0:
        head = s * 0.22
        body_h = h - plinth - 2 * head
        parts.append(frustum(s * 0.3, s * 0.18, body_h, (0.0, 0.0, plinth), color))
        parts.append(sphere(head, (0.0, 0.0, h - head), color))
    else:
        n = 4
        seg = (h - plinth) / n
        for k in range(n):
            parts.append(
                rotated_box(
                    (s * 0.5, s * 0.25, seg),
                    (0.0, 0.0, plinth + seg * (k + 0.5)),
                    color,
                    rz=k * 0.4,
                )
            )
    return ShapeBuild(parts=parts)


@recipe("newspaper")
def newspaper(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A folded newspaper: a grey-white slab printed with a headline bar and text columns."""
    w, d, h = size
    top = h - 0.0005
    parts = [
        slab((-w / 2, -d / 2, 0.0), (w / 2, d / 2, top), color),
        slab((-w * 0.42, d * 0.3, top), (w * 0.42, d * 0.42, h), (0.15, 0.15, 0.15)),
    ]
    for k in range(3):
        x0 = -w * 0.42 + k * w * 0.29
        parts.append(slab((x0, -d * 0.42, top), (x0 + w * 0.24, d * 0.22, h), (0.55, 0.55, 0.55)))
    return ShapeBuild(parts=parts)


@recipe("card")
def card(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A credit card lying flat: a coloured card with a gold chip."""
    w, d, h = size
    parts = [
        slab((-w / 2, -d / 2, 0.0), (w / 2, d / 2, h * 0.8), color),
        slab((-w * 0.35, -d * 0.1, h * 0.8 - 0.0001), (-w * 0.15, d * 0.15, h), (0.85, 0.7, 0.3)),
    ]
    return ShapeBuild(parts=parts)


@recipe("pen")
def pen(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A pen lying along X: barrel, cap with clip, and a writing tip on -X."""
    w, d, h = size
    r = min(d, h) / 2
    tip = w * 0.08
    parts = [
        cylinder(r, w - tip, (tip / 2, 0.0, r), color, axis="x", sections=10),
        cylinder(
            r * 1.0, w * 0.3, (w / 2 - w * 0.15, 0.0, r), shade(color, 0.6), axis="x", sections=10
        ),
    ]
    tip_part = cone(r * 0.8, tip, (0.0, 0.0, 0.0), METAL, sections=8)
    tip_part.mesh.apply_transform(
        [[0, 0, -1, -w / 2 + tip], [0, 1, 0, 0], [1, 0, 0, r], [0, 0, 0, 1]]
    )
    parts.append(tip_part)
    return ShapeBuild(parts=parts)


@recipe("pencil")
def pencil(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A hexagonal pencil lying along X: painted barrel, eraser on +X, sharpened tip on -X."""
    w, d, h = size
    r = min(d, h) / 2
    tip = w * 0.1
    ers = w * 0.06
    parts = [
        cylinder(r, w - tip - ers, ((tip - ers) / 2, 0.0, r), color, axis="x", sections=6),
        cylinder(
            r * 0.95, ers, (w / 2 - ers / 2, 0.0, r), (0.9, 0.55, 0.55), axis="x", sections=10
        ),
    ]
    tip_part = cone(r, tip, (0.0, 0.0, 0.0), (0.85, 0.7, 0.5), sections=6)
    tip_part.mesh.apply_transform(
        [[0, 0, -1, -w / 2 + tip], [0, 1, 0, 0], [1, 0, 0, r], [0, 0, 0, 1]]
    )
    parts.append(tip_part)
    return ShapeBuild(parts=parts)


@recipe("alarm_clock")
def alarm_clock(size: Size, variant: int, color: Color) -> ShapeBuild:
    """An alarm clock facing -Y: variant 0 a round twin-bell clock, variant 1 a digital cube."""
    w, d, h = size
    if variant % 2 == 1:
        parts = [
            slab((-w / 2, -d / 2 + 0.003, 0.0), (w / 2, d / 2, h), color),
            slab((-w * 0.4, -d / 2, h * 0.25), (w * 0.4, -d / 2 + 0.003, h * 0.75), SCREEN),
            slab(
                (-w * 0.3, -d / 2, h * 0.42), (w * 0.3, -d / 2 + 0.0015, h * 0.58), (0.9, 0.2, 0.2)
            ),
        ]
        return ShapeBuild(parts=parts)
    bell = min(w, h) * 0.16
    r = min(w / 2, (h - bell * 1.2) / 2)
    cz = h - bell * 1.2 - r
    parts = [
        cylinder(r, d * 0.8, (0.0, d * 0.1, cz), color, axis="y", sections=20),
        cylinder(r * 0.85, d * 0.2, (0.0, -d / 2 + d * 0.1, cz), WHITE, axis="y", sections=20),
        box((0.003, d * 0.1, r * 0.7), (0.0, -d / 2 + d * 0.05, cz + r * 0.3), DARK),
        box((r * 0.5, d * 0.1, 0.003), (r * 0.25, -d / 2 + d * 0.05, cz), DARK),
    ]
    for sx in (-1, 1):
        parts.append(sphere(bell, (sx * r * 0.6, d * 0.1, h - bell), METAL, subdivisions=1))
        parts.append(
            box(
                (0.01, d * 0.3, cz - r + 0.005), (sx * r * 0.6, d * 0.1, (cz - r + 0.005) / 2), DARK
            )
        )
    return ShapeBuild(parts=parts)


@recipe("disc")
def disc(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A CD lying flat: a silver disc with a printed ring and a centre hole."""
    w, d, h = size
    r = min(w, d) / 2
    parts = [
        tube(r * 0.1, r, h * 0.6, (0.0, 0.0, 0.0), (0.82, 0.84, 0.88), sections=24),
        tube(r * 0.3, r * 0.95, h * 0.4, (0.0, 0.0, h * 0.6), color, sections=24),
    ]
    return ShapeBuild(parts=parts)


@recipe("teddy_bear")
def teddy_bear(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A sitting teddy bear facing -Y: body, head with ears and muzzle, arms and legs."""
    w, d, h = size
    s = min(w, d)
    body_r = s * 0.32
    head_r = min(s * 0.3, h * 0.22)
    body_z = body_r * 1.1
    head_z = h - head_r * 1.1 - head_r * 0.25
    parts = [
        sphere(0.5, (0.0, 0.0, body_z), color, scale=(2 * body_r, 2 * body_r, 2.2 * body_r)),
        sphere(head_r, (0.0, 0.0, head_z), color),
        sphere(
            head_r * 0.4,
            (0.0, -head_r * 0.9, head_z - head_r * 0.2),
            shade(color, 1.3),
            subdivisions=1,
        ),
        sphere(head_r * 0.12, (0.0, -head_r * 1.22, head_z - head_r * 0.1), DARK, subdivisions=1),
    ]
    for sx in (-1, 1):
        parts.append(
            sphere(
                head_r * 0.35,
                (sx * head_r * 0.75, 0.0, head_z + head_r * 0.8),
                color,
                subdivisions=1,
            )
        )
        parts.append(
            sphere(
                0.5,
                (sx * body_r * 1.05, -body_r * 0.2, body_z + body_r * 0.3),
                color,
                scale=(body_r * 0.6, body_r * 0.6, body_r * 1.3),
                subdivisions=1,
            )
        )
        parts.append(
            sphere(
                0.5,
                (sx * body_r * 0.6, -d / 2 + body_r * 0.55, body_r * 0.35),
                color,
                scale=(body_r * 0.7, body_r * 1.1, body_r * 0.7),
                subdivisions=1,
            )
        )
        parts.append(
            sphere(
                head_r * 0.08,
                (sx * head_r * 0.35, -head_r * 0.85, head_z + head_r * 0.25),
                DARK,
                subdivisions=1,
            )
        )
    return ShapeBuild(parts=parts)


@recipe("ball")
def ball(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A basketball: an orange sphere with dark seams."""
    w, d, h = size
    r = min(w, d, h) / 2
    # the ball sits a little inside the seam rings so they show as dark lines
    parts = [sphere(r * 0.975, (0.0, 0.0, r), color, subdivisions=3)]
    seam = r * 0.03
    parts.append(tube(r * 0.98, r, seam * 2, (0.0, 0.0, r - seam), DARK, sections=24))
    for axis in ("x", "y"):
        ring = tube(r * 0.98, r, seam * 2, (0.0, 0.0, -seam), DARK, sections=24)
        rot = (
            [[1, 0, 0, 0], [0, 0, -1, 0], [0, 1, 0, r], [0, 0, 0, 1]]
            if axis == "x"
            else [[0, 0, 1, 0], [0, 1, 0, 0], [-1, 0, 0, r], [0, 0, 0, 1]]
        )
        ring.mesh.apply_transform(rot)
        parts.append(ring)
    return ShapeBuild(parts=parts)


@recipe("tennis_racket")
def tennis_racket(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A tennis racket lying flat along X: an oval head frame on -X, strings, throat, grip."""
    w, d, h = size
    head_l = w * 0.45
    hx = -w / 2 + head_l / 2
    t = min(h, 0.025)
    frame = tube(0.86, 1.0, t, (0.0, 0.0, 0.0), color, sections=20)
    frame.mesh.apply_transform(
        [[head_l / 2, 0, 0, hx], [0, d / 2, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]
    )
    strings = elliptic_cylinder(
        head_l / 2 * 0.88, d / 2 * 0.88, 0.002, (hx, 0.0, t / 2), (0.9, 0.9, 0.8), sections=20
    )
    grip_l = w * 0.3
    parts = [
        frame,
        strings,
        slab((-w / 2 + head_l * 0.98, -0.012, 0.0), (w / 2 - grip_l, 0.012, t * 0.8), color),
        slab((w / 2 - grip_l, -0.016, 0.0), (w / 2, 0.016, t), DARK),
    ]
    return ShapeBuild(parts=parts)


@recipe("watch")
def watch(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A wristwatch lying flat: a strap along Y and a round face."""
    w, d, h = size
    r = min(w, d) * 0.45
    parts = [
        slab((-w * 0.28, -d / 2, 0.0), (w * 0.28, d / 2, h * 0.3), color),
        cylinder(r, h * 0.7, (0.0, 0.0, h * 0.35), METAL, sections=18),
        cylinder(r * 0.8, h * 0.3, (0.0, 0.0, h * 0.85), WHITE, sections=18),
    ]
    return ShapeBuild(parts=parts)


@recipe("candle")
def candle(size: Size, variant: int, color: Color) -> ShapeBuild:
    """A pillar candle on a dish, with a wick and a flame."""
    w, d, h = size
    r = min(w, d) / 2
    flame = min(0.03, h * 0.2)
    body = h - flame - 0.008
    parts = [
        cylinder(r, 0.008, (0.0, 0.0, 0.004), METAL, sections=16),
        cylinder(r * 0.7, body - 0.008, (0.0, 0.0, 0.008 + (body - 0.008) / 2), color, sections=16),
        cylinder(0.0015, 0.01, (0.0, 0.0, body + 0.004), DARK, sections=6),
        sphere(
            0.5,
            (0.0, 0.0, h - flame / 2),
            (1.0, 0.75, 0.2),
            scale=(flame * 0.4, flame * 0.4, flame),
            subdivisions=1,
        ),
    ]
    return ShapeBuild(parts=parts)
