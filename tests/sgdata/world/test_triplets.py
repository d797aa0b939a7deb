"""sgdata.world.triplets: Table I offsets, exact shares, reachability, determinism, errors."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sgdata.errors import ConfigError
from sgdata.world.triplets import (
    DEFAULT_SHARES,
    TIERS,
    PoseKey,
    RoomPoses,
    Triplet,
    heading_step,
    referenced_poses,
    referenced_poses_by_room,
    sample_triplets,
    tier_counts,
)

# Table I written out again, independently of the module: per tier, the positive's
# |α|+|β| (None: same pose in another layout) and the negative's (None: same cell, γ != 0).
TABLE_I = {0: (None, 1), 1: (1, 2), 2: (2, 3), 3: (3, 4), 4: (4, None)}


def make_room(
    room_id: str,
    *,
    split: str = "train",
    rows: int = 12,
    cols: int = 13,
    layouts: int = 5,
    hole: float = 0.1,
    seed: int = 0,
    origin: tuple[int, int] = (0, 0),
) -> RoomPoses:
    """A rows x cols room whose layouts each block a random ``hole`` fraction of cells."""
    rng = np.random.default_rng(seed)
    reachable = {}
    for layout in range(layouts):
        free = rng.random((rows, cols)) >= hole
        reachable[layout] = frozenset(
            (int(i) + origin[0], int(j) + origin[1]) for i, j in np.argwhere(free)
        )
    return RoomPoses(room_id, split, reachable)


def offset(a: PoseKey, b: PoseKey) -> tuple[int, int, int]:
    """(α, β, γ) recomputed by hand, γ in {-1, 0, 1, 2}."""
    gamma = {0: 0, 1: 1, 2: 2, 3: -1}[(b.heading - a.heading) % 4]
    return b.i - a.i, b.j - a.j, gamma


def check_triplet(t: Triplet, rooms: dict[str, RoomPoses]) -> None:
    """Everything a single triplet must satisfy, checked against the plain Table I."""
    room = rooms[t.room_id]
    for key in (t.anchor, t.positive, t.negative):
        assert key.layout in room.reachable
        assert (key.i, key.j) in room.reachable[key.layout], (t, key)
        assert 0 <= key.heading < 4
    pos_rule, neg_rule = TABLE_I[t.tier]
    a, b, g = offset(t.anchor, t.positive)
    assert t.positive_offset == (a, b, g)
    if pos_rule is None:
        assert (a, b, g) == (0, 0, 0)
        assert t.positive.layout != t.anchor.layout
    else:
        assert abs(a) + abs(b) == pos_rule and g == 0
    a, b, g = offset(t.anchor, t.negative)
    assert t.negative_offset == (a, b, g)
    if neg_rule is None:
        assert (a, b) == (0, 0) and g != 0
    else:
        assert abs(a) + abs(b) == neg_rule and g == 0


def all_triplets(room: RoomPoses, tier: int) -> set[tuple[PoseKey, PoseKey, PoseKey]]:
    """Plain reference: every valid (anchor, positive, negative) of one room and tier."""
    poses = [
        PoseKey(layout, i, j, h)
        for layout, cells in room.reachable.items()
        for (i, j) in cells
        for h in range(4)
    ]
    by_cell: dict[tuple[int, int], list[PoseKey]] = {}
    for p in poses:
        by_cell.setdefault((p.i, p.j), []).append(p)
    pos_rule, neg_rule = TABLE_I[tier]

    def ok(anchor: PoseKey, other: PoseKey, rule: int | None, positive: bool) -> bool:
        a, b, g = offset(anchor, other)
        if rule is None and positive:
            return (a, b, g) == (0, 0, 0) and other.layout != anchor.layout
        if rule is None:
            return (a, b) == (0, 0) and g != 0
        return abs(a) + abs(b) == rule and g == 0

    out = set()
    for anchor in poses:
        near = [
            p
            for (i, j), ps in by_cell.items()
            if abs(i - anchor.i) + abs(j - anchor.j) <= 4
            for p in ps
        ]
        positives = [p for p in near if ok(anchor, p, pos_rule, True)]
        negatives = [p for p in near if ok(anchor, p, neg_rule, False)]
        out.update(itertools.product([anchor], positives, negatives))
    return out


# ------------------------------------------------------------------ tier counts


def test_tiers_are_table_one() -> None:
    assert DEFAULT_SHARES == (0.50, 0.20, 0.15, 0.10, 0.05)
    assert [t.index for t in TIERS] == [0, 1, 2, 3, 4]
    for t in TIERS:
        pos, neg = TABLE_I[t.index]
        assert t.positive.distance == (pos or 0) and t.positive.other_layout == (pos is None)
        assert t.negative.distance == (neg or 0) and t.negative.turn == (neg is None)


def test_tier_counts_default() -> None:
    assert tier_counts(100) == [50, 20, 15, 10, 5]
    assert tier_counts(10_000) == [5000, 2000, 1500, 1000, 500]
    assert tier_counts(0) == [0, 0, 0, 0, 0]


shares_strategy = st.lists(
    st.floats(min_value=0.0, max_value=1.0, allow_nan=False), min_size=5, max_size=5
).filter(lambda xs: sum(xs) > 0.01)


@given(total=st.integers(100, 1_000_000), raw=st.one_of(st.just(DEFAULT_SHARES), shares_strategy))
def test_tier_counts_within_one_point(total: int, raw: tuple[float, ...]) -> None:
    shares = [x / sum(raw) for x in raw]
    counts = tier_counts(total, shares)
    assert sum(counts) == total
    for count, share in zip(counts, shares, strict=True):
        assert abs(count / total - share) <= 0.01
        assert abs(count - total * share) < 1 + 1e-6


@given(total=st.integers(0, 99), raw=st.one_of(st.just(DEFAULT_SHARES), shares_strategy))
def test_tier_counts_small_totals(total: int, raw: tuple[float, ...]) -> None:
    """Below 100 only the one-triplet bound holds, and the counts still sum exactly."""
    shares = [x / sum(raw) for x in raw]
    counts = tier_counts(total, shares)
    assert sum(counts) == total
    for count, share in zip(counts, shares, strict=True):
        assert abs(count - total * share) < 1 + 1e-6
        if share == 0:
            assert count == 0


@pytest.mark.parametrize(
    "total, shares",
    [
        (-1, DEFAULT_SHARES),
        (10, (0.5, 0.5)),
        (10, (0.5, 0.2, 0.2, 0.2, 0.2)),
        (10, (1, 0, 0, 0, -0.1)),
    ],
)
def test_tier_counts_rejects_bad_input(total: int, shares: tuple[float, ...]) -> None:
    with pytest.raises(ConfigError):
        tier_counts(total, shares)


# ------------------------------------------------------------------ sampling


room_shapes = st.tuples(
    st.integers(9, 16),  # rows: >= 9 so that every tier has anchors
    st.integers(9, 16),  # cols
    st.integers(2, 5),  # layouts
    st.floats(0.0, 0.3),  # blocked fraction per layout
    st.integers(0, 2**32 - 1),  # layout seed
)


@settings(deadline=None, max_examples=30)
@given(
    shapes=st.lists(room_shapes, min_size=1, max_size=4),
    total=st.integers(100, 3000),
    seed=st.integers(0, 2**63 - 1),
)
def test_sampled_split_is_valid(shapes: list[tuple], total: int, seed: int) -> None:
    rooms = [
        make_room(f"room_{n}", rows=r, cols=c, layouts=k, hole=h, seed=s, origin=(100 * n, 0))
        for n, (r, c, k, h, s) in enumerate(shapes)
    ]
    triplets = sample_triplets(rooms, total, seed)
    assert len(triplets) == total
    by_id = {r.room_id: r for r in rooms}
    for t in triplets:
        assert t.split == "train"
        check_triplet(t, by_id)
    counts = np.bincount([t.tier for t in triplets], minlength=5)
    assert counts.tolist() == tier_counts(total)
    assert np.all(np.abs(counts / total - np.array(DEFAULT_SHARES)) <= 0.01)
    assert len(set(triplets)) == total  # rooms this size have far more than enough


def test_tier_zero_changes_only_the_layout() -> None:
    rooms = [make_room("a", seed=1), make_room("b", seed=2)]
    tier0 = [t for t in sample_triplets(rooms, 1000, 7) if t.tier == 0]
    assert len(tier0) == 500
    for t in tier0:
        p, a = t.positive, t.anchor
        assert (p.i, p.j, p.heading) == (a.i, a.j, a.heading)
        assert p.layout != a.layout


def test_layouts_are_not_a_shortcut() -> None:
    """Negatives share the anchor's layout about as often as tier 1-4 positives do."""
    rooms = [make_room("a", layouts=5, hole=0.0, seed=3)]
    triplets = [t for t in sample_triplets(rooms, 20_000, 1) if t.tier > 0]
    pos_same = np.mean([t.positive.layout == t.anchor.layout for t in triplets])
    neg_same = np.mean([t.negative.layout == t.anchor.layout for t in triplets])
    assert abs(pos_same - 0.2) < 0.03 and abs(neg_same - 0.2) < 0.03


