"""Colourised depth and masks beside the RGB: the strip ``sgdata render`` and ``sgdata report``
draw for people to check the channels (:mod:`sgdata.dataset.channels`).

Depth is drawn near = bright, far = dark (a fixed 0..8 m ramp through a viridis-like palette,
so two pictures compare), no hit black; a mask gives each value a fixed colour hashed from it
(0 black), so a class has the same colour in every view's class panel.
"""

from __future__ import annotations

import numpy as np
from PIL import Image, ImageDraw

from sgdata.dataset.channels import class_mask

__all__ = ["DEPTH_RAMP_METRES", "channel_strip", "colour_depth", "colour_mask"]

DEPTH_RAMP_METRES = 8.0  # depth at the dark end of the ramp
# a few stops of a viridis-like ramp, far (index 0) to near (last)
_STOPS = np.array(
    [[68, 1, 84], [59, 82, 139], [33, 145, 140], [94, 201, 98], [253, 231, 37]], dtype=np.float64
)


def colour_depth(metres: np.ndarray) -> np.ndarray:
    """(H, W, 3) uint8: near bright yellow, far dark violet, no hit (0) black."""
    t = 1.0 - np.clip(metres / DEPTH_RAMP_METRES, 0.0, 1.0)
    x = t * (len(_STOPS) - 1)
    lo = np.minimum(x.astype(np.int64), len(_STOPS) - 2)
    f = (x - lo)[..., None]
    rgb = _STOPS[lo] * (1 - f) + _STOPS[lo + 1] * f
    rgb[metres <= 0] = 0
    return rgb.round().astype(np.uint8)


def colour_mask(mask: np.ndarray) -> np.ndarray:
    """(H, W, 3) uint8: each non-zero value a fixed bright colour, 0 black."""
    values = np.arange(int(mask.max(initial=0)) + 1, dtype=np.uint64)
    hashed = (values * np.uint64(2654435761)) & np.uint64(0xFFFFFF)
    palette = np.stack([(hashed >> np.uint64(s)) & np.uint64(255) for s in (0, 8, 16)], axis=1)
    palette = (64 + palette.astype(np.uint16) * 191 // 255).astype(np.uint8)
    palette[0] = 0
    return palette[mask]


def channel_strip(
    rgb: np.ndarray,
    *,
    depth: np.ndarray | None,
    instances: np.ndarray | None,
    class_ids: np.ndarray | None = None,
    structure: np.ndarray | None = None,
    n_classes: int = 0,
) -> Image.Image:
    """RGB | depth | instances | classes side by side, each panel titled; a channel that is
    None is left out (the class panel needs ``instances`` and ``class_ids``).

    Args:
        rgb: (H, W, 3) uint8.
        depth: (H, W) metres (0: no hit) or None.
        instances: (H, W) uint16 instance mask or None.
        class_ids: the listed objects' class ids (for the class panel).
        structure: (H, W) structure mask or None; the class panel then shows the room's
            parts too, as classes after the ``n_classes`` of the catalog.
    """
    panels = [("rgb", rgb)]
    if depth is not None:
        panels.append((f"depth 0-{DEPTH_RAMP_METRES:g} m", colour_depth(depth)))
    if instances is not None:
        panels.append(("instances", colour_mask(instances)))
        if class_ids is not None:
            classes = class_mask(instances, class_ids, structure, n_classes=n_classes)
            panels.append(("classes", colour_mask(classes)))
    h, w = rgb.shape[:2]
    title = 14
    strip = Image.new("RGB", (len(panels) * w + (len(panels) - 1) * 4, h + title), "white")
    draw = ImageDraw.Draw(strip)
    for k, (name, pixels) in enumerate(panels):
        x = k * (w + 4)
        draw.text((x + 2, 1), name, fill="black")
        strip.paste(Image.fromarray(np.ascontiguousarray(pixels)), (x, title))
    return strip
