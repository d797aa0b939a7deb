"""A trained detector as the labeling tool's box proposer (``sgdata label --detector RUN``):
the function a run's ``detector.json`` names under ``proposer``."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import torch

from seannet.detection.train import load_detector
from sgdata.label.box_proposer import ProposedBox

__all__ = ["open_proposer"]


def open_proposer(run: Path):  # noqa: ANN201  (sgdata.label.box_proposer.Detect)
    """The detections of ``run``'s detector on a photo's (H, W, 3) uint8 RGB pixels: every box
    it keeps (torchvision's own score floor and non-maximum suppression), in photo pixels.

    Raises:
        CheckpointError: no detector in ``run``.
    """
    detector = load_detector(run)

    @torch.no_grad()
    def detect(pixels: np.ndarray) -> list[ProposedBox]:
        image = torch.from_numpy(np.array(pixels, np.uint8)).permute(2, 0, 1).float() / 255
        found = detector.model([image])[0]  # resized to the trained size, boxes scaled back
        return [
            ProposedBox(detector.classes[int(label) - 1], tuple(box.tolist()), float(score))
            for box, label, score in zip(
                found["boxes"], found["labels"], found["scores"], strict=True
            )
        ]

    return detect
