"""Grid motion of the agent (paper §VI): its five actions and where each takes a grid pose.

A pose is ``(i, j, h)``: a cell of the pose grid and a heading index (0..3 for 0, 90, 180,
270 degrees; heading 0 looks along +X, 90 along +Y). Translations move one cell d without
turning: ``forward`` along the heading, ``left`` / ``right`` sideways (left is 90 degrees
counter-clockwise of the heading, since Z is up); ``turn_left`` / ``turn_right`` rotate 90
degrees in place.
"""

from __future__ import annotations

from seannet.data.poses import HEADINGS

__all__ = [
    "ACTIONS",
    "FORWARD",
    "HEADINGS",
    "NAVIGATOR_ACTIONS",
    "TURNS",
    "apply",
    "local_offset",
    "turn_towards",
]

# heading index -> the unit grid step (di, dj) of moving forward
FORWARD = ((1, 0), (0, 1), (-1, 0), (0, -1))
NAVIGATOR_ACTIONS = ("forward", "left", "right")  # the navigator's logits, in this order
TURNS = ("turn_left", "turn_right")
ACTIONS = NAVIGATOR_ACTIONS + TURNS

Pose = tuple[int, int, int]


def apply(pose: Pose, action: str) -> Pose:
    """The pose after ``action`` (no collision check).

    Raises:
        ValueError: an unknown action (a bug: actions come from :data:`ACTIONS`).
    """
    i, j, h = pose
    if action == "turn_left":
        return (i, j, (h + 1) % HEADINGS)
    if action == "turn_right":
        return (i, j, (h - 1) % HEADINGS)
    step = {"forward": h, "left": (h + 1) % HEADINGS, "right": (h - 1) % HEADINGS}.get(action)
    if step is None:
        raise ValueError(f"unknown action {action!r}; expected one of {ACTIONS}")
    di, dj = FORWARD[step]
    return (i + di, j + dj, h)


def local_offset(start: Pose, cell: tuple[int, int]) -> tuple[int, int]:
    """(forward, left) cells from ``start`` to ``cell`` in ``start``'s own frame."""
    di, dj = cell[0] - start[0], cell[1] - start[1]
    fi, fj = FORWARD[start[2]]
    li, lj = FORWARD[(start[2] + 1) % HEADINGS]
    return (di * fi + dj * fj, di * li + dj * lj)


def turn_towards(heading: int, goal: int) -> str:
    """The turn that brings ``heading`` one step closer to ``goal`` (left on a tie)."""
    return "turn_right" if (goal - heading) % HEADINGS == 3 else "turn_left"
