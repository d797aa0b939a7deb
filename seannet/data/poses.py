"""A view's pose as the data gives it: grid cell (i, j) and a heading index 0..HEADINGS-1.

seannet's home of the heading count, in the lowest stage that needs it (evaluation groups
views by heading, navigation turns between them). The generator's own home is
``sgdata.world.poses.HEADINGS_DEG`` (0, 90, 180, 270 degrees), which seannet does not import
(tests/architecture: seannet reaches only the dataset side of sgdata); a test checks the two
agree.
"""

from __future__ import annotations

__all__ = ["HEADINGS"]

HEADINGS = 4  # heading indices 0..3: 0, 90, 180, 270 degrees
