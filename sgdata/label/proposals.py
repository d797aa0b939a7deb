"""Relation proposals from 2D boxes: on / in / proximity by plain rules, for a person to confirm.

Real photos have no 3D boxes, so DESIGN §5's rules are mirrored in the image plane and only
*proposed*; the labeler accepts, retypes or rejects each one. For every unordered pair of boxes
the first rule that matches wins:

1. ``in``: at least ``inside_share`` of the smaller box's area lies inside the larger box, and
   the larger box is a container (its class is a catalog container: Bowl, SinkBasin, Box ...)
   -> smaller in larger.
2. ``on``: the smaller box's bottom edge lies in the top part of the larger box (within
   ``top_band`` of its height below the top edge, or ``top_slack`` above it) and the smaller
   box's horizontal centre lies over the larger box -> smaller on larger. Seen from above (a
   cup on a saucer, a book on a desk) the resting object's bottom edge lies anywhere on the
   supporting surface but its front rim, hence the deep band.
3. ``proximity``: the centres are no further apart than the sum of the boxes' half diagonals
   times ``proximity_scale`` (the 2D image of §5's bounding-sphere rule) -> symmetric, one
   proposal with ``src < dst``.
"""

from __future__ import annotations

import math
from collections.abc import Collection, Mapping, Sequence
from dataclasses import asdict, dataclass

from sgdata.errors import ConfigError

__all__ = [
    "Box",
    "DEFAULT_RULES",
    "Proposal",
    "ProposalRules",
    "RELATION_NAMES",
    "propose_pair",
    "propose_relations",
]

Box = Sequence[float]  # (u1, v1, u2, v2) in pixels, u2 > u1 and v2 > v1 (v grows downwards)
# The stored relation names, in code order (sgdata.annotate.relations.RelationType).
RELATION_NAMES = ("on", "in", "proximity", "disjoint")


@dataclass(frozen=True)
class ProposalRules:
    """The knobs of the 2D rules; recorded in an export's ``relation_rules``."""

    top_band: float = 0.8  # share of the larger box's height, below its top edge, that is "top"
    top_slack: float = 0.05  # share of the larger box's height above its top edge still "on"
    inside_share: float = 0.9  # share of the smaller box's area inside the larger one for "in"
    proximity_scale: float = 1.0  # x (half diagonal + half diagonal) = farthest "close" centres

    def __post_init__(self) -> None:
        for name, value in asdict(self).items():
            if not (math.isfinite(value) and value >= 0):
                raise ConfigError(f"proposal rule {name}={value}: expected a finite value >= 0")
        if self.inside_share > 1:
            raise ConfigError(f"inside_share={self.inside_share}: expected a share in [0, 1]")

    def to_dict(self) -> dict[str, object]:
        """Plain dict for the manifest."""
        return {
            "heuristic": "2D first-match in (containers only)>on>proximity, confirmed by hand",
            **asdict(self),
        }


DEFAULT_RULES = ProposalRules()


@dataclass(frozen=True)
class Proposal:
    """A proposed directed edge; proximity is symmetric and given once, ``src < dst``."""

    src: int
    dst: int
    type: str  # on | in | proximity

    def to_dict(self) -> dict[str, object]:
        """Plain dict for the page."""
        return {"src": self.src, "dst": self.dst, "type": self.type}


def _area(b: Box) -> float:
    return max(0.0, b[2] - b[0]) * max(0.0, b[3] - b[1])


def _on(small: Box, large: Box, rules: ProposalRules) -> bool:
    height = large[3] - large[1]
    bottom = small[3]
    centre = (small[0] + small[2]) / 2
    in_band = large[1] - rules.top_slack * height <= bottom <= large[1] + rules.top_band * height
    return in_band and large[0] <= centre <= large[2]


def _inside(small: Box, large: Box, rules: ProposalRules) -> bool:
    w = min(small[2], large[2]) - max(small[0], large[0])
    h = min(small[3], large[3]) - max(small[1], large[1])
    overlap = max(0.0, w) * max(0.0, h)
    return overlap >= rules.inside_share * _area(small) > 0


def _close(a: Box, b: Box, rules: ProposalRules) -> bool:
    ca = ((a[0] + a[2]) / 2, (a[1] + a[3]) / 2)
    cb = ((b[0] + b[2]) / 2, (b[1] + b[3]) / 2)
    ra = math.hypot(a[2] - a[0], a[3] - a[1]) / 2
    rb = math.hypot(b[2] - b[0], b[3] - b[1]) / 2
    return math.dist(ca, cb) <= rules.proximity_scale * (ra + rb)


def propose_pair(
    a: int,
    box_a: Box,
    b: int,
    box_b: Box,
    rules: ProposalRules | None = None,
    *,
    containers: Collection[int] = (),
) -> Proposal | None:
    """The proposal for one pair of boxes, or None (first match of in > on > proximity).

    ``containers`` holds the ids of the boxes whose class is a catalog container.
    """
    rules = rules or DEFAULT_RULES
    # The smaller box is the candidate for on / in; equal areas: the lower id is the smaller.
    if (_area(box_a), a) <= (_area(box_b), b):
        small, large = (a, box_a), (b, box_b)
    else:
        small, large = (b, box_b), (a, box_a)
    if _area(small[1]) < _area(large[1]):
        if large[0] in containers and _inside(small[1], large[1], rules):
            return Proposal(small[0], large[0], "in")
        if _on(small[1], large[1], rules):
            return Proposal(small[0], large[0], "on")
    if _close(box_a, box_b, rules):
        return Proposal(min(a, b), max(a, b), "proximity")
    return None


def propose_relations(
    boxes: Mapping[int, Box],
    rules: ProposalRules | None = None,
    *,
    containers: Collection[int] = (),
) -> list[Proposal]:
    """Proposals for every pair of ``boxes`` (object id -> box), sorted by (src, dst);
    ``containers``: the ids of the boxes whose class is a catalog container."""
    rules = rules or DEFAULT_RULES
    ids = sorted(boxes)
    out = []
    for k, a in enumerate(ids):
        for b in ids[k + 1 :]:
            found = propose_pair(a, boxes[a], b, boxes[b], rules, containers=containers)
            if found is not None:
                out.append(found)
    return sorted(out, key=lambda p: (p.src, p.dst))
