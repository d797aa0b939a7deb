"""Sizes a home holds: a room or object measured beyond them was likely authored in other units."""

from __future__ import annotations

from pathlib import Path

from pxr import Usd, UsdGeom

from sgdata.errors import UsdError
from sgdata.usd.stage_frame import meters_per_unit, room_prim
from sgdata.usd.user_rooms import MeasuredRoom

__all__ = ["check_sizes"]

_SLACK = 1.0  # metres an object may stand outside the room (a painting on a wall, a doormat)


def check_sizes(
    stage: Usd.Stage,
    path: Path,
    measured: MeasuredRoom,
    *,
    max_room: float,
    max_object: float,
) -> None:
    """Refuse a room wider, deeper or taller than ``max_room`` metres, an object standing
    outside it, or an object larger than ``max_object`` metres along any side.

    A room modelled in centimetres whose ``metersPerUnit`` was left at 1 measures a hundred
    times too large and would otherwise make a dataset of 400 m rooms and 75 m tables.

    Args:
        stage: the composed stage ``measured`` was read from.
        path: its file, named in the message.
        measured: the room :func:`sgdata.usd.user_rooms.measure_stage` read.
        max_room: metres; the config's ``[rooms] max_room_size``.
        max_object: metres; the config's ``[rooms] max_object_size``.

    Raises:
        UsdError: one line naming the prim, its measured size, the stage's ``metersPerUnit`` and
            ``upAxis``, and both fixes (the units, or the ``[rooms]`` limit).
    """
    room = measured.room
    units = f"metersPerUnit {meters_per_unit(stage):g} and upAxis {UsdGeom.GetStageUpAxis(stage)}"
    fix = (
        "if the file is in centimetres set its metersPerUnit = 0.01 (millimetres: 0.001); "
        "if it really is this large, raise [rooms] {key}"
    )
    sides = (room.width, room.depth, room.height)
    if max(sides) > max_room:
        raise UsdError(
            f"{path}: {room_prim(stage).GetPath()} measures {_size(sides)} m with the stage's "
            f"{units}; a home's room is at most {max_room:g} m a side: "
            + fix.format(key=f"max_room_size (now {max_room:g})")
        )
    bounds = (room.width, room.depth, room.height)
    for obj in room.objects:
        at = (obj.placement.x, obj.placement.y, obj.placement.z)
        if any(not -_SLACK <= v <= side + _SLACK for v, side in zip(at, bounds, strict=True)):
            raise UsdError(
                f"{path}: {measured.paths[obj.instance]} ({obj.class_name}) stands at "
                f"({_size(at, ', ')}) m, outside the room's {_size(bounds)} m; move it into "
                "the room or remove it"
            )
    largest = max(room.objects, key=lambda o: max(o.size), default=None)
    if largest is not None and max(largest.size) > max_object:
        raise UsdError(
            f"{path}: {measured.paths[largest.instance]} ({largest.class_name}) measures "
            f"{_size(largest.size)} m with the stage's {units}; a home's object is at most "
            f"{max_object:g} m a side: " + fix.format(key=f"max_object_size (now {max_object:g})")
        )


def _size(sides: tuple[float, ...], sep: str = " x ") -> str:
    return sep.join(f"{v:.3g}" for v in sides)
