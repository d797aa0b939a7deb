"""The navigation test (paper §VI-B, Table II): episodes, the rules that judge them, the runner.

An episode starts at a sub-node of a room's map (built in layout 0) and must reach a goal
sub-node after the room changed to another layout. Its map path (Dijkstra) is cut into
segments of two neighbouring sub-nodes. Within a segment, each step is one action: a 90
degree turn where the map's edge is a rotation, else the navigator's forward / left / right
move of one cell; after each step the localizer compares the current view with the goal
sub-node's stored embedding and the robot stops when S > epsilon. At most ``k_max`` = 12
steps per segment. Judged per step (:func:`step_verdict`), first failure ends the episode:

- **collision**: a move into a cell off the layout's reachable grid;
- **localization**: the robot stopped (S > epsilon) away from the goal, or stood on the goal
  without stopping (it passes it);
- **navigation**: ``k_max`` steps without stopping and without a localization failure;
- **success**: every segment stopped within half a cell and 10 degrees of its goal.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from seannet.data.live_views import LiveRooms
from seannet.errors import MapError, NavigationError
from seannet.navigation.localizer import Localizer
from seannet.navigation.maps import TopoMap
from seannet.navigation.motion import HEADINGS, TURNS, apply, turn_towards

__all__ = [
    "CASES",
    "FAILURES",
    "K_MAX",
    "OUTCOMES",
    "Episode",
    "EpisodeResult",
    "Step",
    "judge_episode",
    "judge_segment",
    "reached",
    "run_episode",
    "sample_episode",
    "step_verdict",
]

K_MAX = 12  # steps per segment (paper §VI-B)
POSITION_TOLERANCE = 0.5  # cells: "within half a cell" of the goal
ANGLE_TOLERANCE_DEG = 10.0
CASES = ("N", "A")  # neighbour sub-nodes / arbitrary sub-nodes
FAILURES = ("navigation", "localization", "collision")
OUTCOMES = ("success", *FAILURES)
REACHED = "reached"  # a segment's goal reached and stopped at

Pose = tuple[int, int, int]


@dataclass(frozen=True)
class Step:
    """One action and what followed it."""

    action: str  # forward | left | right | turn_left | turn_right
    pose: Pose  # the true pose after it (for a collision: the blocked pose it tried)
    collided: bool = False
    similarity: float = float("nan")  # S(current view, goal sub-node); NaN after a collision


def reached(pose: Pose, goal: Pose) -> bool:
    """Within half a cell and 10 degrees of ``goal`` (poses in cells and heading indices)."""
    distance = math.hypot(pose[0] - goal[0], pose[1] - goal[1])
    turn = abs((pose[2] - goal[2]) % HEADINGS) * 360.0 / HEADINGS
    return distance <= POSITION_TOLERANCE and min(turn, 360.0 - turn) <= ANGLE_TOLERANCE_DEG


def step_verdict(step: Step, goal: Pose, epsilon: float) -> str | None:
    """``"reached"``, a failure class, or None (keep going) after ``step``."""
    if step.collided:
        return "collision"
    here = reached(step.pose, goal)
    if step.similarity > epsilon:
        return REACHED if here else "localization"  # stopped: at the goal, or a false positive
    return "localization" if here else None  # on the goal without stopping: it passes it


def judge_segment(
    goal: Pose, steps: Sequence[Step], epsilon: float, *, k_max: int = K_MAX
) -> tuple[str, int]:
    """(verdict, steps used) of one segment's steps.

    Raises:
        NavigationError: fewer than ``k_max`` steps and none decides (an unfinished segment).
    """
    for k, step in enumerate(steps[:k_max], 1):
        verdict = step_verdict(step, goal, epsilon)
        if verdict is not None:
            return verdict, k
    if len(steps) < k_max:
        raise NavigationError(f"segment to {goal}: {len(steps)} steps decide nothing (< {k_max})")
    return "navigation", k_max


def judge_episode(
    segments: Sequence[tuple[Pose, Sequence[Step]]], epsilon: float, *, k_max: int = K_MAX
) -> tuple[str, int]:
    """(outcome, index of the failing segment or -1) of an episode's (goal, steps) segments."""
    for n, (goal, steps) in enumerate(segments):
        verdict, _ = judge_segment(goal, steps, epsilon, k_max=k_max)
        if verdict != REACHED:
            return verdict, n
    return "success", -1


