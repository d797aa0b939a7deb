"""Cascaded triplet sampling (paper Table I, DESIGN §6): which poses form each training triplet.

Pure numpy, no rendering: the input is, per room, the grid cells a robot can stand on in each
layout; the output is a list of :class:`Triplet` of pose keys ``(layout, i, j, heading)``,
and :func:`referenced_poses` gives the views a room must render for them.

Offsets ``(α, β, γ)`` are taken from the anchor pose ``[i, j, h]``: α along i, β along j, γ
in heading steps of 90°, with ``γ = (h' - h) mod 4`` written as one of ``{-1, 0, 1, 2}``.

=====  ======  =====================================  =====================================
tier   share   positive                               negative
=====  ======  =====================================  =====================================
0      50 %    same pose, a *different* layout        ``|α|+|β| = 1``, ``γ = 0``
1      20 %    ``|α|+|β| = 1``, ``γ = 0``             ``|α|+|β| = 2``, ``γ = 0``
2      15 %    ``|α|+|β| = 2``, ``γ = 0``             ``|α|+|β| = 3``, ``γ = 0``
3      10 %    ``|α|+|β| = 3``, ``γ = 0``             ``|α|+|β| = 4``, ``γ = 0``
4       5 %    ``|α|+|β| = 4``, ``γ = 0``             same cell, ``γ ≠ 0``
=====  ======  =====================================  =====================================

How a triplet is drawn, for one room and tier:

1. **Anchor.** Its layout is drawn uniformly among the room's layouts that hold at least one
   valid anchor for the tier; its cell uniformly among that layout's valid anchor cells (a cell
   reachable in that layout with at least one valid positive and one valid negative); its
   heading uniformly among the four.
2. **Positive / negative cell.** Uniform among the cells at the tier's distance that are
   reachable in *some* layout of the room (the offset is drawn first, then the layout); for the
   tier-4 negative, γ is uniform over ``{1, 2, -1}``.
3. **Their layouts.** The tier-0 positive takes a layout other than the anchor's where the
   anchor's cell is reachable. Every other positive and every negative takes a layout drawn
   uniformly among the layouts where its cell is reachable, the anchor's own layout included
   when the cell is reachable there. So a negative is as likely as a positive to share the
   anchor's layout, and "same layout as the anchor" is never a shortcut the network could
   learn in place of geometry; and every referenced cell is reachable in its layout.

Counts are exact: :func:`tier_counts` fixes each tier's number of triplets for the split by
largest remainder, then each tier's count is split over the rooms in proportion to their
numbers of valid anchor poses (largest remainder again), capped at the number of distinct
triplets a room can make; what a room cannot supply goes to the others. Triplets never cross
rooms or splits. Exact duplicates within a split are avoided by redrawing, a bounded number of
rounds; they can only remain when a room's tier is asked for nearly all of its distinct
triplets.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np

from sgdata.errors import ConfigError
from sgdata.seeds import triplet_stream_seed
from sgdata.world.poses import HEADINGS_DEG

__all__ = [
    "OffsetRule",
    "Tier",
    "TIERS",
    "DEFAULT_SHARES",
    "check_shares",
    "PoseKey",
    "Triplet",
    "RoomPoses",
    "heading_step",
    "tier_counts",
    "sample_triplets",
    "referenced_poses",
    "referenced_poses_by_room",
]

HEADINGS = len(HEADINGS_DEG)  # 0/90/180/270 degrees (sgdata.world.poses, their home)
MAX_DISTANCE = 4  # the largest |α|+|β| any tier uses; also the grid padding below
_DEDUP_ROUNDS = 16  # redraw rounds against duplicates before accepting them (never loop forever)
_SHARE_TOLERANCE = 1e-6  # shares must sum to 1 within this


@dataclass(frozen=True)
class OffsetRule:
    """Where a positive or negative lies relative to the anchor."""

    distance: int  # |α| + |β| in grid cells
    turn: bool = False  # γ != 0 (another heading); otherwise γ == 0
    other_layout: bool = False  # must be in a layout other than the anchor's

    def describe(self) -> str:
        """Short human text, used in error messages."""
        if self.turn:
            return "same cell, another heading"
        if self.distance == 0:
            return "same pose in another layout" if self.other_layout else "same pose"
        cells = "cell" if self.distance == 1 else "cells"
        return f"{self.distance} {cells} away"

    def matches(self, offset: tuple[int, int, int], *, same_layout: bool) -> bool:
        """Whether an ``(α, β, γ)`` offset (and same-layout flag) satisfies this rule."""
        alpha, beta, gamma = offset
        if abs(alpha) + abs(beta) != self.distance or (gamma != 0) != self.turn:
            return False
        return not (self.other_layout and same_layout)


@dataclass(frozen=True)
class Tier:
    """One row of Table I."""

    index: int
    share: float  # default fraction of a split's triplets
    positive: OffsetRule
    negative: OffsetRule


TIERS: tuple[Tier, ...] = (
    Tier(0, 0.50, OffsetRule(0, other_layout=True), OffsetRule(1)),
    Tier(1, 0.20, OffsetRule(1), OffsetRule(2)),
    Tier(2, 0.15, OffsetRule(2), OffsetRule(3)),
    Tier(3, 0.10, OffsetRule(3), OffsetRule(4)),
    Tier(4, 0.05, OffsetRule(4), OffsetRule(0, turn=True)),
)
DEFAULT_SHARES: tuple[float, ...] = tuple(t.share for t in TIERS)  # (0.50, 0.20, 0.15, 0.10, 0.05)


def heading_step(h_from: int, h_to: int) -> int:
    """γ from heading index ``h_from`` to ``h_to``: ``(h_to - h_from) mod 4`` as -1, 0, 1 or 2."""
    step = (h_to - h_from) % HEADINGS
    return step - HEADINGS if step == 3 else step


@dataclass(frozen=True, order=True, slots=True)
class PoseKey:
    """One view of a room: layout index, grid cell (i, j) and heading index 0..3."""

    layout: int
    i: int
    j: int
    heading: int


@dataclass(frozen=True, slots=True)
class Triplet:
    """(anchor, positive, negative) poses of one room and split, drawn for ``tier``."""

    room_id: str
    split: str
    tier: int  # index into TIERS
    anchor: PoseKey
    positive: PoseKey
    negative: PoseKey

    @property
    def positive_offset(self) -> tuple[int, int, int]:
        """``(α, β, γ)`` of the positive from the anchor."""
        return _offset(self.anchor, self.positive)

    @property
    def negative_offset(self) -> tuple[int, int, int]:
        """``(α, β, γ)`` of the negative from the anchor."""
        return _offset(self.anchor, self.negative)


def _offset(a: PoseKey, b: PoseKey) -> tuple[int, int, int]:
    return (b.i - a.i, b.j - a.j, heading_step(a.heading, b.heading))


@dataclass(frozen=True)
class RoomPoses:
    """The reachable grid cells of every layout of one room, the input to triplet sampling."""

    room_id: str  # e.g. "kitchen_003"
    split: str  # e.g. "train"
    reachable: dict[int, frozenset[tuple[int, int]]]  # layout index -> reachable (i, j) cells

    def __post_init__(self) -> None:
        if not self.reachable:
            raise ConfigError(f"room {self.room_id}: no layouts given; expected >= 1")
        for layout, cells in self.reachable.items():
            if not isinstance(layout, int | np.integer) or layout < 0:
                raise ConfigError(
                    f"room {self.room_id}: layout key {layout!r}; expected an int >= 0"
                )
            for cell in cells:
                if len(cell) != 2 or not all(isinstance(c, int | np.integer) for c in cell):
                    raise ConfigError(
                        f"room {self.room_id} layout {layout}: cell {cell!r}; "
                        "expected an (i, j) pair of ints"
                    )


# --------------------------------------------------------------------------- counts


def check_shares(shares: Sequence[float]) -> np.ndarray:
    """The shares as an array; refuses a wrong count, negative values or a sum other than 1."""
    values = np.asarray(shares, dtype=np.float64)
    if values.shape != (len(TIERS),):
        raise ConfigError(f"shares {tuple(shares)}: expected {len(TIERS)} values, one per tier")
    if not np.all(np.isfinite(values)) or np.any(values < 0):
        raise ConfigError(f"shares {tuple(shares)}: expected finite values >= 0")
    if abs(values.sum() - 1.0) > _SHARE_TOLERANCE:
        raise ConfigError(
            f"shares {tuple(shares)} sum to {values.sum():.6g}; expected 1 "
            f"(the default is {DEFAULT_SHARES})"
        )
    return values


def _largest_remainder(total: int, weights: np.ndarray) -> np.ndarray:
    """Split ``total`` into integers proportional to ``weights`` (>= 0, not all 0).

    Each part is the floor or the ceiling of its exact quota; the parts sum to ``total``; ties
    of remainders go to the lower index, so the result is deterministic.
    """
    weights = np.asarray(weights, dtype=np.float64)
    quotas = total * weights / weights.sum()
    # The epsilon keeps 100 * 0.15 = 15.000000000000002 or 14.999999999999998 from flipping.
    floors = np.floor(quotas + 1e-9).astype(np.int64)
    floors = np.minimum(floors, total)
    left = total - int(floors.sum())
    if left > 0:
        order = np.lexsort((np.arange(len(weights)), -(quotas - floors)))
        eligible = order[weights[order] > 0]
        floors[eligible[:left]] += 1
    return floors


def tier_counts(total: int, shares: Sequence[float] = DEFAULT_SHARES) -> list[int]:
    """Exact number of triplets per tier for a split of ``total`` triplets.

    Largest-remainder apportionment: each tier gets ``floor(total * share)`` or that plus one,
    and the counts sum to exactly ``total``.

    Guarantee: every tier's count is within one triplet of ``total * share`` (strictly less
    than one away), so its realised share is within ``1 / total`` of its target: within ±1
    percentage point whenever ``total >= 100``. For smaller totals only the one-triplet bound
    holds, which is more than a point (with ``total = 10`` the 5 % tier gets 0 or 1 triplet,
    i.e. 0 % or 10 %); a tier with share 0 always gets 0.

    Args:
        total: number of triplets in the split (>= 0).
        shares: one fraction per tier, >= 0, summing to 1.

    Raises:
        ConfigError: a negative total or malformed shares.
    """
    if not isinstance(total, int | np.integer) or total < 0:
        raise ConfigError(f"triplet total {total!r}: expected an int >= 0")
    values = check_shares(shares)
    if total == 0:
        return [0] * len(TIERS)
    return [int(c) for c in _largest_remainder(int(total), values)]


# --------------------------------------------------------------------------- room grids


def _offsets(distance: int) -> np.ndarray:
    """All (α, β) with |α| + |β| == distance, sorted: shape (n, 2)."""
    if distance == 0:
        return np.zeros((1, 2), dtype=np.int64)
    rng = range(-distance, distance + 1)
    return np.array(
        [(a, b) for a in rng for b in rng if abs(a) + abs(b) == distance], dtype=np.int64
    )


_OFFSETS: tuple[np.ndarray, ...] = tuple(_offsets(k) for k in range(MAX_DISTANCE + 1))


class _RoomGrid:
    """One room on a padded grid: reachability per layout, and per-tier anchor tables.

    Cells are flat indices into a (H, W) grid padded by MAX_DISTANCE on every side, so any
    offset with |α| + |β| <= MAX_DISTANCE from a real cell stays inside without wrapping.
    """

    def __init__(self, room: RoomPoses) -> None:
        self.room = room
        self.layouts = np.array(sorted(int(k) for k in room.reachable), dtype=np.int64)
        cells = [
            np.array(sorted(room.reachable[int(k)]), dtype=np.int64).reshape(-1, 2)
            for k in self.layouts
        ]
        everything = np.concatenate(cells) if any(len(c) for c in cells) else np.zeros((1, 2))
        pad = MAX_DISTANCE
        self.origin = everything.min(axis=0).astype(np.int64) - pad
        shape = everything.max(axis=0).astype(np.int64) - self.origin + pad + 1
        self.height, self.width = int(shape[0]), int(shape[1])
        n_layouts = len(self.layouts)
        grid = np.zeros((n_layouts, self.height, self.width), dtype=bool)
        for index, c in enumerate(cells):
            grid[index, c[:, 0] - self.origin[0], c[:, 1] - self.origin[1]] = True
        self.reach = grid.reshape(n_layouts, -1)  # (L, H*W) reachable per layout
        self.count = self.reach.sum(axis=0)  # (H*W,) number of layouts reaching each cell
        union = self.count > 0  # reachable in some layout
        # Flat index deltas of each distance's offset table.
        self.deltas = tuple(o[:, 0] * self.width + o[:, 1] for o in _OFFSETS)
        inner = np.flatnonzero(self._interior())
        # Per distance k: how many (layout, cell) poses lie k cells away (any heading counted
        # once). Only the interior holds real cells; the padding stays 0.
        self.near_poses = [np.zeros(self.height * self.width, dtype=np.int64) for _ in _OFFSETS]
        for k, delta in enumerate(self.deltas):
            self.near_poses[k][inner] = self.count[inner[:, None] + delta[None, :]].sum(axis=1)
        self.union = union
        self._tiers: dict[int, tuple[np.ndarray, np.ndarray, int]] = {}

    def _interior(self) -> np.ndarray:
        mask = np.zeros((self.height, self.width), dtype=bool)
        p = MAX_DISTANCE
        mask[p : self.height - p, p : self.width - p] = True
        return mask.ravel()

    def cell_ij(self, flat: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Room grid (i, j) of flat cell indices."""
        return flat // self.width + self.origin[0], flat % self.width + self.origin[1]

    def tier_table(self, tier: Tier) -> tuple[np.ndarray, np.ndarray, int]:
        """Valid anchor cells per layout for ``tier`` and the room's distinct-triplet count.

        Returns ``(valid, per_pose, capacity)``: ``valid`` (L, H*W) bool marks anchor cells
        per layout; ``per_pose`` (H*W,) is the number of distinct (positive, negative) pairs
        of an anchor pose at that cell (the same for every heading and layout holding it);
        ``capacity`` is the number of distinct triplets the room can make for the tier.
        """
        if tier.index in self._tiers:
            return self._tiers[tier.index]
        pos, neg = tier.positive, tier.negative
        if pos.other_layout:
            # The anchor's own layout reaches the cell, so count - 1 others do.
            n_pos = np.maximum(self.count - 1, 0)
        else:
            n_pos = self.near_poses[pos.distance]
        if neg.turn:
            n_neg = self.count * (HEADINGS - 1)
        else:
            n_neg = self.near_poses[neg.distance]
        per_pose = n_pos * n_neg
        valid = self.reach & (per_pose > 0)[None, :]
        capacity = int(valid.sum(axis=0) @ per_pose) * HEADINGS
        self._tiers[tier.index] = (valid, per_pose, capacity)
        return self._tiers[tier.index]

    def anchor_poses(self, tier: Tier) -> int:
        """Number of valid anchor poses (layout, cell, heading) for ``tier``."""
        return int(self.tier_table(tier)[0].sum()) * HEADINGS

    def draw(self, tier: Tier, n: int, rng: np.random.Generator) -> np.ndarray:
        """``n`` triplets as an (n, 9) array of (layout index, flat cell, heading) x 3."""
        valid = self.tier_table(tier)[0]
        per_layout = valid.sum(axis=1)
        layouts_ok = np.flatnonzero(per_layout > 0)
        anchor_cells = [np.flatnonzero(row) for row in valid]
        starts = np.concatenate([[0], np.cumsum([len(c) for c in anchor_cells])])
        pool = np.concatenate(anchor_cells)

        a_layout = layouts_ok[rng.integers(0, len(layouts_ok), size=n)]
        pick = _uniform_below(rng, per_layout[a_layout])
        a_cell = pool[starts[a_layout] + pick]
        a_head = rng.integers(0, HEADINGS, size=n)

        p_layout, p_cell, p_head = self._target(tier.positive, a_layout, a_cell, a_head, rng)
        n_layout, n_cell, n_head = self._target(tier.negative, a_layout, a_cell, a_head, rng)
        return np.stack(
            [a_layout, a_cell, a_head, p_layout, p_cell, p_head, n_layout, n_cell, n_head],
            axis=1,
        )

    def _target(
        self,
        rule: OffsetRule,
        a_layout: np.ndarray,
        a_cell: np.ndarray,
        a_head: np.ndarray,
        rng: np.random.Generator,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        n = len(a_cell)
        if rule.distance == 0:
            cell = a_cell
        else:
            # Uniform among the cells at this distance reachable in some layout.
            candidates = a_cell[:, None] + self.deltas[rule.distance][None, :]
            cell = candidates[np.arange(n), _choose_true(rng, self.union[candidates])]
        if rule.turn:
            head = (a_head + rng.integers(1, HEADINGS, size=n)) % HEADINGS
        else:
            head = a_head
        layout_mask = self.reach[:, cell].T.copy()  # (n, L)
        if rule.other_layout:
            layout_mask[np.arange(n), a_layout] = False
        layout = _choose_true(rng, layout_mask)
        return layout, cell, head


def _uniform_below(rng: np.random.Generator, counts: np.ndarray) -> np.ndarray:
    """One uniform integer in [0, count) per entry of ``counts`` (all > 0)."""
    pick = (rng.random(len(counts)) * counts).astype(np.int64)
    return np.minimum(pick, counts - 1)  # guard the (measure-zero) float edge


def _choose_true(rng: np.random.Generator, mask: np.ndarray) -> np.ndarray:
    """Per row of a (n, m) bool ``mask`` with a True in every row, a uniform True column."""
    rank = _uniform_below(rng, mask.sum(axis=1))
    # The chosen column is the one where the running count of Trues first exceeds ``rank``.
    return (np.cumsum(mask, axis=1) <= rank[:, None]).sum(axis=1)


# --------------------------------------------------------------------------- sampling


def _allocate(need: int, weights: np.ndarray, capacity: np.ndarray) -> np.ndarray | None:
    """Split ``need`` over rooms in proportion to ``weights``, none above its ``capacity``.

    What a full room cannot take goes to the others, again in proportion; ``None`` when the
    rooms together cannot hold ``need``.
    """
    given = np.zeros(len(weights), dtype=np.int64)
    if need == 0:
        return given
    if int(capacity.sum()) < need:
        return None
    left = need
    while left > 0:
        open_ = (capacity - given > 0) & (weights > 0)
        share = np.zeros(len(weights), dtype=np.int64)
        share[open_] = _largest_remainder(left, weights[open_])
        share = np.minimum(share, capacity - given)
        given += share
        left = need - int(given.sum())
        # Every round either places everything or fills at least one room: it ends.
    return given


def _draw_unique(grid: _RoomGrid, tier: Tier, n: int, rng: np.random.Generator) -> np.ndarray:
    """``n`` triplets of one room and tier, without exact duplicates where redraws allow.

    Triplets of different tiers can never coincide (their positive distances differ) and
    different rooms never do, so de-duplicating per (room, tier) de-duplicates the split.
    """
    kept: list[np.ndarray] = []
    seen: set[bytes] = set()
    for _ in range(_DEDUP_ROUNDS):
        missing = n - len(kept)
        if missing == 0:
            break
        batch = grid.draw(tier, 2 * missing, rng)  # oversample: fewer rounds near saturation
        for row in batch:
            key = row.tobytes()
            if key not in seen:
                seen.add(key)
                kept.append(row)
                if len(kept) == n:
                    break
    missing = n - len(kept)
    if missing:  # nearly every distinct triplet asked for: accept duplicates, stay bounded
        kept.extend(grid.draw(tier, missing, rng))
    return np.array(kept, dtype=np.int64).reshape(n, 9)


def sample_triplets(
    rooms: list[RoomPoses],
    total: int,
    seed: int,
    *,
    shares: Sequence[float] = DEFAULT_SHARES,
) -> list[Triplet]:
    """Draw ``total`` cascaded triplets for one split from its ``rooms`` (DESIGN §6).

    Tier counts are exactly :func:`tier_counts`; each tier's count is split over the rooms in
    proportion to their valid anchor poses for the tier (see the module docstring for how
    anchors, positives, negatives and their layouts are drawn). Every room's tier draws come
    from their own stream ``sgdata.seeds.triplet_stream_seed(seed, split, room_id, tier)`` (strings
    through a stable hash), so a room's triplets do not depend on the order of ``rooms``,
    Python's hash salt, or set iteration order. The result is ordered by room id, then tier,
    then draw.

    Args:
        rooms: the rooms of the split; all must have the same ``split`` and distinct ids.
        total: number of triplets to draw (>= 0).
        seed: dataset seed.
        shares: fraction per tier, >= 0, summing to 1.

    Returns:
        ``total`` triplets; every referenced cell is reachable in its layout.

    Raises:
        ConfigError: mixed splits, duplicate room ids, bad shares, or a tier the rooms
            together cannot supply.
    """
    counts = tier_counts(total, shares)
    if total == 0:
        return []
    if not rooms:
        raise ConfigError(f"{total} triplets asked of an empty room list; give at least one room")
    splits = sorted({r.split for r in rooms})
    if len(splits) > 1:
        raise ConfigError(
            f"sample_triplets got rooms of splits {splits}; triplets never cross splits, "
            "call it once per split"
        )
    split = splits[0]
    ordered = sorted(rooms, key=lambda r: r.room_id)
    ids = [r.room_id for r in ordered]
    duplicates = sorted({i for i in ids if ids.count(i) > 1})
    if duplicates:
        raise ConfigError(f"split {split}: room ids {duplicates} appear more than once")

    grids = [_RoomGrid(r) for r in ordered]
    plan: list[np.ndarray] = []
    for tier, need in zip(TIERS, counts, strict=True):
        anchors = np.array([g.anchor_poses(tier) for g in grids], dtype=np.int64)
        capacity = np.array([g.tier_table(tier)[2] for g in grids], dtype=np.int64)
        given = _allocate(need, anchors.astype(np.float64), capacity)
        if given is None:
            raise ConfigError(
                f"split {split}: tier {tier.index} (positive {tier.positive.describe()}, "
                f"negative {tier.negative.describe()}) needs {need} triplets but its "
                f"{len(grids)} room(s) offer only {int(capacity.sum())} distinct ones from "
                f"{int(anchors.sum())} anchor poses with such cells; "
                "lower triplets.count or add rooms"
            )
        plan.append(given)

    triplets: list[Triplet] = []
    for r, grid in enumerate(grids):
        room = grid.room
        for tier in TIERS:
            n = int(plan[tier.index][r])
            if n == 0:
                continue
            stream = triplet_stream_seed(seed, split, room.room_id, tier.index)
            rng = np.random.default_rng(stream)
            rows = _draw_unique(grid, tier, n, rng)
            triplets.extend(_to_triplets(grid, split, tier.index, rows))
    return triplets


def _to_triplets(grid: _RoomGrid, split: str, tier: int, rows: np.ndarray) -> list[Triplet]:
    keys = []
    for k in range(3):
        layout = grid.layouts[rows[:, 3 * k]]
        i, j = grid.cell_ij(rows[:, 3 * k + 1])
        keys.append(np.stack([layout, i, j, rows[:, 3 * k + 2]], axis=1).tolist())
    room_id = grid.room.room_id
    return [
        Triplet(room_id, split, tier, PoseKey(*a), PoseKey(*p), PoseKey(*n))
        for a, p, n in zip(*keys, strict=True)
    ]


# --------------------------------------------------------------------------- views to render


def referenced_poses_by_room(triplets: Iterable[Triplet]) -> dict[str, list[PoseKey]]:
    """Per room id (sorted), the unique poses its triplets reference, sorted: views to render."""
    poses: dict[str, set[PoseKey]] = {}
    for t in triplets:
        poses.setdefault(t.room_id, set()).update((t.anchor, t.positive, t.negative))
    return {room_id: sorted(poses[room_id]) for room_id in sorted(poses)}


def referenced_poses(triplets: Iterable[Triplet], *, room_id: str | None = None) -> list[PoseKey]:
    """The unique poses one room's triplets reference, sorted: the views that room must render.

    Args:
        triplets: triplets of any rooms when ``room_id`` is given, else of a single room.
        room_id: keep only this room's triplets.

    Raises:
        ConfigError: ``room_id`` is None and the triplets come from several rooms.
    """
    by_room = referenced_poses_by_room(triplets)
    if room_id is not None:
        return by_room.get(room_id, [])
    if len(by_room) > 1:
        raise ConfigError(
            f"triplets of {len(by_room)} rooms ({', '.join(list(by_room)[:3])}, ...); pass "
            "room_id= or use referenced_poses_by_room"
        )
    return next(iter(by_room.values()), [])
