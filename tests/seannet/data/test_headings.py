"""The heading count: seannet's home (seannet.data.poses) agrees with the generator's."""

from __future__ import annotations

from seannet.data.poses import HEADINGS
from seannet.navigation import motion
from sgdata.world import triplets
from sgdata.world.poses import HEADINGS_DEG


def test_one_heading_count_everywhere() -> None:
    assert HEADINGS == len(HEADINGS_DEG) == triplets.HEADINGS
    assert motion.HEADINGS is HEADINGS and len(motion.FORWARD) == HEADINGS
