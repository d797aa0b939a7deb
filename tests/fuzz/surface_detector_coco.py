"""Surface: the COCO files ``seannet detector train`` and ``eval`` read (a run's ``coco/``
export, which a person may edit by hand or replace), through
:class:`seannet.detection.coco_views.CocoViews`.

A small valid instances file (two images, two classes, three boxes) gets up to three of the
mutations people make to JSON (a key removed, a value retyped, made extreme or nasty text, a
list item duplicated, an unknown key), and its images may be missing or not images. Reading
the split and every item answers one line (:class:`~seannet.errors.DataError`, or
:class:`~sgdata.label.annotations.AnnotationFormatError` for a field), or items whose
boxes and labels are what an oracle written here, apart from the reader, says the file holds:
every box of positive width and height as (x0, y0, x1, y1), in file order, with its class.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

from hypothesis import strategies as st

from seannet.errors import SeannetError  # no torch: the fuzz suite loads it late
from sgdata.errors import SgdataError

from .harness import Surface
from .mutations import mutated

SPLIT = "train"
SIZE = (12, 8)  # width, height of each image
BASE = {
    "images": [
        {"id": 1, "file_name": "a.png", "width": SIZE[0], "height": SIZE[1]},
        {"id": 2, "file_name": "b.png", "width": SIZE[0], "height": SIZE[1]},
    ],
    "categories": [{"id": 1, "name": "Mug"}, {"id": 2, "name": "Table"}],
    "annotations": [
        {"id": 1, "image_id": 1, "category_id": 2, "bbox": [1, 1, 6.5, 4], "area": 26},
        {"id": 2, "image_id": 1, "category_id": 1, "bbox": [7, 2, 3, 3], "area": 9},
        {"id": 3, "image_id": 2, "category_id": 1, "bbox": [0, 0, 0, 5], "area": 0},
    ],
}
IMAGES = ("png", "png", "png", "png", "missing", "text", "empty")

inputs = st.fixed_dictionaries(
    {"document": mutated(BASE), "a.png": st.sampled_from(IMAGES), "b.png": st.just("png")}
)


def _number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _expected(doc: Any, readable: set[str]) -> dict[int, tuple[list, list]] | None:
    """Image id -> (boxes xyxy, labels) in image-id order, or None where the reader must
    refuse the file: the rules of what sgdata export coco writes, restated apart."""
    if not isinstance(doc, dict) or not all(
        isinstance(doc.get(k), list) for k in ("images", "annotations", "categories")
    ):
        return None
    images, categories = doc["images"], doc["categories"]
    if not all(isinstance(c, dict) and type(c.get("id")) is int for c in categories):
        return None
    ids = sorted(c["id"] for c in categories)
    if not ids or ids != list(range(1, len(ids) + 1)):
        return None
    if not all(isinstance(im, dict) and type(im.get("id")) is int for im in images):
        return None
    if len({im["id"] for im in images}) != len(images):
        return None
    if not all(
        isinstance(im.get("file_name"), str) and im["file_name"] in readable for im in images
    ):
        return None
    out: dict[int, tuple[list, list]] = {im["id"]: ([], []) for im in images}
    for ann in doc["annotations"]:
        if not isinstance(ann, dict) or type(ann.get("image_id")) is not int:
            return None
        if ann["image_id"] not in out or type(ann.get("category_id")) is not int:
            return None
        if ann["category_id"] not in ids:
            return None
        box = ann.get("bbox")
        if not isinstance(box, list) or len(box) != 4 or not all(_number(v) for v in box):
            return None
        if not all(abs(v) <= 1e6 for v in box) or not all(math.isfinite(v) for v in box):
            return None
        x, y, w, h = (float(v) for v in box)
        if w > 0 and h > 0:
            boxes, labels = out[ann["image_id"]]
            boxes.append([x, y, x + w, y + h])
            labels.append(ann["category_id"])
    return dict(sorted(out.items()))


def _write(example: dict, work: Path) -> set[str]:
    """The export's folder under ``work``; the names of the images that decode."""
    from PIL import Image

    (work / "annotations").mkdir(parents=True)
    (work / "annotations" / f"instances_{SPLIT}.json").write_text(json.dumps(example["document"]))
    folder = work / "images" / SPLIT
    folder.mkdir(parents=True)
    readable = set()
    for name in ("a.png", "b.png"):
        kind = example[name]
        if kind == "png":
            Image.new("RGB", SIZE, (120, 90, 60)).save(folder / name)
            readable.add(name)
        elif kind == "text":
            (folder / name).write_text("not an image")
        elif kind == "empty":
            (folder / name).write_bytes(b"")
    return readable


def feed(example: dict, work: Path, _session: None) -> None:
    import torch

    from seannet.detection.coco_views import CocoViews

    readable = _write(example, work)
    expected = _expected(example["document"], readable)
    views = CocoViews(work, SPLIT)
    got = {}
    for i in range(len(views)):
        image, target = views[i]
        assert image.shape == (3, SIZE[1], SIZE[0]), f"image shape: {tuple(image.shape)}"
        assert target["boxes"].dtype == torch.float32 and target["labels"].dtype == torch.int64
        got[views.images[i]["id"]] = (target["boxes"].tolist(), target["labels"].tolist())
    assert expected is not None, f"read a file the reader should refuse: {got}"
    assert list(got) == list(expected), f"images: {list(got)} != {list(expected)}"
    for key, (boxes, labels) in expected.items():
        assert got[key][1] == labels, f"labels of image {key}: {got[key][1]} != {labels}"
        close = all(
            math.isclose(a, b, rel_tol=1e-6, abs_tol=1e-4)
            for row, want in zip(got[key][0], boxes, strict=True)
            for a, b in zip(row, want, strict=True)
        )
        assert len(got[key][0]) == len(boxes) and close, f"boxes of image {key}: {got[key][0]}"


SURFACE = Surface(
    name="COCO files seannet detector reads",
    inputs=inputs,
    feed=feed,
    refusals=(SeannetError, SgdataError),
)
