"""The 2D proposal rules on hand-made boxes."""

from __future__ import annotations

import pytest

from sgdata.errors import ConfigError
from sgdata.label.proposals import Proposal, ProposalRules, propose_relations

TABLE = (40, 100, 280, 230)


def test_small_box_standing_on_the_top_band_is_on() -> None:
    mug = (120, 60, 170, 105)  # bottom edge 105: just below the table's top edge 100
    assert propose_relations({0: TABLE, 1: mug}) == [Proposal(1, 0, "on")]


def test_bottom_edge_below_the_top_part_or_beside_the_box_is_not_on() -> None:
    low = (120, 212, 170, 228)  # bottom edge at 98% of the table's height: its front rim
    assert propose_relations({0: TABLE, 1: low}) == [Proposal(0, 1, "proximity")]
    beside = (300, 60, 340, 105)  # bottom in the band's rows but centre not over the table
    assert all(p.type != "on" for p in propose_relations({0: TABLE, 1: beside}))


def test_cup_on_a_saucer_seen_from_above_is_on() -> None:
    # skimage's coffee photo (600 x 400): the cup's box sticks out above the saucer's, its
    # bottom edge lies at 75% of the saucer's height, 82% of it inside the saucer's box
    saucer, cup = (76, 70, 480, 388), (172, 18, 410, 308)
    assert propose_relations({0: saucer, 1: cup}) == [Proposal(1, 0, "on")]


def test_contained_boxes_are_in_only_for_containers() -> None:
    bowl, apple = (200, 110, 260, 150), (215, 120, 236, 139)
    assert propose_relations({5: bowl, 7: apple}, containers={5}) == [Proposal(7, 5, "in")]
    # the same boxes when the larger is no container (a shelf, a plate): on
    assert propose_relations({5: bowl, 7: apple}) == [Proposal(7, 5, "on")]
    shelf, book = (20, 20, 300, 220), (100, 120, 140, 160)
    assert propose_relations({0: shelf, 1: book}) == [Proposal(1, 0, "on")]


def test_far_boxes_get_nothing_and_close_ones_proximity() -> None:
    assert propose_relations({0: (0, 0, 10, 10), 1: (100, 100, 110, 110)}) == []
    assert propose_relations({3: (0, 0, 10, 10), 2: (12, 0, 22, 10)}) == [
        Proposal(2, 3, "proximity")
    ]


def test_equal_boxes_are_neither_on_nor_in() -> None:
    assert propose_relations({0: (0, 0, 10, 10), 1: (0, 0, 10, 10)}) == [
        Proposal(0, 1, "proximity")
    ]


def test_one_proposal_per_pair_sorted() -> None:
    boxes = {0: TABLE, 1: (120, 60, 170, 105), 2: (200, 150, 230, 190), 9: (900, 900, 910, 910)}
    found = propose_relations(boxes, containers={0})
    pairs = [(p.src, p.dst) for p in found]
    assert pairs == sorted(pairs)
    assert len({frozenset(p) for p in pairs}) == len(pairs)
    assert Proposal(2, 0, "in") in found and all(9 not in p for p in pairs)


def test_rules_are_checked_and_recorded() -> None:
    with pytest.raises(ConfigError, match="inside_share"):
        ProposalRules(inside_share=1.5)
    assert ProposalRules().to_dict()["top_band"] == 0.8
