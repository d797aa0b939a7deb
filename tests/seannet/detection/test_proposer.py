"""seannet's trained detector as ``sgdata label --detector``'s box proposer: a run names it,
and it proposes on a photo's pixels what the detector's own evaluation sees on that view."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
from PIL import Image

from seannet.detection.coco_eval import detect
from seannet.detection.coco_views import CocoViews
from seannet.detection.train import PROPOSER, load_detector
from sgdata.label.box_proposer import open_proposer


def test_the_proposer_sees_what_the_detectors_evaluation_sees(detector_run: Path) -> None:
    assert json.loads((detector_run / "detector.json").read_text())["proposer"] == PROPOSER
    views = CocoViews(detector_run / "coco", "test")
    loaded = load_detector(detector_run)
    found = detect(loaded.model, views, [0])[0]
    path = detector_run / "coco" / "images" / "test" / views.images[0]["file_name"]
    pixels = np.asarray(Image.open(path).convert("RGB"))
    height, width = pixels.shape[:2]
    proposer = open_proposer(detector_run, min_score=0.0, known=loaded.classes)
    got = proposer(pixels)
    assert got, "an FCOS head scores every location: a two-epoch detector proposes boxes"
    expected = []
    for box, label, score in zip(found["boxes"], found["labels"], found["scores"], strict=True):
        u1, v1, u2, v2 = (round(float(x)) for x in box)
        u1, u2, v1, v2 = max(u1, 0), min(u2, width), max(v1, 0), min(v2, height)
        if u2 - u1 >= 2 and v2 - v1 >= 2:
            expected.append((loaded.classes[int(label) - 1], (u1, v1, u2, v2), float(score)))
    expected.sort(key=lambda row: -row[2])
    assert [(b.class_name, b.box) for b in got] == [row[:2] for row in expected]
    assert np.allclose([b.score for b in got], [row[2] for row in expected], atol=1e-6)
    # the floor keeps the best ones only
    floor = got[len(got) // 2].score
    assert all(b.score >= floor for b in open_proposer(
        detector_run, min_score=floor, known=loaded.classes
    )(pixels))  # fmt: skip
