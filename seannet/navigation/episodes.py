"""The navigation test (paper §VI-B, Table II): episodes, the rules that judge them, the runner.

An episode starts at a sub-node of a room's map (built in layout 0) and must reach a goal
sub-node after the room changed to another layout. Its map path (Dijkstra) is cut into
segments of two neighbouring sub-nodes. Within a segment, each step is one action: a 90
degree turn where the map's edge is a rotation, else the navigator's forward / left / right
move of one cell; after each step the localizer compares the current view with the goal
sub-node's stored embedding and the robot stops when S > epsilon. At most ``k_max`` = 12
steps per segment. Judged per step (:func:`step_verdict`), first failure ends the episode:

- **collision**: a move into a cell off the layout's reachable grid, classified
  (:func:`collision_cause`) as *path blocked* (from where the robot stood, no collision-free
  sequence of forward / left / right moves on the episode's reachable grid reaches the
  segment's goal within the segment's steps left: no navigator could pass) or *navigator
  error* (one did: a sidestep around a moved object, say);
- **localization**: the robot stopped (S > epsilon) away from the goal (a *false stop*), or
  stood on the goal without stopping and passes it (a *missed goal*);
- **navigation**: ``k_max`` steps without stopping and without a localization failure;
- **success**: every segment stopped within half a cell and 10 degrees of its goal.

A *traced* episode (``trace``, for stop policies chosen offline,
:mod:`seannet.navigation.stopping`) never stops on S: each segment runs until the robot
stands on its goal, collides or spends ``k_max`` steps, every step recording S to the goal,
to the segment's start, to the plan's next sub-node and the best S among the map's other
sub-nodes; the next segment starts on its start sub-node. The navigator's actions never
depend on S, and a segment that ends well ends on its goal's pose, so any stop rule judged on
the trace gives the outcome a run under that rule would have had; the paper's rule included.

Beyond the paper (``rule``): a live run may stop by a chosen stop rule
(:class:`seannet.navigation.stopping.StopRule`) on the same evidence a trace records, and its
map may learn the layout it is in (``memory``): when the rule stops on a goal, that sub-node's
stored embedding becomes the current view's, so what comes later compares against today's
arrangement (the navigator's goal image stays the map's).

Beyond the paper (``replan``): a real robot feels a bump. A collision then marks the
segment's map edge unusable for the episode, the robot localizes itself on the map with the
localizer (its best sub-node) and Dijkstra plans again from there; the episode ends on any
other failure, when no path is left, or past a step budget (:func:`step_budget`).
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from seannet.data.live_views import LiveRooms
from seannet.errors import MapError, NavigationError
from seannet.navigation.config import K_MAX
from seannet.navigation.localizer import AnyLocalizer
from seannet.navigation.maps import TopoMap
from seannet.navigation.motion import (
    HEADINGS,
    NAVIGATOR_ACTIONS,
    TURNS,
    apply,
    local_offset,
    turn_towards,
)
from seannet.navigation.navigator import label_for

__all__ = [
    "BLOCKED",
    "CASES",
    "CAUSES",
    "FAILURES",
    "K_MAX",
    "LOCALIZATION_KINDS",
    "NAVIGATOR_ERROR",
    "OUTCOMES",
    "Episode",
    "EpisodeResult",
    "Step",
    "Timing",
    "collision_cause",
    "evidence_row",
    "free_path_steps",
    "ideal_action",
    "judge_episode",
    "judge_segment",
    "localization_kind",
    "reached",
    "run_episode",
    "sample_episode",
    "segment_cells",
    "step_budget",
    "step_verdict",
]

POSITION_TOLERANCE = 0.5  # cells: "within half a cell" of the goal
ANGLE_TOLERANCE_DEG = 10.0
CASES = ("N", "A")  # neighbour sub-nodes / arbitrary sub-nodes
FAILURES = ("navigation", "localization", "collision")
OUTCOMES = ("success", *FAILURES)
REACHED = "reached"  # a segment's goal reached and stopped at
TRACED = "traced"  # a traced segment's end: on its goal or bumped (every rule has decided)
BLOCKED, NAVIGATOR_ERROR = "path blocked", "navigator error"  # why a collision happened
CAUSES = (BLOCKED, NAVIGATOR_ERROR)
FALSE_STOP, MISSED_GOAL = "false stop", "missed goal"  # the two localization failures
_FALSE_STOPPED = ("localization", FALSE_STOP)  # a stop rule's verdict on a stop off the goal
LOCALIZATION_KINDS = (FALSE_STOP, MISSED_GOAL)
# --replan: the episode's steps may reach this many times the paper's most (k_max per
# segment of the first plan), so detours are possible but a robot bumping in circles stops
REPLAN_BUDGET = 2

Pose = tuple[int, int, int]


@dataclass(frozen=True)
class Step:
    """One action and what followed it."""

    action: str  # forward | left | right | turn_left | turn_right
    pose: Pose  # the true pose after it (for a collision: the blocked pose it tried)
    collided: bool = False
    similarity: float = float("nan")  # S(current view, goal sub-node); NaN after a collision
    cause: str | None = None  # a collision's: BLOCKED or NAVIGATOR_ERROR
    # a traced episode's (run_episode(trace=True)) rival evidence: S to the segment's start
    # sub-node, to the plan's next sub-node after the goal (NaN at the last goal), and the
    # best S among the map's sub-nodes other than the goal
    start_similarity: float = float("nan")
    next_similarity: float = float("nan")
    other_similarity: float = float("nan")


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


def localization_kind(step: Step, goal: Pose, epsilon: float) -> str:
    """Which localization failure ``step`` is: a false stop (S > epsilon away from the goal)
    or a missed goal (on the goal, S <= epsilon)."""
    return MISSED_GOAL if reached(step.pose, goal) and not step.similarity > epsilon else FALSE_STOP


def segment_cells(start: Pose, goal: Pose) -> list[tuple[int, int]]:
    """The cells of a translation edge's straight run, ``start``'s first, ``goal``'s last."""
    (i1, j1), (i2, j2) = start[:2], goal[:2]
    if i1 != i2 and j1 != j2:
        raise NavigationError(f"{start} -> {goal}: not a straight map edge")
    n = abs(i2 - i1) + abs(j2 - j1)
    di, dj = (i2 > i1) - (i2 < i1), (j2 > j1) - (j2 < j1)
    return [(i1 + k * di, j1 + k * dj) for k in range(n + 1)]


