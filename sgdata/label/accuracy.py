"""How well the relation proposals match decided labels: per type and over every pair of boxes."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

from sgdata.label.classes import ClassNames
from sgdata.label.models import PhotoLabels
from sgdata.label.proposals import RELATION_NAMES, ProposalRules
from sgdata.label.review import proposals_for
from sgdata.markdown import table

__all__ = ["ProposalScore", "score_proposals"]


@dataclass
class ProposalScore:
    """Counts over the unordered pairs of boxes of some photos; no proposal reads ``disjoint``."""

    pairs: int = 0
    agree: int = 0  # same type and, for on / in, the same direction
    labeled: dict[str, int] = field(default_factory=lambda: dict.fromkeys(RELATION_NAMES, 0))
    proposed: dict[str, int] = field(default_factory=lambda: dict.fromkeys(RELATION_NAMES, 0))
    hits: dict[str, int] = field(default_factory=lambda: dict.fromkeys(RELATION_NAMES, 0))

    @property
    def accuracy(self) -> float:
        return self.agree / self.pairs if self.pairs else float("nan")

    def table(self) -> str:
        """A markdown table: per type, labeled / proposed / both, recall and precision."""
        rows: list[list[object]] = []
        for kind in RELATION_NAMES:
            n, p, h = self.labeled[kind], self.proposed[kind], self.hits[kind]
            recall = f"{h / n:.0%}" if n else "–"
            precision = f"{h / p:.0%}" if p else "–"
            rows.append([kind, n, p, h, recall, precision])
        rows.append(["**all pairs**", self.pairs, "", self.agree, f"{self.accuracy:.0%}", ""])
        header = ("relation", "labeled", "proposed", "both", "recall", "precision")
        return "\n".join(table(header, rows, right=range(1, 6)))


def score_proposals(
    photos: Mapping[str, PhotoLabels], classes: ClassNames, rules: ProposalRules
) -> ProposalScore:
    """Compare the proposals for each photo's boxes with its decided relations.

    Every unordered pair of boxes counts once: the labeled type is the decision (``disjoint``
    when undecided), the proposed type the proposal (``disjoint`` when none); ``on`` / ``in``
    agree only in the same direction.
    """
    score = ProposalScore()
    for labels in photos.values():
        decided = {frozenset((r.src, r.dst)): r for r in labels.relations}
        proposed = {frozenset((p.src, p.dst)): p for p in proposals_for(labels, classes, rules)}
        ids = sorted(o.id for o in labels.objects)
        for k, a in enumerate(ids):
            for b in ids[k + 1 :]:
                pair = frozenset((a, b))
                want, got = decided.get(pair), proposed.get(pair)
                want_type = want.type if want else "disjoint"
                got_type = got.type if got else "disjoint"
                directed = want_type in ("on", "in")
                same = want_type == got_type and (
                    not directed or (want.src, want.dst) == (got.src, got.dst)
                )
                score.pairs += 1
                score.agree += same
                score.labeled[want_type] += 1
                score.proposed[got_type] += 1
                score.hits[want_type] += same
    return score
