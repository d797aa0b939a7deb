"""What two generations of one recipe may differ by and still be the same dataset: the
tolerance of ``sgdata diff`` (:mod:`sgdata.dataset.diff`), kept apart so that the command line
reads its defaults without loading the tables."""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["Tolerance"]


@dataclass(frozen=True)
class Tolerance:
    """What a pixel-level difference may reach and still be "the same dataset"."""

    pixel_share: float = 0.01  # of one view's pixels, per channel; also bounds visible_pixels
    min_iou: float = 0.9  # of an object's 2D box with its counterpart