def collision_cause(
    pose: Pose,
    start: Pose,
    goal: Pose,
    reachable: Callable[[int, int], bool],
    steps_left: int = K_MAX,
) -> str:
    """Why a move from ``pose`` collided in the translation segment ``start`` -> ``goal``.

    :data:`BLOCKED` when no collision-free path of at most ``steps_left`` navigator moves
    leads from ``pose`` to ``goal`` on the episode's reachable grid (:func:`free_path_steps`):
    no navigator could pass; otherwise :data:`NAVIGATOR_ERROR` (a path was there, a sidestep
    around a moved object, say, and the navigator took another action). ``start`` names the
    segment; the search starts where the robot stood.
    """
    del start  # the segment's start; the robot may have left its straight run
    if pose[2] != goal[2]:  # a translation segment never turns: it drifted off somehow
        return NAVIGATOR_ERROR
    found = free_path_steps(pose, goal[:2], reachable, steps_left)
    return BLOCKED if found is None else NAVIGATOR_ERROR


def free_path_steps(
    pose: Pose, cell: tuple[int, int], reachable: Callable[[int, int], bool], limit: int
) -> int | None:
    """The fewest forward / left / right moves (each one cell, the heading kept) from
    ``pose`` to ``cell`` through reachable cells only, if at most ``limit``; else None.
    A breadth-first search on the grid (backward is no navigator action)."""
    heading = pose[2]
    frontier, seen = [pose[:2]], {pose[:2]}
    for depth in range(limit + 1):
        if cell in seen:
            return depth
        nxt = []
        for i, j in frontier:
            for action in NAVIGATOR_ACTIONS:
                there = apply((i, j, heading), action)[:2]
                if there not in seen and reachable(*there):
                    seen.add(there)
                    nxt.append(there)
        if not nxt:
            return None
        frontier = nxt
    return None


