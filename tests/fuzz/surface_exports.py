"""Surface: small datasets' boxes and instance masks, drawn at random, through the COCO and YOLO
writers (``sgdata export coco --masks`` / ``export yolo``: :mod:`sgdata.label.coco_export`,
:mod:`sgdata.label.yolo_export`, :mod:`sgdata.label.detector_files`).

A copy of the tests' dataset with the optional channels gets, in a few views of one split,
boxes anywhere (reversed, empty, off the image, at int16's ends), objects dropped or added with
any class id, a camera of another size (zero included), and instance masks random, of another
shape, naming objects the view does not list, empty, 8-bit or not a PNG. The export answers one
clear error (nothing written) or files that parse: pycocotools' ``COCO()`` loads every
instances file, each annotation's box lies in its image and its mask decodes to the image's
size; every YOLO label line is a class index of ``data.yaml``'s names and four numbers in
[0, 1], and each image has its label file.
"""

from __future__ import annotations

import contextlib
import io
import shutil
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
from hypothesis import strategies as st
from PIL import Image

from sgdata.dataset.channels import encode_mask
from sgdata.errors import SgdataError
from sgdata.label.coco_export import export_coco
from sgdata.label.yolo_export import export_yolo

from .harness import Surface
from .surface_datasets import channels_dataset

SPLIT = "val"
ROWS = 3  # views of the split kept: the export's cost per example
INT16 = (-32768, 32767)
EDGES = (-32768, -1, 0, 1, 47, 95, 96, 97, 1000, 32767)  # around a 96 px image

coordinates = st.one_of(st.integers(-5, 101), st.sampled_from(EDGES))
inside = st.lists(st.integers(0, 96), min_size=4, max_size=4).map(
    lambda c: [min(c[0], c[2]), min(c[1], c[3]), max(c[0], c[2]), max(c[1], c[3])]
)  # a box a detector could have drawn
boxes = st.one_of(inside, st.lists(coordinates, min_size=4, max_size=4))
objects = st.fixed_dictionaries(
    {
        "box": st.one_of(st.none(), boxes),  # None: the stored box
        "class_id": st.one_of(st.none(), st.sampled_from([-1, 0, 1, 31, 32, 33, 1000, 32767])),
        "visible_pixels": st.one_of(st.none(), st.sampled_from([-1, 0, 1, 10_000])),
    }
)
masks = st.one_of(
    st.just(None),  # the stored mask
    st.fixed_dictionaries(
        {
            "kind": st.sampled_from(["random", "shape", "empty", "8-bit", "garbage", "null"]),
            "most": st.sampled_from([0, 1, 2, 3, 9, 65535]),
            "seed": st.integers(0, 2**16),
        }
    ),
)
views = st.fixed_dictionaries(
    {
        "row": st.integers(0, ROWS - 1),
        "objects": st.lists(objects, max_size=4),
        "drop": st.integers(0, 3),  # stored objects removed before ``objects`` are applied
        "camera": st.one_of(
            st.none(),
            st.sampled_from([(96, 96), (0, 96), (96, 0), (48, 200), (-96, 96), (32767, 1)]),
        ),  # fmt: skip
        "mask": masks,
    }
)
examples = st.lists(views, min_size=1, max_size=3)


def _mask(spec: dict[str, Any], height: int, width: int, count: int) -> bytes | None:
    rng = np.random.default_rng(spec["seed"])
    kind = spec["kind"]
    if kind == "null":
        return None
    if kind == "garbage":
        return rng.bytes(int(rng.integers(0, 64)))
    if kind == "8-bit":
        buffer = io.BytesIO()
        Image.fromarray(rng.integers(0, 4, (height, width), dtype=np.uint8)).save(buffer, "PNG")
        return buffer.getvalue()
    if kind == "shape":
        height, width = int(rng.integers(1, 130)), int(rng.integers(1, 130))
    most = 0 if kind == "empty" else min(spec["most"], 65535)
    most = count if spec["most"] == 1 else most  # 1: exactly the objects the view lists
    return encode_mask(rng.integers(0, most + 1, (height, width), dtype=np.uint16))


