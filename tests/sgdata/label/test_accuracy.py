"""Proposal accuracy: the scoring on hand-made pairs (the doc's table: tests/bench)."""

from __future__ import annotations

from sgdata.label.accuracy import score_proposals
from sgdata.label.classes import load_class_names
from sgdata.label.models import PhotoLabels
from sgdata.label.proposals import DEFAULT_RULES


def _labels(relations: list[dict]) -> PhotoLabels:
    objects = [
        {"id": 0, "class_name": "DiningTable", "box": [40, 100, 280, 230]},
        {"id": 1, "class_name": "Mug", "box": [120, 60, 170, 105]},
        {"id": 2, "class_name": "Chair", "box": [600, 600, 700, 700]},
    ]
    return PhotoLabels.model_validate({"objects": objects, "relations": relations})


def test_pairs_agree_on_type_and_direction() -> None:
    names = load_class_names()
    right = score_proposals(
        {"a": _labels([{"src": 1, "dst": 0, "type": "on"}])}, names, DEFAULT_RULES
    )
    assert (right.pairs, right.agree, right.hits["on"], right.hits["disjoint"]) == (3, 3, 1, 2)
    wrong = score_proposals(
        {"a": _labels([{"src": 0, "dst": 1, "type": "on"}])}, names, DEFAULT_RULES
    )
    assert (wrong.agree, wrong.labeled["on"], wrong.proposed["on"], wrong.hits["on"]) == (
        2,
        1,
        1,
        0,
    )
    undecided = score_proposals({"a": _labels([])}, names, DEFAULT_RULES)
    assert undecided.labeled["disjoint"] == 3 and undecided.agree == 2
