"""A card's sweep.png: bars on a 0-100 % axis, counts under the bins, empty bins as gaps."""

from __future__ import annotations

import numpy as np

from seannet.methods.cards import _plot

BAR = (70, 110, 200)


def test_an_empty_bin_is_a_gap_and_a_full_one_a_bar_of_its_height() -> None:
    bins = {
        "0": {"accuracy": 1.0, "triplets": 12},
        "1-2": {"accuracy": float("nan"), "triplets": 0},
        "3+": {"accuracy": 0.5, "triplets": 4},
    }
    card = {"method": "m", "summary": {"change": {"moved_objects": bins}}}
    pixels = np.asarray(_plot(card))
    blue = np.all(pixels == BAR, axis=2)
    columns = np.flatnonzero(blue.any(axis=0))
    # three bins share the panel: the middle third holds no bar at all
    panel = columns.min(), columns.max()
    thirds = np.array_split(np.arange(panel[0], panel[1] + 1), 3)
    heights = [int(blue[:, third].any(axis=1).sum()) for third in thirds]
    assert heights[1] == 0 and heights[0] > 0 and heights[2] > 0
    assert abs(heights[2] / heights[0] - 0.5) < 0.02  # 50 % is half of 100 %
    # the bars stand on the panel's floor; under each bin its name, then its count
    floor = int(np.flatnonzero(blue.any(axis=1)).max())
    ink = pixels.sum(axis=2) < 400
    count_band = ink[floor + 16 : floor + 30]
    assert all(count_band[:, third].any() for third in thirds)
    # tick labels (0 % to 100 %) left of the panel's frame
    frame = int(np.flatnonzero(ink[floor - 5]).min())
    assert ink[: floor + 1, : frame - 4].sum() > 50
