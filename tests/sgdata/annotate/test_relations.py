"""Relations: the vectorised heuristic against a plain pairwise reference (DESIGN §5)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sgdata.annotate.relations import (
    RelationRules,
    RelationType,
    compute_relations,
    stored_precision,
)
from sgdata.errors import ConfigError


def reference_relations(
    instance: list[int],
    lo: list[list[float]],
    hi: list[list[float]],
    support: list[int],
    tol: float = 0.0,
) -> set[tuple[int, int, int]]:
    """The heuristic pair by pair, written for reading, not speed."""

    def inside(a: int, b: int) -> bool:
        corners = [
            (x, y, z)
            for x in (lo[a][0], hi[a][0])
            for y in (lo[a][1], hi[a][1])
            for z in (lo[a][2], hi[a][2])
        ]
        return all(all(lo[b][k] - tol <= c[k] <= hi[b][k] + tol for k in range(3)) for c in corners)

    def volume(a: int) -> float:
        sx, sy, sz = (hi[a][k] - lo[a][k] for k in range(3))
        return sx * sy * sz

    def smaller(a: int, b: int) -> bool:  # a < b in instance id when volumes tie
        return volume(a) < volume(b) or (volume(a) == volume(b) and instance[a] < instance[b])

    def centre_radius(a: int) -> tuple[list[float], float]:
        c = [(lo[a][k] + hi[a][k]) / 2 for k in range(3)]
        sx, sy, sz = (hi[a][k] - lo[a][k] for k in range(3))
        return c, 0.5 * math.sqrt(sx * sx + sy * sy + sz * sz)

    edges = set()
    idx = sorted(range(len(instance)), key=lambda k: instance[k])
    for p, a in enumerate(idx):
        for b in idx[p + 1 :]:
            ia, ib = instance[a], instance[b]
            if support[a] == ib:
                edges.add((ia, ib, RelationType.ON))
            elif support[b] == ia:
                edges.add((ib, ia, RelationType.ON))
            elif inside(a, b) and smaller(a, b):
                edges.add((ia, ib, RelationType.IN))
            elif inside(b, a) and smaller(b, a):
                edges.add((ib, ia, RelationType.IN))
            else:
                (ca, ra), (cb, rb) = centre_radius(a), centre_radius(b)
                dx, dy, dz = ca[0] - cb[0], ca[1] - cb[1], ca[2] - cb[2]
                near = dx * dx + dy * dy + dz * dz <= (ra + rb) * (ra + rb)  # |ca - cb| <= ra + rb
                kind = RelationType.PROXIMITY if near else RelationType.DISJOINT
                edges.add((ia, ib, kind))
                edges.add((ib, ia, kind))
    return {(s, d, int(t)) for s, d, t in edges}


def _edges(rel) -> set[tuple[int, int, int]]:  # type: ignore[no-untyped-def]
    return set(zip(rel.src.tolist(), rel.dst.tolist(), rel.type.tolist(), strict=True))


@st.composite
def scenes(draw: st.DrawFn) -> tuple[list[int], list[list[float]], list[list[float]], list[int]]:
    n = draw(st.integers(0, 12))
    instance = draw(st.lists(st.integers(0, 60), min_size=n, max_size=n, unique=True))
    # coarse coordinates make containment, equal boxes and touching spheres common
    coord = st.integers(0, 8).map(lambda v: v * 0.25)
    lo, hi = [], []
    for _ in range(n):
        a = [draw(coord) for _ in range(3)]
        b = [draw(coord) for _ in range(3)]
        lo.append([min(x, y) for x, y in zip(a, b, strict=True)])
        hi.append([max(x, y) + 0.25 for x, y in zip(a, b, strict=True)])
    support = [
        draw(st.one_of(st.just(-1), st.sampled_from(instance))) if instance else -1
        for _ in range(n)
    ]
    return instance, lo, hi, support


@settings(max_examples=300, deadline=None)
@given(scenes(), st.sampled_from([0.0, 0.1]))
def test_matches_reference(scene, tol: float) -> None:  # type: ignore[no-untyped-def]
    instance, lo, hi, support = scene
    rel = compute_relations(
        np.array(instance, dtype=np.int64),
        np.array(lo).reshape(-1, 3),
        np.array(hi).reshape(-1, 3),
        np.array(support, dtype=np.int64),
        rules=RelationRules(containment_tolerance=tol),
    )
    assert _edges(rel) == reference_relations(instance, lo, hi, support, tol)
    pairs = list(zip(rel.src.tolist(), rel.dst.tolist(), strict=True))
    assert pairs == sorted(pairs)  # deterministic order
    assert len(set(pairs)) == len(pairs)


def test_named_cases() -> None:
    # 0 table, 1 mug on it, 2 box inside a 3 cabinet, 4/5 chairs side by side, 6 far away
    boxes = {
        10: ([0, 0, 0], [1, 1, 0.75], -1),
        11: ([0.4, 0.4, 0.75], [0.5, 0.5, 0.85], 10),
        12: ([3.1, 0.1, 0.1], [3.3, 0.3, 0.3], 99),  # support not visible -> in
        13: ([3, 0, 0], [3.6, 0.6, 1.2], -1),
        14: ([6, 0, 0], [6.4, 0.4, 0.9], -1),
        15: ([6.5, 0, 0], [6.9, 0.4, 0.9], -1),
        16: ([20, 20, 0], [21, 21, 1], -1),
    }
    inst = np.array(list(boxes))
    lo = np.array([b[0] for b in boxes.values()], dtype=float)
    hi = np.array([b[1] for b in boxes.values()], dtype=float)
    sup = np.array([b[2] for b in boxes.values()])
    edges = _edges(compute_relations(inst, lo, hi, sup))
    assert (11, 10, RelationType.ON) in edges and (10, 11, RelationType.PROXIMITY) not in edges
    assert (12, 13, RelationType.IN) in edges and (13, 12, RelationType.IN) not in edges
    assert {(14, 15, RelationType.PROXIMITY), (15, 14, RelationType.PROXIMITY)} <= edges
    assert (16, 10, RelationType.DISJOINT) in edges and (10, 16, RelationType.DISJOINT) in edges
    assert len(edges) == 7 * 6 - 2  # one edge for on/in pairs, two for the others


def test_on_beats_in_and_is_one_way() -> None:
    # a book resting on a board that is inside it geometrically still gets only "on"
    rel = compute_relations(
        np.array([1, 2]), np.array([[0, 0, 0], [0, 0, 0]]), np.array([[1, 1, 1], [2, 2, 2]]),
        np.array([2, -1]),
    )  # fmt: skip
    assert _edges(rel) == {(1, 2, RelationType.ON)}


def test_tiny_and_empty_inputs() -> None:
    for n in (0, 1):
        rel = compute_relations(np.arange(n), np.zeros((n, 3)), np.ones((n, 3)), -np.ones(n))
        assert len(rel) == 0


def test_rules_are_validated_and_recorded() -> None:
    with pytest.raises(ConfigError):
        RelationRules(containment_tolerance=-0.1)
    with pytest.raises(ConfigError):
        RelationRules(box="obb")
    assert RelationRules().to_dict()["box"] == "world_aabb"


def test_drawer_flush_with_its_cabinet_is_in() -> None:
    """A drawer whose front is flush with its cabinet's front (a shared face, float noise on
    it) is `in` the cabinet under the default 1 mm tolerance, on the stored float32 boxes."""
    cabinet_lo, cabinet_hi = np.array([1.2, 0.3, 0.0]), np.array([1.8, 0.9, 0.85])
    drawer_lo = np.array([1.25, 0.3 - 3e-7, 0.6])  # front face on the cabinet's, noise outside
    drawer_hi = np.array([1.75, 0.8, 0.8])
    lo = stored_precision(np.stack([cabinet_lo, drawer_lo]))
    hi = stored_precision(np.stack([cabinet_hi, drawer_hi]))
    rel = compute_relations(np.array([10, 11]), lo, hi, np.array([-1, -1]))
    assert list(zip(rel.src, rel.dst, rel.type, strict=True)) == [(11, 10, RelationType.IN)]
    strict = compute_relations(
        np.array([10, 11]), lo, hi, np.array([-1, -1]), rules=RelationRules(containment_tolerance=0)
    )
    assert set(strict.type.tolist()) == {RelationType.PROXIMITY}
