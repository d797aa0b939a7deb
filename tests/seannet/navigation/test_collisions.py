"""Collisions explained and bump-and-replan: the cause of a collision on hand-made layouts,
and an episode on the real renderer whose planned edge is blocked (paper rule, then
``--replan`` around it)."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from seannet.data.datasets import open_dataset
from seannet.data.live_views import LiveRooms
from seannet.errors import NavigationError
from seannet.navigation.episodes import (
    BLOCKED,
    NAVIGATOR_ERROR,
    Episode,
    collision_cause,
    free_path_steps,
    ideal_action,
    run_episode,
    segment_cells,
    step_budget,
)
from seannet.navigation.localizer import load_localizer
from seannet.navigation.maps import TopoMap, ensure_map
from seannet.navigation.motion import FORWARD, HEADINGS

# Only the very view a sub-node stores passes: the oracle stops exactly on its goals, so the
# episode's outcome depends on the layout alone.
EXACT = 0.99999


def _mask(rows: list[str]) -> np.ndarray:
    """A reachable mask from rows of '.' (free) and '#' (blocked); row index is i."""
    return np.array([[c == "." for c in row] for row in rows])


def test_a_collision_on_a_blocked_run_is_no_navigators_fault() -> None:
    layout = _mask(["...", "#..", "..."])  # (1, 0) is taken by a moved chair

    def free(i: int, j: int) -> bool:
        return 0 <= i < 3 and 0 <= j < 3 and bool(layout[i, j])

    assert segment_cells((0, 0, 0), (2, 0, 0)) == [(0, 0), (1, 0), (2, 0)]
    assert segment_cells((2, 2, 1), (2, 0, 1)) == [(2, 2), (2, 1), (2, 0)]
    with pytest.raises(NavigationError, match="straight"):
        segment_cells((0, 0, 0), (2, 2, 0))
    # the planned next cell (1, 0) is blocked, but a sidestep passes: left, forward, forward,
    # right (4 moves); within the steps left that is the navigator's error, beyond them blocked
    assert free_path_steps((0, 0, 0), (2, 0), free, 12) == 4
    assert collision_cause((0, 0, 0), (0, 0, 0), (2, 0, 0), free, 12) == NAVIGATOR_ERROR
    assert free_path_steps((0, 0, 0), (2, 0), free, 3) is None
    assert collision_cause((0, 0, 0), (0, 0, 0), (2, 0, 0), free, 3) == BLOCKED
    # a wall across the room: no navigator could pass, whatever the budget
    wall = _mask(["...", "###", "..."])

    def walled(i: int, j: int) -> bool:
        return 0 <= i < 3 and 0 <= j < 3 and bool(wall[i, j])

    assert collision_cause((0, 1, 0), (0, 1, 0), (2, 1, 0), walled, 100) == BLOCKED
    # backward is no navigator move: a goal behind the robot is out of reach
    assert free_path_steps((2, 1, 0), (0, 1), free, 100) is None
    # the run (0, 1) -> (2, 1) is free: a collision there is the navigator's
    assert ideal_action((0, 1, 0), (2, 1, 0)) == "forward"
    assert collision_cause((0, 1, 0), (0, 1, 0), (2, 1, 0), free) == NAVIGATOR_ERROR
    # off the run (it drifted sideways), or past its end: the navigator's as well
    assert collision_cause((0, 2, 0), (0, 1, 0), (2, 1, 0), free) == NAVIGATOR_ERROR
    assert collision_cause((2, 1, 0), (0, 1, 0), (2, 1, 0), free) == NAVIGATOR_ERROR
    assert step_budget(3) == 72


def _square_edge(topo: TopoMap) -> tuple[tuple[int, int], tuple[int, int], tuple[int, int]]:
    """A translation edge (a, b) of the map and a perpendicular offset p such that a, b,
    a + p, b + p are nodes joined in a square: a detour exists when (a, b) is blocked."""
    edges = {frozenset(((e[0], e[1]), (e[2], e[3]))) for e in topo.meta["edges"]}
    s = topo.spacing
    for pair in sorted(tuple(sorted(e)) for e in edges):
        a, b = pair
        d = (b[0] - a[0], b[1] - a[1])
        for p in ((d[1], d[0]), (-d[1], -d[0])):
            a2, b2 = (a[0] + p[0], a[1] + p[1]), (b[0] + p[0], b[1] + p[1])
            if all(frozenset(x) in edges for x in ((a, a2), (b, b2), (a2, b2))):
                assert abs(p[0]) + abs(p[1]) == s
                return a, b, p
    pytest.skip("the mini test room's map has no square of nodes")


def test_replanning_around_a_blocked_edge(
    localizer_run: Path, mini_dataset: Path, tmp_path: Path
) -> None:
    localizer = load_localizer(localizer_run, mini_dataset, epsilon=EXACT)
    (room,) = open_dataset(mini_dataset).rooms("test")
    with LiveRooms(mini_dataset) as live:
        topo = ensure_map(localizer, live, room, tmp_path / "map")
        a, b, _ = _square_edge(topo)
        step = ((b[0] - a[0]) // topo.spacing, (b[1] - a[1]) // topo.spacing)
        heading = FORWARD.index(step) if step in FORWARD else 0
        # the map's own layout, with the cell between a and b taken: a hand-made change that
        # only that edge crosses (the view is the stored one, so the localizer knows it)
        live.load(room, topo.layout)
        middle = segment_cells((*a, heading), (*b, heading))[1]
        mask = live.grid.reachable.copy()
        mask[middle] = False
        live.grid = dataclasses.replace(live.grid, reachable=mask)
        episode = Episode(room, "N", 0, topo.layout, ((*a, heading), (*b, heading)))

        paper = run_episode(episode, topo, live, localizer, None)
        # the square's other three sides go round the taken cell: a navigator could have
        # passed, so the oracle's bump (it goes straight) is a navigator error, not "blocked"
        detour = free_path_steps((*a, heading), b, live.reachable, 12)
        assert detour is not None and detour > 2
        assert (paper.outcome, paper.detail, paper.replans) == ("collision", NAVIGATOR_ERROR, 0)
        ((goal, steps),) = paper.segments
        assert steps[-1].collided and steps[-1].pose[:2] == middle

        bumped = run_episode(episode, topo, live, localizer, None, replan=True)
        record = bumped.to_dict()
        assert (bumped.outcome, bumped.replans, record["bumps"]) == (
            "success",
            1,
            [NAVIGATOR_ERROR],
        )
        # the same run read under the paper's rule is the paper run
        assert bumped.paper == (paper.outcome, paper.failed_segment, paper.detail)
        # it went round: three two-cell legs after the bump, ending on b, never through middle
        visited = [s.pose[:2] for _, seg in bumped.segments for s in seg if not s.collided]
        assert middle not in visited and visited[-1] == b
        assert record["goals"][-1] == [*b, heading] and len(record["goals"]) == 4
        assert record["steps"] == 1 + 6
        assert all(t >= 0 for t in record["seconds"].values()) and record["seconds"]["render"] > 0
        # the map itself: Dijkstra avoids the blocked edge at every heading
        for h in range(HEADINGS):
            path = topo.shortest_path((*a, h), (*b, h), avoid=[frozenset((a, b))])
            assert len(path) > 2 and all(p[:2] != middle for p in path)
