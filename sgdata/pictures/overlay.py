"""A human-readable picture of an annotated view: boxes, class names and relation arrows."""

from __future__ import annotations

import colorsys
import math
import zlib

import numpy as np
from PIL import Image, ImageDraw, ImageFont

from sgdata.annotate.records import ViewRecord
from sgdata.annotate.relations import RelationType

__all__ = ["RELATION_COLORS", "draw_overlay"]

RELATION_COLORS = {  # disjoint edges are not drawn
    RelationType.ON: (230, 40, 40),
    RelationType.IN: (40, 110, 255),
    RelationType.PROXIMITY: (30, 200, 70),
}


def _class_color(name: str) -> tuple[int, int, int]:
    """A stable bright colour per class name."""
    hue = (zlib.crc32(name.encode()) % 360) / 360.0
    r, g, b = colorsys.hsv_to_rgb(hue, 0.75, 1.0)
    return (int(r * 255), int(g * 255), int(b * 255))


def _arrow(
    draw: ImageDraw.ImageDraw,
    a: tuple[float, float],
    b: tuple[float, float],
    color: tuple[int, int, int],
    *,
    heads: int = 1,
    width: int = 2,
) -> None:
    """A line a -> b with an arrow head at b (and at a when ``heads`` is 2)."""
    draw.line([a, b], fill=color, width=width)
    ends = [(a, b)] if heads == 1 else [(a, b), (b, a)]
    for p, q in ends:
        ang = math.atan2(q[1] - p[1], q[0] - p[0])
        size = 9.0
        left = (q[0] - size * math.cos(ang - 0.45), q[1] - size * math.sin(ang - 0.45))
        right = (q[0] - size * math.cos(ang + 0.45), q[1] - size * math.sin(ang + 0.45))
        draw.polygon([q, left, right], fill=color)


def draw_overlay(record: ViewRecord, *, scale: int = 3) -> Image.Image:
    """The view's RGB upscaled ``scale`` times with 2D boxes, labels, relation arrows and a
    legend strip below (on: red, in: blue, proximity: green, both heads; disjoint: not drawn).
    """
    img = Image.fromarray(np.asarray(record.rgb)).resize(
        (record.image_width * scale, record.image_height * scale), Image.Resampling.NEAREST
    )
    legend_h = 22
    canvas = Image.new("RGB", (img.width, img.height + legend_h), (20, 20, 20))
    canvas.paste(img, (0, 0))
    draw = ImageDraw.Draw(canvas)
    font = ImageFont.load_default()
    centre: dict[int, tuple[float, float]] = {}
    for inst, cls, box in zip(
        record.obj_instance.tolist(), record.obj_class, record.obj_box2d.tolist(), strict=True
    ):
        u1, v1, u2, v2 = (c * scale for c in box)
        color = _class_color(cls)
        draw.rectangle([u1, v1, u2 - 1, v2 - 1], outline=color, width=2)
        centre[inst] = ((u1 + u2) / 2, (v1 + v2) / 2)
    for src, dst, kind in zip(
        record.rel_src.tolist(), record.rel_dst.tolist(), record.rel_type.tolist(), strict=True
    ):
        rt = RelationType(kind)
        if rt not in RELATION_COLORS:
            continue
        if rt == RelationType.PROXIMITY:
            if src > dst:  # symmetric: draw once with two heads
                continue
            _arrow(draw, centre[src], centre[dst], RELATION_COLORS[rt], heads=2)
        else:
            _arrow(draw, centre[src], centre[dst], RELATION_COLORS[rt])
    for inst, cls, box in zip(
        record.obj_instance.tolist(), record.obj_class, record.obj_box2d.tolist(), strict=True
    ):
        label = f"{cls} #{inst}"
        x, y = box[0] * scale + 2, max(0, box[1] * scale - 12)
        tb = draw.textbbox((x, y), label, font=font)
        draw.rectangle(tb, fill=(0, 0, 0))
        draw.text((x, y), label, fill=_class_color(cls), font=font)
    x = 6
    y = img.height + 5
    for rt, color in RELATION_COLORS.items():
        draw.rectangle([x, y + 2, x + 14, y + 10], fill=color)
        name = rt.name.lower()
        draw.text((x + 18, y), name, fill=(235, 235, 235), font=font)
        x += 18 + int(draw.textlength(name, font=font)) + 16
    draw.text(
        (x, y),
        f"{record.room_id} L{record.layout} ({record.grid_i},{record.grid_j}) h{record.heading}",
        fill=(160, 160, 160),
        font=font,
    )
    return canvas