def ideal_action(pose: Pose, goal: Pose) -> str:
    """The navigator's right answer from ``pose`` towards ``goal`` (its label rule)."""
    return NAVIGATOR_ACTIONS[label_for(*local_offset(pose, goal[:2]))]


def step_budget(segments: int, k_max: int = K_MAX) -> int:
    """The steps a ``--replan`` episode may take: twice the paper's most for its first plan."""
    return REPLAN_BUDGET * k_max * segments


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
class Timing:
    """Seconds one episode spent rendering, embedding (localizer) and in the navigator."""

    render: float = 0.0
    embed: float = 0.0
    navigator: float = 0.0

    def timed(self, part: str, fn: Callable[..., Any], *args: Any) -> Any:
        """``fn(*args)``, its wall time added to ``part``."""
        started = time.perf_counter()
        value = fn(*args)
        setattr(self, part, getattr(self, part) + time.perf_counter() - started)
        return value

    def to_dict(self) -> dict[str, float]:
        return {"render": self.render, "embed": self.embed, "navigator": self.navigator}


@dataclass
class EpisodeResult:
    """What happened in one episode."""

    episode: Episode
    outcome: str  # success | navigation | localization | collision
    failed_segment: int  # -1 on success
    detail: str | None  # a collision's cause (CAUSES), a localization failure's kind
    segments: list[tuple[Pose, list[Step]]]
    frames: list[np.ndarray] = field(default_factory=list)  # views after each step (strips)
    # (outcome, failed segment, detail) under the paper's rule: this run's own, or under
    # --replan the first failure of the same run
    paper: tuple[str, int, str | None] = ("success", -1, None)
    replans: int = 0  # --replan: plans made again after a bump
    timing: Timing = field(default_factory=Timing)
    traced: bool = False  # run_episode(trace=True): its steps' evidence goes into to_dict

    def to_dict(self) -> dict[str, Any]:
        """The episode as plain data; ``seconds`` is the only field that varies between runs."""
        e = self.episode
        steps = [s for _, seg in self.segments for s in seg]
        return {
            "room_id": e.room_id,
            "case": e.case,
            "index": e.index,
            "layout": e.layout,
            "path": [list(p) for p in e.path],
            "outcome": self.outcome,
            "detail": self.detail,
            "failed_segment": self.failed_segment,
            "paper": dict(zip(("outcome", "failed_segment", "detail"), self.paper, strict=True)),
            "steps": len(steps),
            "replans": self.replans,
            "bumps": [s.cause for s in steps if s.collided],
            "goals": [list(goal) for goal, _ in self.segments],
            "actions": [[s.action for s in seg] for _, seg in self.segments],
            **({"evidence": self.evidence()} if self.traced else {}),
            "seconds": self.timing.to_dict(),
        }

    def evidence(self) -> list[list[list[Any]]]:
        """Per segment, per step: ``[S goal, S start, S next, S other, on the goal, collision
        cause]`` (a NaN as None; the cause "" when the step did not collide), what a stop rule
        is judged on (:mod:`seannet.navigation.stopping`)."""
        return [[evidence_row(s, goal) for s in steps] for goal, steps in self.segments]