def test_never_across_rooms_or_splits() -> None:
    # Far-apart coordinates: a cell borrowed from another room would not be reachable.
    rooms = [make_room(f"r{n}", seed=n, origin=(50 * n, -50 * n)) for n in range(3)]
    triplets = sample_triplets(rooms, 2000, 0)
    assert {t.room_id for t in triplets} == {"r0", "r1", "r2"}
    by_id = {r.room_id: r for r in rooms}
    for t in triplets:
        check_triplet(t, by_id)
    val = [make_room("v0", split="val", seed=9)]
    assert {t.split for t in sample_triplets(val, 200, 0)} == {"val"}


def test_rooms_share_in_proportion_to_anchors() -> None:
    big = make_room("big", rows=16, cols=16, hole=0.0)
    small = make_room("small", rows=9, cols=9, hole=0.0)
    triplets = sample_triplets([big, small], 10_000, 0)
    tier0 = [t.room_id for t in triplets if t.tier == 0]
    # Tier 0: every pose of a fully free room is an anchor, so 256 : 81 cells.
    assert tier0.count("big") == round(5000 * 256 / (256 + 81))


def test_deterministic() -> None:
    rooms = [make_room("a", seed=1), make_room("b", seed=2, rows=10)]
    first = sample_triplets(rooms, 1500, 42)
    assert first == sample_triplets(rooms, 1500, 42)
    assert first == sample_triplets(list(reversed(rooms)), 1500, 42)  # order of rooms is moot
    assert first != sample_triplets(rooms, 1500, 43)
    # Same cells given in another set/dict insertion order: same draws.
    shuffled = [
        RoomPoses(
            r.room_id, r.split, {k: frozenset(sorted(v)) for k, v in reversed(r.reachable.items())}
        )
        for r in rooms
    ]
    assert first == sample_triplets(shuffled, 1500, 42)


