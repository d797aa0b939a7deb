"""The views of one split of a COCO export (``sgdata export coco``) as detector inputs and
targets: what the detector trains and is scored on, from the files any other tool reads."""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import torch
from PIL import Image
from torch import Tensor

from seannet.errors import DataError

__all__ = ["CocoViews", "ViewTarget", "collate_detection"]

ViewTarget = dict[str, Tensor]  # torchvision's: "boxes" (n, 4) xyxy pixels, "labels" (n,)


@dataclass
class CocoViews(torch.utils.data.Dataset):
    """Split ``split`` of the COCO export in ``folder``: item i is image i (by image id) as a
    (3, H, W) float tensor on [0, 1] and its target; ``flip`` mirrors an item left-right
    when ``flip(i)`` says so (training's augmentation, drawn by the caller's generator)."""

    folder: Path
    split: str

    def __post_init__(self) -> None:
        self.folder = Path(self.folder)
        path = self.folder / "annotations" / f"instances_{self.split}.json"
        try:
            document = json.loads(path.read_text())
        except (OSError, ValueError, RecursionError) as exc:  # RecursionError: nested too deeply
            raise DataError(f"{path}: not a readable COCO file ({exc})") from None
        _check_document(document, path)
        self.document: dict[str, Any] = document
        self.images = sorted(document["images"], key=lambda im: im["id"])
        self.categories = sorted(c["id"] for c in document["categories"])
        boxes: dict[int, list[list[float]]] = {im["id"]: [] for im in self.images}
        labels: dict[int, list[int]] = {im["id"]: [] for im in self.images}
        for ann in document["annotations"]:
            x, y, w, h = (float(v) for v in ann["bbox"])
            if w > 0 and h > 0:  # a box of no area teaches nothing and breaks the GIoU loss
                boxes[ann["image_id"]].append([x, y, x + w, y + h])
                labels[ann["image_id"]].append(ann["category_id"])
        self._boxes = boxes
        self._labels = labels
        self.flips: np.ndarray | None = None  # per item: mirror it (set per epoch)

    @property
    def num_classes(self) -> int:
        return len(self.categories)

    def __len__(self) -> int:
        return len(self.images)

    def image(self, i: int) -> Tensor:
        """Image ``i`` as (3, H, W) float32 on [0, 1]."""
        path = self.folder / "images" / self.split / self.images[i]["file_name"]
        try:
            with Image.open(path) as im:
                pixels = np.asarray(im.convert("RGB"))
        except OSError as exc:
            raise DataError(f"{path}: cannot read the image ({exc})") from None
        return torch.from_numpy(pixels.copy()).permute(2, 0, 1).float().div_(255.0)

    def __getitem__(self, i: int) -> tuple[Tensor, ViewTarget]:
        image_id = self.images[i]["id"]
        image = self.image(i)
        boxes = torch.tensor(self._boxes[image_id], dtype=torch.float32).reshape(-1, 4)
        labels = torch.tensor(self._labels[image_id], dtype=torch.int64)
        if self.flips is not None and self.flips[i]:
            width = image.shape[-1]
            image = image.flip(-1)
            boxes = torch.stack(
                (width - boxes[:, 2], boxes[:, 1], width - boxes[:, 0], boxes[:, 3]), dim=1
            )
        return image, {"boxes": boxes, "labels": labels}


# a box corner or side beyond this many pixels is no photo's: a hand-edited file's mistake
MOST_PIXELS = 1e6


def _check_document(document: object, path: Path) -> None:
    """Refuse, in one line naming the file and the field (the labeling tool's
    :class:`~sgdata.label.annotations.FieldReader`), what sgdata export coco never writes and
    the detector cannot learn from: missing lists, ids that are not integers, category ids
    other than 1..N, an annotation naming no image or class, a box that is not four numbers
    within :data:`MOST_PIXELS`."""
    from sgdata.label.annotations import FieldReader

    f = FieldReader(path)
    root = f.obj(document, "top level")
    ids = []
    for k, category in enumerate(f.get(root, "categories", "top level", "list")):
        ids.append(f.get(f.obj(category, f"categories[{k}]"), "id", f"categories[{k}]", "int"))
    if sorted(ids) != list(range(1, len(ids) + 1)) or not ids:
        raise f.fail("categories", "ids 1..N, as sgdata export coco writes")
    images: set[int] = set()
    for k, image in enumerate(f.get(root, "images", "top level", "list")):
        where = f"images[{k}]"
        image_id = f.get(f.obj(image, where), "id", where, "int")
        if image_id in images:
            raise f.fail(f"{where}.id", f"an id no other image has, not {image_id} again")
        f.get(image, "file_name", where, "str")
        images.add(image_id)
    for k, ann in enumerate(f.get(root, "annotations", "top level", "list")):
        where = f"annotations[{k}]"
        if f.get(f.obj(ann, where), "image_id", where, "int") not in images:
            raise f.fail(f"{where}.image_id", "the id of an entry of images")
        if f.get(ann, "category_id", where, "int") not in ids:
            raise f.fail(f"{where}.category_id", "the id of an entry of categories")
        box = f.get(ann, "bbox", where, "list")
        if len(box) != 4 or not all(
            isinstance(v, int | float) and not isinstance(v, bool) and abs(v) <= MOST_PIXELS
            for v in box  # NaN fails the bound too
        ):
            raise f.fail(f"{where}.bbox", f"[x, y, width, height] numbers within {MOST_PIXELS:g}")


def collate_detection(
    items: list[tuple[Tensor, ViewTarget]],
) -> tuple[list[Tensor], list[ViewTarget]]:
    """torchvision detectors take lists of images and targets, not stacked tensors."""
    return [image for image, _ in items], [target for _, target in items]