def evidence_row(step: Step, goal: Pose) -> list[Any]:
    """``step``'s evidence as a stop rule reads it (:meth:`EpisodeResult.evidence`)."""

    def number(value: float) -> float | None:
        return None if math.isnan(value) else float(value)

    return [number(step.similarity), number(step.start_similarity),
            number(step.next_similarity), number(step.other_similarity),
            reached(step.pose, goal) and not step.collided, step.cause or ""]  # fmt: skip


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
            near = sorted(n for n in graph.successors(start) if live.reachable(n[0], n[1]))
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
    localizer: AnyLocalizer,
    policy: Any,
    *,
    k_max: int = K_MAX,
    replan: bool = False,
    keep_frames: bool = False,
    trace: bool = False,
    rule: Any = None,
    memory: np.ndarray | None = None,
) -> EpisodeResult:
    """Run ``episode`` on the live renderer (see the module doc).

    Args:
        policy: the navigator, ``policy.act(current, goal)`` on RGB views
            (:class:`seannet.navigation.navigator.Policy`); None is the oracle, which takes
            :func:`ideal_action` from the true pose (a bound that leaves only the localizer).
        replan: bump and replan (beyond the paper) instead of ending on a collision.
        keep_frames: keep every view (for strips).
        trace: never stop on S; record every segment's evidence (see the module doc). Its
            outcome is the paper rule's, judged on the trace.
        rule: stop by this :class:`~seannet.navigation.stopping.StopRule` instead of the
            paper's; its ending is the result's and its paper field's.
        memory: the map's embeddings as this run knows them (a copy of
            ``topo.embeddings``), with ``rule`` only: a stop on a goal writes the current
            view's embedding into the goal's row, in place.

    Raises:
        NavigationError: ``trace`` with ``replan`` (a trace is judged under the paper's
            collision rule), ``rule`` with either, ``memory`` without ``rule``.
    """
    if trace and replan:
        raise NavigationError("a traced episode is judged under the paper's rule: no replan")
    if rule is not None and (trace or replan):
        raise NavigationError("an episode stopped by a chosen rule is neither traced nor replanned")
    if memory is not None and rule is None:
        raise NavigationError("the map learns its layout under a chosen stop rule only")
    stored = topo.embeddings if memory is None else memory
    ended: tuple[str, int, str | None] | None = None  # under rule: how the episode ended
    live.load(episode.room_id, episode.layout)
    clock = Timing()
    pose = episode.path[0]
    current = clock.timed("render", live.view, *pose)
    vector: np.ndarray | None = None  # the current view's embedding, once computed
    frames = [current.rgb] if keep_frames else []
    plan = list(episode.path)
    avoid: set[frozenset[tuple[int, int]]] = set()  # map edges found blocked
    budget = step_budget(len(plan) - 1, k_max) if replan else math.inf
    segments: list[tuple[Pose, list[Step]]] = []
    used = replans = n = 0
    verdict: str | None = REACHED
    while n < len(plan) - 1:
        if used >= budget:  # --replan: the episode's steps are spent
            verdict = None
            break
        a, b = plan[n], plan[n + 1]
        if trace and pose != a:  # every traced segment starts on its start sub-node
            pose = a
            current = clock.timed("render", live.view, *pose)
        goal_vector, goal_image = stored[topo.index(b)], topo.image(b)
        after = plan[n + 2] if n + 2 < len(plan) else None
        rows = _rival_rows(topo, a, b, after) if trace or rule is not None else None
        steps: list[Step] = []
        verdict = None
        while verdict is None and len(steps) < min(k_max, budget - used):
            if a[:2] == b[:2]:
                action = turn_towards(a[2], b[2])  # a rotation edge: the map's turn
            elif policy is None:
                action = ideal_action(pose, b)
            else:
                action = clock.timed("navigator", policy.act, current.rgb, goal_image)
            nxt = apply(pose, action)
            if action not in TURNS and not live.reachable(nxt[0], nxt[1]):
                left = min(k_max, budget - used) - len(steps)  # this segment's steps left
                cause = collision_cause(pose, a, b, live.reachable, int(left))
                steps.append(Step(action, nxt, collided=True, cause=cause))
            else:
                pose = nxt
                current = clock.timed("render", live.view, *pose)
                vector = clock.timed("embed", _embed, localizer, live, current)
                similarity = float(localizer.similarities(vector, goal_vector[None])[0])
                step = Step(action, pose, similarity=similarity)
                if rows is not None:
                    step = _with_rivals(step, localizer.similarities(vector, stored), rows)
                steps.append(step)
                if keep_frames:
                    frames.append(current.rgb)
            if trace:  # on the goal or bumped: every stop rule has decided this segment
                last = steps[-1]
                verdict = TRACED if last.collided or reached(last.pose, b) else None
            elif rule is not None:
                decided = rule.verdict([evidence_row(s, b) for s in steps])
                verdict = None if decided is None else decided[0]
                if decided is not None and decided[0] != REACHED:
                    ended = (decided[0], n, decided[1])
                if memory is not None and (verdict == REACHED or decided == _FALSE_STOPPED):
                    memory[topo.index(b)] = vector  # it stopped: it believes it stands on b
            else:
                verdict = step_verdict(steps[-1], b, localizer.epsilon)
        used += len(steps)
        segments.append((b, steps))
        if rule is not None and verdict is None:  # k_max steps decided nothing
            ended = ("navigation", n, None)
        if verdict == REACHED or trace:
            n += 1
            continue
        if verdict == "collision" and replan and used < budget:
            avoid.add(frozenset((a[:2], b[:2])))
            if vector is None:  # bumped on the first move: the start view is not embedded yet
                vector = clock.timed("embed", _embed, localizer, live, current)
            best = np.argmax(localizer.similarities(vector, topo.embeddings))
            here = topo.sub_nodes()[int(best)]
            new = _replan(topo, here, plan[-1], avoid)
            if new is not None:
                plan, n, replans = new, 0, replans + 1
                continue
        break
    # The paper's rule, a collision ends it: the first failure. Under --replan the steps
    # before the first bump are the paper run's own (same views, same actions), so its
    # paper-rule outcome is read off the same run.
    if rule is not None:
        ending = ended or ("success", -1, None)
        return EpisodeResult(episode, *ending, segments, frames, ending, 0, clock)
    epsilon = localizer.epsilon
    paper = _ending(segments, *judge_episode(segments, epsilon, k_max=k_max), epsilon, k_max)
    ending = paper
    if replan:
        failed = len(segments) - 1
        last = ("success", -1) if verdict == REACHED else (verdict or "navigation", failed)
        ending = _ending(segments, *last, epsilon, k_max)
    return EpisodeResult(episode, *ending, segments, frames, paper, replans, clock, trace)