@pytest.mark.parametrize(
    "rows, cols, layouts, seed, origin",
    [(3, 5, 3, 5, (0, 0)), (5, 5, 2, 8, (-7, 3)), (2, 7, 3, 1, (4, -20))],
)
def test_matches_reference_enumeration(
    rows: int, cols: int, layouts: int, seed: int, origin: tuple[int, int]
) -> None:
    """On a tiny room every sample is a valid triplet, and capacity is exactly the reference's."""
    room = make_room(
        "tiny", rows=rows, cols=cols, layouts=layouts, hole=0.25, seed=seed, origin=origin
    )
    for tier in range(5):
        reference = all_triplets(room, tier)
        assert reference, tier
        shares = [0.0] * 5
        shares[tier] = 1.0
        triplets = sample_triplets([room], len(reference), 0, shares=shares)
        keys = {(t.anchor, t.positive, t.negative) for t in triplets}
        assert keys <= reference
        for t in triplets:
            check_triplet(t, {"tiny": room})
        # Asking for every distinct triplet ends (bounded redraws) and repeats few.
        assert len(keys) >= 0.9 * len(reference)
        with pytest.raises(ConfigError, match=f"tier {tier}"):
            sample_triplets([room], len(reference) + 1, 0, shares=shares)


def test_room_without_far_cells_hands_its_share_on() -> None:
    narrow = make_room("narrow", rows=2, cols=3, hole=0.0)  # no two cells 4 apart
    wide = make_room("wide", seed=4)
    triplets = sample_triplets([narrow, wide], 2000, 0)
    assert tier_counts(2000) == np.bincount([t.tier for t in triplets]).tolist()
    assert {t.room_id for t in triplets if t.tier >= 3} == {"wide"}
    assert "narrow" in {t.room_id for t in triplets}


