"""Scene-graph relations among visible objects: on / in / proximity / disjoint (DESIGN §5).

For each unordered pair {a, b} of visible objects, with a the lower instance id, the first
rule that matches decides (paper §V-A.1, the authors' code):

1. ``support(a) == b`` -> ON a->b; else ``support(b) == a`` -> ON b->a.
2. a's box inside b's box and a the smaller -> IN a->b; else b inside a, b the smaller ->
   IN b->a. "Inside": all 8 corners of the inner box lie in the outer box grown by
   ``RelationRules.containment_tolerance`` on every side. "Smaller": smaller box volume;
   equal volumes (two identical boxes) make the lower instance id the inner one.
3. ``|c_a - c_b| <= r_a + r_b`` (box centres, r = half the box diagonal) -> PROXIMITY, both
   directions.
4. otherwise DISJOINT, both directions (kept in the data, not fed to the GCN).

So a pair yields exactly one edge (ON, IN) or two (PROXIMITY, DISJOINT). Edges are returned
sorted by (src, dst) instance id. Everything is n x n numpy arrays: no Python loop over pairs.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from enum import IntEnum

import numpy as np

from sgdata.errors import ConfigError

__all__ = ["RelationType", "RelationRules", "Relations", "compute_relations", "stored_precision"]


class RelationType(IntEnum):
    """Edge type codes as stored in the dataset."""

    ON = 0
    IN = 1
    PROXIMITY = 2
    DISJOINT = 3


@dataclass(frozen=True)
class RelationRules:
    """How relations are computed; recorded in the dataset manifest."""

    box: str = "world_aabb"  # world axis-aligned box of the object's transformed mesh
    # Metres an inner box may stick out and still be "in". 1 mm: a drawer flush with its
    # cabinet front, a shelf flush with its unit share a face, and float noise on that face
    # must not turn containment into proximity (it did for a third of all `in` edges).
    containment_tolerance: float = 0.001

    def __post_init__(self) -> None:
        if self.box != "world_aabb":
            raise ConfigError(f"relation box {self.box!r}: only 'world_aabb' is supported")
        if not self.containment_tolerance >= 0.0:
            raise ConfigError(
                f"containment_tolerance={self.containment_tolerance}: expected >= 0 metres"
            )

    def to_dict(self) -> dict[str, object]:
        """Plain dict for the manifest."""
        return {"heuristic": "first-match on>in>proximity>disjoint", **asdict(self)}


@dataclass(frozen=True)
class Relations:
    """Directed edges between instance ids, sorted by (src, dst)."""

    src: np.ndarray  # (E,) int64 instance ids
    dst: np.ndarray  # (E,) int64
    type: np.ndarray  # (E,) int8 RelationType codes

    def __len__(self) -> int:
        return len(self.src)


def stored_precision(boxes: np.ndarray) -> np.ndarray:
    """Box coordinates rounded to the float32 the dataset stores them in (as float64)."""
    return np.asarray(boxes, dtype=np.float32).astype(np.float64)


def compute_relations(
    instance: np.ndarray,
    box_min: np.ndarray,
    box_max: np.ndarray,
    support: np.ndarray,
    *,
    rules: RelationRules | None = None,
) -> Relations:
    """All pairwise relations among n objects.

    Args:
        instance: (n,) distinct instance ids.
        box_min, box_max: (n, 3) corners of each object's world axis-aligned box.
        support: (n,) instance id each object rests on, -1 (or any id not among
            ``instance``) for none.
        rules: containment tolerance and box kind (defaults to :class:`RelationRules`).

    Returns:
        Relations with n*(n-1) - (#ON + #IN) edges, sorted by (src, dst).
    """
    rules = rules or RelationRules()
    inst = np.asarray(instance, dtype=np.int64)
    order = np.argsort(inst, kind="stable")
    inst = inst[order]
    lo = np.asarray(box_min, dtype=np.float64)[order]
    hi = np.asarray(box_max, dtype=np.float64)[order]
    sup = np.asarray(support, dtype=np.int64)[order]
    n = len(inst)
    if n < 2:
        empty = np.zeros(0, dtype=np.int64)
        return Relations(empty, empty.copy(), np.zeros(0, dtype=np.int8))

    ar = np.arange(n)
    upper = ar[:, None] < ar[None, :]  # i < j: i is the pair's lower id
    s = sup[:, None] == inst[None, :]  # s[i, j]: i rests on j
    np.fill_diagonal(s, False)  # an object resting on itself is no relation
    on = s & (upper | ~s.T)  # the lower id's own support wins a (cyclic) tie
    pair_taken = on | on.T

    tol = rules.containment_tolerance
    # per-axis 2D comparisons: numpy reduces a trailing axis of length 3 slowly
    inside = smaller = None
    for k in range(3):
        ok = (lo[:, k, None] >= lo[None, :, k] - tol) & (hi[:, k, None] <= hi[None, :, k] + tol)
        inside = ok if inside is None else inside & ok
    size = hi - lo
    vol = size[:, 0] * size[:, 1] * size[:, 2]
    smaller = (vol[:, None] < vol[None, :]) | ((vol[:, None] == vol[None, :]) & upper)
    in_ = inside & smaller & ~pair_taken
    pair_taken |= in_ | in_.T

    centre = (lo + hi) / 2
    radius = 0.5 * np.sqrt(size[:, 0] ** 2 + size[:, 1] ** 2 + size[:, 2] ** 2)
    d2 = None
    for k in range(3):
        dk = centre[:, k, None] - centre[None, :, k]
        d2 = dk * dk if d2 is None else d2 + dk * dk
    reach = radius[:, None] + radius[None, :]
    near = d2 <= reach * reach  # |c_i - c_j| <= r_i + r_j, squared (both sides >= 0)
    rest = ~pair_taken
    np.fill_diagonal(rest, False)

    kind = np.where(near, np.int8(RelationType.PROXIMITY), np.int8(RelationType.DISJOINT))
    kind[in_] = RelationType.IN
    kind[on] = RelationType.ON
    kind[~(rest | in_ | on)] = -1  # the reverse direction of on/in pairs, and the diagonal
    flat_kind = kind.ravel()
    flat = np.flatnonzero(flat_kind >= 0)  # row-major: sorted by (src, dst)
    src, dst = np.divmod(flat, n)
    return Relations(src=inst[src], dst=inst[dst], type=flat_kind[flat])
