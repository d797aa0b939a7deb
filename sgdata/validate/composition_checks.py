"""Composition checks on the triplet tables: references into the split, no triplet across
rooms or splits, tier shares (DESIGN §6), offsets recomputed from the grid poses against the
tier rules and the stored offsets; rooms never shared by two splits' observations."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc

from sgdata.dataset.paths import MANIFEST
from sgdata.validate.loading import SplitTables, column_numpy, fixed_numpy
from sgdata.validate.problems import Collector
from sgdata.world.triplets import HEADINGS, TIERS, tier_counts

__all__ = ["check_triplets", "check_rooms_across_splits", "check_counts", "ROLES"]

ROLES = ("anchor", "positive", "negative")
_POINT = 0.01  # shares must hold within ±1 percentage point (DESIGN §6)


def _shares(raw: dict[str, Any]) -> list[float]:
    shares = raw.get("config", {}).get("triplets", {}).get("shares")
    return list(shares) if shares else [t.share for t in TIERS]


@dataclass(frozen=True)
class _Triplets:
    """One split's triplet table and where its problems go."""

    tables: SplitTables
    out: Collector
    table: pa.Table

    @property
    def n(self) -> int:
        return self.table.num_rows

    def report(self, check: str, bad: np.ndarray, field: str, message: Any) -> None:
        """One problem per True of ``bad`` (a triplet row); ``message`` a string or callable."""
        for r in np.flatnonzero(bad):
            text = message(r) if callable(message) else message
            self.out.add(check, self.tables.triplets_file, text, row=int(r), field=field)


def check_triplets(tables: SplitTables, raw: dict[str, Any], out: Collector) -> None:
    """Every triplet rule for one split."""
    if tables.triplets is None:
        return
    tri = _Triplets(tables, out, tables.triplets)
    room = _check_ids_and_rooms(tri, raw)
    index, found = _check_references(tri)
    if tables.observations is not None:
        _check_one_room(tri, index, room)
    tier = _check_tiers(tri, raw)
    if tables.observations is not None:
        _check_offsets(tri, index, found, tier)


def _check_ids_and_rooms(tri: _Triplets, raw: dict[str, Any]) -> np.ndarray:
    """Ids are row indices, the split is this one, rooms are the split's; returns the rooms."""
    table, split, n = tri.table, tri.tables.split, tri.n
    tri.out.count("triplets.ids", n)
    ids = column_numpy(table, "triplet_id")
    tri.report(
        "triplets.ids",
        ids != np.arange(n),
        "triplet_id",
        lambda r: f"{ids[r]}; expected the row index {r}",
    )
    tsplit = column_numpy(table, "split")
    tri.report(
        "triplets.rooms",
        tsplit != split,
        "split",
        lambda r: f"{tsplit[r]!r} in the {split} table; triplets never cross splits",
    )
    room = column_numpy(table, "room_id")
    rooms = set(raw["splits"].get(split, []))
    tri.out.count("triplets.rooms", n)
    tri.report(
        "triplets.rooms",
        ~np.isin(room, list(rooms)),
        "room_id",
        lambda r: f"{room[r]!r} is not a room of split {split}",
    )
    return room


def _check_references(tri: _Triplets) -> tuple[dict[str, np.ndarray], np.ndarray]:
    """Every anchor / positive / negative is a row of this split; returns each role's row
    index (-1: not found) and which triplets have all three."""
    obs, split = tri.tables.observations, tri.tables.split
    obs_ids = obs.column("obs_id") if obs is not None else pa.array([], pa.string())
    index = {}
    tri.out.count("triplets.references", 3 * tri.n)
    for role in ROLES:
        idx = pc.index_in(tri.table.column(role), value_set=obs_ids)
        index[role] = column_numpy(pa.table({"i": idx}), "i", -1).astype(np.int64)
        values = column_numpy(tri.table, role)
        tri.report(
            "triplets.references",
            index[role] < 0,
            role,
            lambda r, v=values: f"{v[r]!r} is not an observation of split {split}",
        )
    return index, np.all([index[r] >= 0 for r in ROLES], axis=0)


def _check_one_room(tri: _Triplets, index: dict[str, np.ndarray], room: np.ndarray) -> None:
    """No triplet across rooms: its three views are of its room."""
    obs_room = column_numpy(tri.tables.observations, "room_id")
    for role in ROLES:
        ok = index[role] >= 0
        other = np.where(ok, obs_room[np.maximum(index[role], 0)], None)
        tri.report(
            "triplets.rooms",
            ok & (other != room),
            role,
            lambda r, o=other: f"a view of room {o[r]!r} in a triplet of room {room[r]!r}",
        )