def test_split_that_cannot_supply_tier_four_raises() -> None:
    rooms = [make_room(f"n{k}", split="test", rows=2, cols=3, hole=0.0) for k in range(3)]
    shares = (0.55, 0.25, 0.15, 0.0, 0.05)  # tier 3 off, so tier 4 is what falls short
    with pytest.raises(ConfigError) as info:
        sample_triplets(rooms, 240, 0, shares=shares)
    message = str(info.value)
    assert "\n" not in message
    assert "split test" in message and "tier 4" in message and "positive 4 cells away" in message
    assert "needs 12 triplets" in message and "offer only 0" in message
    assert "lower triplets.count or add rooms" in message


def test_mixed_splits_raise() -> None:
    rooms = [make_room("a", split="train"), make_room("b", split="val")]
    with pytest.raises(ConfigError, match="split"):
        sample_triplets(rooms, 100, 0)


def test_bad_input_raises() -> None:
    with pytest.raises(ConfigError):
        sample_triplets([], 10, 0)
    with pytest.raises(ConfigError, match="more than once"):
        sample_triplets([make_room("a"), make_room("a", seed=1)], 100, 0)
    with pytest.raises(ConfigError):
        RoomPoses("x", "train", {})
    with pytest.raises(ConfigError):
        RoomPoses("x", "train", {0: frozenset({(1, 2, 3)})})
    assert sample_triplets([make_room("a")], 0, 0) == []


def test_performance_sanity() -> None:
    """10k triplets over 4 rooms of 5 layouts x ~150 cells completes (timing is for benches)."""
    rooms = [make_room(f"room_{n}", rows=12, cols=14, hole=0.1, seed=n) for n in range(4)]
    triplets = sample_triplets(rooms, 10_000, 0)
    assert len(triplets) == 10_000
    assert len(set(triplets)) == 10_000


# ------------------------------------------------------------------ small pieces


def test_heading_step() -> None:
    assert [heading_step(0, h) for h in range(4)] == [0, 1, 2, -1]
    assert heading_step(3, 0) == 1 and heading_step(1, 0) == -1 and heading_step(1, 3) == 2


def test_referenced_poses() -> None:
    rooms = [make_room("a", seed=1), make_room("b", seed=2)]
    triplets = sample_triplets(rooms, 500, 0)
    by_room = referenced_poses_by_room(triplets)
    assert list(by_room) == ["a", "b"]
    for room_id, poses in by_room.items():
        expected = {
            k for t in triplets if t.room_id == room_id for k in (t.anchor, t.positive, t.negative)
        }
        assert poses == sorted(expected)
        assert referenced_poses(triplets, room_id=room_id) == poses
        assert referenced_poses([t for t in triplets if t.room_id == room_id]) == poses
    with pytest.raises(ConfigError, match="room_id"):
        referenced_poses(triplets)
    assert referenced_poses([]) == []