def _edit(row: dict[str, Any], view: dict[str, Any]) -> dict[str, Any]:
    """The row with ``view``'s boxes, objects, camera and mask."""
    kept = row["objects"][view["drop"] :]
    template = row["objects"][0] if row["objects"] else None
    edited = []
    for k, change in enumerate(view["objects"]):
        if k < len(kept):
            obj = dict(kept[k])
        elif template is not None:
            obj = dict(template) | {"instance": 10_000 + k}
        else:
            continue
        if change["box"] is not None:
            obj["box2d"] = [int(np.clip(v, *INT16)) for v in change["box"]]
        if change["class_id"] is not None:
            obj["class_id"] = change["class_id"]
        if change["visible_pixels"] is not None:
            obj["visible_pixels"] = change["visible_pixels"]
        edited.append(obj)
    row = dict(row) | {"objects": edited + kept[len(view["objects"]) :]}
    if view["camera"] is not None:
        row["camera"] = dict(row["camera"]) | dict(
            zip(("width", "height"), view["camera"], strict=True)
        )
    if view["mask"] is not None:
        data = _mask(view["mask"], 96, 96, len(row["objects"]))
        row["instances"] = None if data is None else {"bytes": data, "path": None}
    return row


def _write(root: Path, example: list[dict[str, Any]]) -> None:
    """Keep :data:`ROWS` views of the split's shard and apply the example's edits to them."""
    (shard,) = sorted((root / "observations" / SPLIT).glob("*.parquet"))
    table = pq.read_table(shard)
    rows = table.slice(0, ROWS).to_pylist()
    for view in example:
        rows[view["row"]] = _edit(rows[view["row"]], view)
    pq.write_table(pa.Table.from_pylist(rows, schema=table.schema), shard)


def _check_coco(out: Path) -> None:
    from pycocotools.coco import COCO
    from pycocotools.mask import decode

    with contextlib.redirect_stdout(io.StringIO()):  # COCO() prints its progress
        coco = COCO(str(out / "annotations" / f"instances_{SPLIT}.json"))
    categories = set(coco.getCatIds())
    for ann in coco.dataset["annotations"]:
        image = coco.imgs[ann["image_id"]]
        _, _, w, h = ann["bbox"]
        assert ann["category_id"] in categories, (
            f"COCO category not among the categories: {ann['category_id']}"
        )
        assert w >= 0 and h >= 0 and ann["area"] >= 0, (
            f"COCO box or area negative: {ann['bbox']}, area {ann['area']}"
        )
        if "segmentation" in ann:
            pixels = decode(coco.annToRLE(ann))
            assert pixels.shape == (image["height"], image["width"]), (
                f"COCO mask not its image's size: {pixels.shape} in a {image['width']} x "
                f"{image['height']} image"
            )


def _check_yolo(out: Path) -> None:
    text = (out / "data.yaml").read_text(encoding="utf-8").splitlines()
    names = text.index("names:")
    classes = len(text) - names - 1
    images = sorted((out / "images" / SPLIT).iterdir())
    for image in images:
        label = out / "labels" / SPLIT / f"{image.stem}.txt"
        assert label.is_file(), f"YOLO image without a label file: {image.name}"
        for line in label.read_text(encoding="utf-8").splitlines():
            fields = line.split()
            assert len(fields) == 5, f"YOLO line not 5 fields: {line!r}"
            assert fields[0].isdigit() and int(fields[0]) < classes, (
                f"YOLO class beyond data.yaml's names: {fields[0]} of {classes}"
            )
            values = [float(v) for v in fields[1:]]
            assert all(0.0 <= v <= 1.0 for v in values), f"YOLO numbers outside [0, 1]: {values}"


def feed(example: list[dict[str, Any]], work: Path, dataset: Path) -> None:
    root = work / "data"
    shutil.copytree(dataset, root)
    _write(root, example)
    refusals: list[SgdataError] = []
    for export, check, out, options in (
        (export_coco, _check_coco, work / "coco", {"masks": True}),
        (export_yolo, _check_yolo, work / "yolo", {}),
    ):
        try:
            export(root, out, split=SPLIT, **options)
        except SgdataError as exc:  # the other writer still runs; then the refusal is raised
            left = [p.name for p in work.iterdir() if p.name.startswith(f".{out.name}")]
            assert not out.exists() and not left, f"half-written export: {out.name} after {exc}"
            refusals.append(exc)
            continue
        check(out)
    if refusals:
        raise refusals[0]


SURFACE = Surface(
    name="detector exports (COCO, YOLO)",
    inputs=examples,
    feed=feed,
    session=channels_dataset,
)
