"""The parts of a room's structure that a view's structure mask names, in one place: the
renderer draws them (:mod:`sgdata.render.structure`) and the dataset stores them
(:mod:`sgdata.dataset.channels`). Part ``k`` of :data:`STRUCTURE_PARTS` is mask value ``k + 1``;
0 is an object or nothing drawn."""

from __future__ import annotations

__all__ = ["CEILING", "DOOR", "FLOOR", "STRUCTURE_PARTS", "WALL"]

STRUCTURE_PARTS = ("wall", "floor", "ceiling", "door")
WALL, FLOOR, CEILING, DOOR = range(1, len(STRUCTURE_PARTS) + 1)
