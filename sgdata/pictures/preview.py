"""Top-down pictures of rooms and layouts with class labels (PNG, for people to check)."""

from __future__ import annotations

import numpy as np
from PIL import Image, ImageDraw, ImageFont

from sgdata.world.scene import Room, SceneObject

__all__ = ["draw_room", "draw_layout_pair"]

PIXELS_PER_METRE = 140
MARGIN = 40
WALL_COLOR = (60, 60, 60)
DOOR_COLOR = (230, 160, 40)
MOVED_COLOR = (220, 30, 30)


def _font(size: int) -> ImageFont.ImageFont:
    return ImageFont.load_default(size=size)


def draw_room(
    room: Room, *, moved: set[int] | None = None, title: str | None = None
) -> Image.Image:
    """A top-down drawing of ``room``: footprints filled with object colours, labels, door.

    Objects in ``moved`` are outlined in red. Objects are drawn from the floor up, so what
    rests on a table is drawn over it.
    """
    moved = moved or set()
    scale = PIXELS_PER_METRE
    width = int(room.width * scale) + 2 * MARGIN
    height = int(room.depth * scale) + 2 * MARGIN + 24
    image = Image.new("RGB", (width, height), (250, 250, 247))
    draw = ImageDraw.Draw(image)

    def to_px(x: float, y: float) -> tuple[float, float]:
        # north (y = depth) at the top of the picture
        return MARGIN + x * scale, 24 + MARGIN + (room.depth - y) * scale

    corners = [to_px(0, 0), to_px(room.width, room.depth)]
    draw.rectangle(
        [corners[0][0], corners[1][1], corners[1][0], corners[0][1]], outline=WALL_COLOR, width=4
    )
    _draw_door(draw, room, to_px)
    font = _font(11)
    labels: list[tuple[tuple[float, float], str, bool]] = []
    for obj in sorted(room.objects, key=lambda o: (o.world_aabb()[1][2], o.instance)):
        polygon = [to_px(*c[:2]) for c in _footprint(obj)]
        fill = tuple(int(255 * c) for c in obj.color)
        is_moved = obj.instance in moved
        draw.polygon(
            polygon,
            fill=fill,
            outline=MOVED_COLOR if is_moved else (30, 30, 30),
            width=3 if is_moved else 1,
        )
        if obj.attached_to is None:
            labels.append((to_px(obj.placement.x, obj.placement.y), obj.class_name, is_moved))
    for (x, y), text, is_moved in labels:
        box = draw.textbbox((x, y), text, font=font, anchor="mm")
        draw.rectangle(box, fill=(255, 255, 255))
        draw.text((x, y), text, fill=MOVED_COLOR if is_moved else (0, 0, 0), font=font, anchor="mm")
    heading = (
        title
        or f"{room.room_id}  {room.width:.2f} x {room.depth:.2f} m  {len(room.objects)} objects"
    )
    draw.text((MARGIN, 8), heading, fill=(0, 0, 0), font=_font(15))
    return image


def draw_layout_pair(base: Room, layout: Room, *, title: str = "layout") -> Image.Image:
    """The base room beside a layout, moved objects outlined in red on the layout."""
    before = {o.instance: o.placement for o in base.objects}
    moved = {o.instance for o in layout.objects if before.get(o.instance) != o.placement}
    left = draw_room(base, title=f"{base.room_id}  base layout")
    right = draw_room(layout, moved=moved, title=f"{base.room_id}  {title}: {len(moved)} moved")
    pair = Image.new(
        "RGB", (left.width + right.width + 10, max(left.height, right.height)), "white"
    )
    pair.paste(left, (0, 0))
    pair.paste(right, (left.width + 10, 0))
    return pair


def _footprint(obj: SceneObject) -> np.ndarray:
    # the bottom four corners, in order around the rectangle
    c = obj.corners()
    return c[[0, 2, 6, 4]]


def _draw_door(draw: ImageDraw.ImageDraw, room: Room, to_px) -> None:  # noqa: ANN001
    door = room.door
    a, b = door.center - door.width / 2, door.center + door.width / 2
    ends = {
        "south": ((a, 0), (b, 0)),
        "north": ((a, room.depth), (b, room.depth)),
        "west": ((0, a), (0, b)),
        "east": ((room.width, a), (room.width, b)),
    }[door.wall]
    draw.line([to_px(*ends[0]), to_px(*ends[1])], fill=DOOR_COLOR, width=8)
