"""COCO box AP of a detector on a split, by pycocotools (the reference implementation), with
AP50 per class: the figures docs/detector.md quotes."""

from __future__ import annotations

import contextlib
import io
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
import torch
from torch import nn

from seannet.detection.coco_views import CocoViews

__all__ = ["CocoScore", "coco_score", "detect"]

Progress = Callable[[int, int], None]


@torch.no_grad()
def detect(
    model: nn.Module,
    views: CocoViews,
    indices: Sequence[int],
    *,
    batch_size: int = 16,
    progress: Progress | None = None,
) -> list[dict[str, np.ndarray]]:
    """The detections of views ``indices``: per view ``boxes`` (n, 4) xyxy pixels,
    ``labels`` (n,) category ids, ``scores`` (n,), best first."""
    model.eval()
    out: list[dict[str, np.ndarray]] = []
    for start in range(0, len(indices), batch_size):
        chunk = indices[start : start + batch_size]
        for found in model([views.image(i) for i in chunk]):
            out.append({k: v.numpy() for k, v in found.items()})
        if progress is not None:
            progress(min(start + batch_size, len(indices)), len(indices))
    return out


@dataclass(frozen=True)
class CocoScore:
    """pycocotools' box AP (IoU 0.5:0.95), AP50, and AP50 per category name (categories
    with no ground truth in the split are left out)."""

    views: int
    ap: float
    ap50: float
    ap50_per_class: dict[str, float] = field(default_factory=dict)

    def to_dict(self) -> dict[str, object]:
        return {
            "views": self.views,
            "ap": self.ap,
            "ap50": self.ap50,
            "ap50_per_class": self.ap50_per_class,
        }


def coco_score(
    views: CocoViews, indices: Sequence[int], detections: Sequence[dict[str, np.ndarray]]
) -> CocoScore:
    """Score ``detections`` of views ``indices`` against the split's ground truth."""
    from pycocotools.coco import COCO
    from pycocotools.cocoeval import COCOeval

    image_ids = [views.images[i]["id"] for i in indices]
    results = []
    for image_id, found in zip(image_ids, detections, strict=True):
        for (x1, y1, x2, y2), label, score in zip(
            found["boxes"].tolist(),
            found["labels"].tolist(),
            found["scores"].tolist(),
            strict=True,
        ):
            results.append(
                {
                    "image_id": image_id,
                    "category_id": int(label),
                    "bbox": [x1, y1, x2 - x1, y2 - y1],
                    "score": float(score),
                }
            )
    with contextlib.redirect_stdout(io.StringIO()):  # pycocotools prints as it goes
        truth = COCO()
        truth.dataset = views.document
        truth.createIndex()
        if not results:
            return CocoScore(len(image_ids), 0.0, 0.0)
        found_coco = truth.loadRes(results)
        run = COCOeval(truth, found_coco, "bbox")
        run.params.imgIds = image_ids
        run.evaluate()
        run.accumulate()
        run.summarize()
    names = {c["id"]: c["name"] for c in views.document["categories"]}
    # precision: [IoU threshold, recall, category, area range, max detections]; IoU 0.5 is
    # the first threshold, "all" areas the first range, 100 detections the last
    precision = run.eval["precision"][0, :, :, 0, -1]
    per_class = {}
    for k, category in enumerate(run.params.catIds):
        p = precision[:, k]
        if (p > -1).any():
            per_class[names[category]] = float(p[p > -1].mean())
    return CocoScore(
        len(image_ids), float(max(run.stats[0], 0.0)), float(max(run.stats[1], 0.0)), per_class
    )
