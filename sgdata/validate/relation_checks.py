"""Relations recomputed from the stored 3D boxes and supports with
:func:`sgdata.annotate.relations.compute_relations` (the manifest's rules) must equal the stored
ones, every pair, with no allowance: the generator decides on exactly the stored float32 boxes.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from sgdata.annotate.relations import RelationRules, compute_relations
from sgdata.dataset.paths import MANIFEST
from sgdata.errors import ConfigError
from sgdata.validate.loading import Flat, SplitTables, column_numpy
from sgdata.validate.problems import Collector

__all__ = ["check_recompute"]


def _rules(raw: dict[str, Any]) -> RelationRules:
    r = raw.get("relation_rules", {})
    try:
        return RelationRules(
            box=str(r.get("box", "world_aabb")),
            containment_tolerance=float(r.get("containment_tolerance", 0.0)),
        )
    except (AttributeError, TypeError, ValueError):  # the manifest's schema leaves it open
        raise ConfigError(
            f"relation_rules is {r!r}; expected a table with box and containment_tolerance"
        ) from None


def check_recompute(
    tables: SplitTables, raw: dict[str, Any], obj: Flat, rel: Flat, out: Collector
) -> None:
    """Compare stored relations with recomputed ones, synthetic rows with 3D boxes only."""
    obs = tables.observations
    if obs is None:
        return
    try:
        rules = _rules(raw)
    except ConfigError as exc:
        out.add("relations.recompute", MANIFEST, str(exc), field="relation_rules")
        return
    names = raw["relation_types"]
    name_of = lambda t: names[t] if 0 <= t < len(names) else str(t)  # noqa: E731
    synthetic = column_numpy(obs, "domain") == "synthetic"
    lo, lo_ok = obj.fixed("box3d_min", 3, np.float64)
    hi, hi_ok = obj.fixed("box3d_max", 3, np.float64)
    instance = obj.get("instance").astype(np.int64)
    support = obj.get("support", -1).astype(np.int64)
    src, dst = rel.get("src").astype(np.int64), rel.get("dst").astype(np.int64)
    kind = rel.get("type").astype(np.int64)
    n_rows = obs.num_rows
    o_start = np.searchsorted(obj.parent, np.arange(n_rows + 1))
    r_start = np.searchsorted(rel.parent, np.arange(n_rows + 1))
    for row in np.flatnonzero(synthetic):
        a, b = o_start[row], o_start[row + 1]
        if not (lo_ok[a:b].all() and hi_ok[a:b].all()):
            continue  # reported by objects.box3d
        out.count("relations.recompute")
        inst = instance[a:b]
        got = compute_relations(inst, lo[a:b], hi[a:b], support[a:b], rules=rules)
        c, d = r_start[row], r_start[row + 1]
        stored = set(zip(src[c:d].tolist(), dst[c:d].tolist(), kind[c:d].tolist(), strict=True))
        recomputed = set(zip(got.src.tolist(), got.dst.tolist(), got.type.tolist(), strict=True))
        if stored == recomputed:
            continue

        def pair_of(edge: tuple[int, int, int]) -> tuple[int, int]:
            return (min(edge[0], edge[1]), max(edge[0], edge[1]))

        diff: dict[tuple[int, int], tuple[list[str], list[str]]] = {}
        for edges, side in ((stored - recomputed, 0), (recomputed - stored, 1)):
            for edge in edges:
                diff.setdefault(pair_of(edge), ([], []))[side].append(
                    f"{name_of(edge[2])} {edge[0]}->{edge[1]}"
                )
        f, file_row = tables.where(row)
        for (x, y), (was, now) in sorted(diff.items()):
            out.add(
                "relations.recompute",
                tables.files[f],
                f"pair ({x}, {y}): stored {', '.join(sorted(was)) or 'nothing'}; recomputed "
                f"from the 3D boxes and supports: {', '.join(sorted(now)) or 'nothing'}",
                row=file_row,
                field="relations",
            )