def _ending(
    segments: list[tuple[Pose, list[Step]]],
    outcome: str,
    failed: int,
    epsilon: float,
    k_max: int,
) -> tuple[str, int, str | None]:
    """(outcome, failed segment, detail): a collision's cause or a localization failure's
    kind, read off the step that decided the failed segment (a traced segment goes on
    after it)."""
    detail = None
    if outcome in ("collision", "localization"):
        goal, steps = segments[failed]
        _, used = judge_segment(goal, steps, epsilon, k_max=k_max)
        last = steps[used - 1]
        detail = last.cause if last.collided else localization_kind(last, goal, epsilon)
    return outcome, failed, detail


def _rival_rows(topo: TopoMap, start: Pose, goal: Pose, after: Pose | None) -> tuple:
    """A traced segment's rows of the map: its goal, its start, the plan's next sub-node."""
    return topo.index(goal), topo.index(start), None if after is None else topo.index(after)


def _with_rivals(step: Step, scores: np.ndarray, rows: tuple) -> Step:
    """``step`` with its rival evidence from ``scores`` (S against every map row)."""
    goal, start, after = rows
    others = np.delete(scores, goal)
    return dataclasses.replace(
        step,
        start_similarity=float(scores[start]),
        next_similarity=float("nan") if after is None else float(scores[after]),
        other_similarity=float(others.max()) if len(others) else float("nan"),
    )


def _embed(localizer: AnyLocalizer, live: LiveRooms, view: Any) -> np.ndarray:
    return localizer.embed([live.tensors(view, localizer.transform)])[0]


def _replan(
    topo: TopoMap, here: Pose, goal: Pose, avoid: set[frozenset[tuple[int, int]]]
) -> list[Pose] | None:
    """Dijkstra's path from ``here`` to ``goal`` without the ``avoid`` edges; None when
    there is none (or the robot believes it is at the goal already)."""
    try:
        path = topo.shortest_path(here, goal, avoid=avoid)
    except MapError:
        return None
    return path if len(path) > 1 else None