@dataclass(frozen=True)
class Episode:
    """One test case: a room, the layout the world is in, and a map path."""

    room_id: str
    case: str  # N | A
    index: int
    layout: int  # the world's layout (the map's is another)
    path: tuple[Pose, ...]  # start ... goal sub-nodes


@dataclass
class EpisodeResult:
    """What happened in one episode."""

    episode: Episode
    outcome: str  # success | navigation | localization | collision
    failed_segment: int  # -1 on success
    segments: list[tuple[Pose, list[Step]]]
    frames: list[np.ndarray] = field(default_factory=list)  # views after each step (strips)

    def to_dict(self) -> dict[str, Any]:
        e = self.episode
        return {
            "room_id": e.room_id,
            "case": e.case,
            "index": e.index,
            "layout": e.layout,
            "path": [list(p) for p in e.path],
            "outcome": self.outcome,
            "failed_segment": self.failed_segment,
            "steps": sum(len(s) for _, s in self.segments),
            "actions": [[s.action for s in steps] for _, steps in self.segments],
        }


def sample_episode(
    topo: TopoMap,
    live: LiveRooms,
    case: str,
    rng: np.random.Generator,
    *,
    index: int = 0,
    tries: int = 50,
) -> Episode:
    """A seeded episode: another layout than the map's, start and goal sub-nodes on cells
    reachable in it, joined by one map edge (N) or by any map path (A).

    Raises:
        NavigationError: unknown case, a room with one layout, or no episode in ``tries``.
    """
    if case not in CASES:
        raise NavigationError(f"case {case!r}: expected one of {', '.join(CASES)}")
    others = [k for k in live.layouts(topo.room_id) if k != topo.layout]
    if not others:
        raise NavigationError(f"{topo.room_id}: one layout only; the test needs another one")
    layout = others[int(rng.integers(len(others)))]
    live.load(topo.room_id, layout)
    nodes = [k for k in topo.sub_nodes() if live.reachable(k[0], k[1])]
    graph = topo.graph()
    for _ in range(tries if nodes else 0):
        start = nodes[int(rng.integers(len(nodes)))]
        if case == "N":
            near = sorted(n for n in graph.neighbors(start) if live.reachable(n[0], n[1]))
            if not near:
                continue
            path = [start, near[int(rng.integers(len(near)))]]
        else:
            goal = nodes[int(rng.integers(len(nodes)))]
            if goal == start:
                continue
            try:
                path = topo.shortest_path(start, goal)
            except MapError:
                continue
        return Episode(topo.room_id, case, index, layout, tuple(path))
    raise NavigationError(f"{topo.room_id} layout {layout}: no {case} episode in {tries} draws")


def run_episode(
    episode: Episode,
    topo: TopoMap,
    live: LiveRooms,
    localizer: Localizer,
    policy: Any,
    *,
    k_max: int = K_MAX,
    keep_frames: bool = False,
) -> EpisodeResult:
    """Run ``episode`` on the live renderer (see the module doc); ``policy.act(current,
    goal)`` is the navigator (:class:`seannet.navigation.train_navigator.Policy`)."""
    live.load(episode.room_id, episode.layout)
    pose = episode.path[0]
    current = live.view(*pose)
    frames = [current.rgb] if keep_frames else []
    segments: list[tuple[Pose, list[Step]]] = []
    for a, b in zip(episode.path, episode.path[1:], strict=False):
        goal_vector = topo.embedding(b)
        goal_image = topo.image(b)
        rotation = a[:2] == b[:2]
        steps: list[Step] = []
        verdict = None
        while verdict is None and len(steps) < k_max:
            action = turn_towards(a[2], b[2]) if rotation else policy.act(current.rgb, goal_image)
            nxt = apply(pose, action)
            if action not in TURNS and not live.reachable(nxt[0], nxt[1]):
                steps.append(Step(action, nxt, collided=True))
            else:
                pose = nxt
                current = live.view(*pose)
                vector = localizer.embed([live.tensors(current, localizer.transform)])[0]
                steps.append(Step(action, pose, similarity=float(vector @ goal_vector)))
                if keep_frames:
                    frames.append(current.rgb)
            verdict = step_verdict(steps[-1], b, localizer.epsilon)
        segments.append((b, steps))
        if verdict != REACHED:
            break
    outcome, failed = judge_episode(segments, localizer.epsilon, k_max=k_max)
    return EpisodeResult(episode, outcome, failed, segments, frames)