def _check_tiers(tri: _Triplets, raw: dict[str, Any]) -> np.ndarray:
    """Tiers in range, their shares as configured (DESIGN §6) and as the manifest counts
    them; returns the tiers."""
    file, split, n, out = tri.tables.triplets_file, tri.tables.split, tri.n, tri.out
    tier = column_numpy(tri.table, "tier").astype(np.int64)
    out.count("triplets.tiers", n)
    tri.report(
        "triplets.tiers",
        (tier < 0) | (tier >= len(TIERS)),
        "tier",
        lambda r: f"{tier[r]}; expected 0..{len(TIERS) - 1}",
    )
    counts = np.bincount(tier[(tier >= 0) & (tier < len(TIERS))], minlength=len(TIERS))
    shares = _shares(raw)
    if n >= 100:
        bad_tiers = [k for k in range(len(TIERS)) if abs(counts[k] / n - shares[k]) > _POINT]
        rule = "within ±1 point of"
    else:
        exact = tier_counts(n, shares)
        bad_tiers = [k for k in range(len(TIERS)) if counts[k] != exact[k]]
        rule = f"exactly tier_counts({n}) = {exact} for"
    if bad_tiers:
        have = ", ".join(f"{100 * c / max(n, 1):.1f}%" for c in counts)
        want = ", ".join(f"{100 * s:.0f}%" for s in shares)
        out.add(
            "triplets.tiers",
            file,
            f"tiers {counts.tolist()} ({have}) of {n} triplets; expected {rule} the shares "
            f"({want}); off in tier(s) {bad_tiers}",
            field="tier",
        )
    listed = raw.get("counts", {}).get("tiers", {}).get(split)
    if listed is not None and list(listed) != counts.tolist():
        out.add(
            "triplets.tiers",
            MANIFEST,
            f"counts.tiers.{split} = {list(listed)} but {file} holds {counts.tolist()}",
            field=f"counts/tiers/{split}",
        )
    return tier


def _check_offsets(
    tri: _Triplets, index: dict[str, np.ndarray], found: np.ndarray, tier: np.ndarray
) -> None:
    """Offsets recomputed from the views' grid poses: the stored ones, and the tier rules."""
    obs = tri.tables.observations
    grid = {}
    posed = found.copy()
    for role in ROLES:
        at = np.maximum(index[role], 0)
        cols = []
        for name in ("layout", "grid_i", "grid_j", "heading"):
            col = obs.column(name)
            valid = ~col.is_null().to_numpy(zero_copy_only=False)[at]
            posed &= valid
            cols.append(column_numpy(obs, name, 0).astype(np.int64)[at])
        grid[role] = np.stack(cols, axis=1)
    tri.out.count("triplets.offsets", int(posed.sum()))
    tri.out.count("triplets.tier_rules", int(posed.sum()))
    a = grid["anchor"]
    for role in ("positive", "negative"):
        g = grid[role]
        step = (g[:, 3] - a[:, 3]) % HEADINGS  # a turn of 3 quarters is one quarter back
        turn = np.where(step == HEADINGS - 1, -1, step)
        offset = np.stack([g[:, 1] - a[:, 1], g[:, 2] - a[:, 2], turn], 1)
        stored, _ = fixed_numpy(tri.table.column(f"{role}_offset").combine_chunks(), 3, np.int64)
        tri.report(
            "triplets.offsets",
            posed & np.any(stored != offset, axis=1),
            f"{role}_offset",
            lambda r, s=stored, o=offset: (
                f"stored {s[r].tolist()}; the views' grid poses give {o[r].tolist()}"
            ),
        )
        same_layout = g[:, 0] == a[:, 0]
        dist = np.abs(offset[:, 0]) + np.abs(offset[:, 1])
        for t in TIERS:
            rule = getattr(t, role)
            sel = posed & (tier == t.index)
            wrong = sel & ((dist != rule.distance) | ((offset[:, 2] != 0) != rule.turn))
            if rule.other_layout:
                wrong |= sel & same_layout
            tri.report(
                "triplets.tier_rules",
                wrong,
                role,
                lambda r, o=offset, rule=rule, t=t, s=same_layout, role=role: (
                    f"offset {o[r].tolist()}"
                    f"{' in the same layout' if s[r] else ''}; tier {t.index} wants the {role} "
                    f"{rule.describe()}"
                ),
            )


def check_rooms_across_splits(splits: list[SplitTables], out: Collector) -> None:
    """The observation rows of a room live in one split only."""
    seen: dict[str, str] = {}
    for tables in splits:
        if tables.observations is None:
            continue
        for room in pc.unique(tables.observations.column("room_id")).to_pylist():
            out.count("splits.disjoint")
            if room in seen:
                out.add(
                    "splits.disjoint",
                    f"observations/{tables.split}",
                    f"room {room} has observations in splits {seen[room]} and {tables.split}",
                    field="room_id",
                )
            else:
                seen[room] = tables.split


def check_counts(splits: list[SplitTables], raw: dict[str, Any], out: Collector) -> None:
    """Every count of the manifest (rooms, observations, triplets, tiers per split) against
    what the files hold."""
    counts = raw.get("counts", {})

    def compare(name: str, field: str, stated: Any, actual: Any) -> None:
        out.count("counts." + name)
        if stated != actual:
            out.add(
                "counts." + name,
                MANIFEST,
                f"counts say {stated}, the files hold {actual}",
                field=f"counts/{field}",
            )

    rooms = sum(len(r) for r in raw.get("splits", {}).values())
    compare("rooms", "rooms", counts.get("rooms"), rooms)
    for tables in splits:
        split = tables.split
        if tables.observations is not None:
            stated = counts.get("observations", {}).get(split)
            compare("observations", f"observations/{split}", stated, tables.observations.num_rows)
        if tables.triplets is not None:
            stated = counts.get("triplets", {}).get(split)
            compare("triplets", f"triplets/{split}", stated, tables.triplets.num_rows)
            tier = column_numpy(tables.triplets, "tier").astype(np.int64)
            valid = tier[(tier >= 0) & (tier < len(TIERS))]
            actual = np.bincount(valid, minlength=len(TIERS)).tolist()
            compare("tiers", f"tiers/{split}", counts.get("tiers", {}).get(split), actual)
