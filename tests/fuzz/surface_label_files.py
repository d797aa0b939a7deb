"""Surface: COCO, LabelMe and Label Studio files, as mutations of valid ones, through ``sgdata
import`` (labels saved, then a real dataset written)."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
from hypothesis import strategies as st
from PIL import Image

from sgdata.label.importers import import_labels

from .harness import Surface
from .mutations import NASTY_TEXT, mutated

COCO = {
    "images": [
        {"id": 7, "file_name": "a.png", "width": 64, "height": 48},
        {"id": 9, "file_name": "sub/b.png", "width": 40, "height": 30},
    ],
    "categories": [{"id": 1, "name": "DiningTable"}, {"id": 2, "name": "Mug"}],
    "annotations": [
        {"id": 100, "image_id": 7, "category_id": 1, "bbox": [4, 10, 40, 30]},
        {"id": 101, "image_id": 7, "category_id": 2, "bbox": [20.4, 5.6, 10, 8.2]},
        {"id": 102, "image_id": 9, "category_id": 2, "bbox": [1, 1, 14, 8]},
    ],
}
LABELME = {
    "imagePath": "a.png",
    "imageWidth": 64,
    "imageHeight": 48,
    "shapes": [
        {"label": "Chair", "shape_type": "rectangle", "points": [[50, 40], [10, 10]]},
        {"label": "Sofa", "shape_type": "polygon", "points": [[1, 1], [5, 1], [5, 5]]},
    ],
}


def _rect(rid: str, label: str, x: float, y: float, w: float, h: float) -> dict:
    return {
        "id": rid,
        "type": "rectanglelabels",
        "from_name": "label",
        "to_name": "image",
        "original_width": 64,
        "original_height": 48,
        "value": {
            "x": x,
            "y": y,
            "width": w,
            "height": h,
            "rotation": 0,
            "rectanglelabels": [label],
        },
    }


LABELSTUDIO = [
    {
        "id": 1,
        "data": {"image": "/data/upload/3/0a1b2c3d-a.png"},
        "annotations": [
            {
                "result": [
                    _rect("tbl", "DiningTable", 10, 40, 60, 50),
                    _rect("mug", "Mug", 30, 20, 10, 12),
                    {
                        "type": "relation",
                        "from_id": "mug",
                        "to_id": "tbl",
                        "direction": "right",
                        "labels": ["on"],
                    },
                ],
                "was_cancelled": False,
            }
        ],
    }
]
BASES = {"coco": COCO, "labelme": LABELME, "labelstudio": LABELSTUDIO}

files = st.one_of(
    *(st.tuples(st.just(fmt), mutated(base, most=3)) for fmt, base in BASES.items()),
    st.tuples(
        st.sampled_from(sorted(BASES)), st.sampled_from(["", "{", "[]", "null", '{"a": NaN}'])
    ),
    st.tuples(st.sampled_from(sorted(BASES)), st.sampled_from(NASTY_TEXT)),
)


def _photo(path: Path, width: int, height: int) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    Image.fromarray(np.full((height, width, 3), 120, np.uint8)).save(path)


def feed(example: tuple[str, Any], work: Path, session: None) -> None:
    fmt, doc = example
    photos = work / "photos"
    _photo(photos / "a.png", 64, 48)
    _photo(photos / "sub" / "b.png", 40, 30)
    path = work / "kitchen_scan.json"
    text = doc if isinstance(doc, str) else json.dumps(doc)  # NaN and inf as JSON allows them
    path.write_text(text, encoding="utf-8", errors="surrogatepass")
    summary = import_labels(fmt, path, photos, work / "out")
    assert summary.photos >= 0 and all(math.isfinite(v) for v in (summary.boxes, summary.relations))


SURFACE = Surface(
    name="label files (COCO, LabelMe, Label Studio)",
    inputs=files,
    feed=feed,
    outputs=("out",),
)
