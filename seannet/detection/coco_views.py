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
        except (OSError, ValueError) as exc:
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


def _integer(value: object) -> bool:
    return type(value) is int  # JSON's integers; not a bool, not 1.0


def _check_document(document: object, path: Path) -> None:
    """Refuse, in one line naming the file and the entry, what sgdata export coco never
    writes and the detector cannot learn from: missing lists, ids that are not integers,
    category ids other than 1..N, an annotation naming no image or class, a box that is not
    four finite numbers."""
    if not isinstance(document, dict) or not all(
        isinstance(document.get(k), list) for k in ("images", "annotations", "categories")
    ):
        raise DataError(
            f"{path}: expected a COCO object with lists images, annotations and categories"
        )
    categories = document["categories"]
    for k, category in enumerate(categories):
        if not isinstance(category, dict) or not _integer(category.get("id")):
            raise DataError(f"{path}: categories[{k}] has no integer id")
    ids = sorted(c["id"] for c in categories)
    if not ids or ids != list(range(1, len(ids) + 1)):
        raise DataError(f"{path}: category ids must be 1..N, as sgdata export coco writes")
    images: set[int] = set()
    for k, image in enumerate(document["images"]):
        if not isinstance(image, dict) or not _integer(image.get("id")):
            raise DataError(f"{path}: images[{k}] has no integer id")
        if image["id"] in images:
            raise DataError(f"{path}: images[{k}] repeats the image id {image['id']}")
        if not isinstance(image.get("file_name"), str):
            raise DataError(f"{path}: images[{k}] has no file_name string")
        images.add(image["id"])
    for k, ann in enumerate(document["annotations"]):
        if not isinstance(ann, dict):
            raise DataError(f"{path}: annotations[{k}] is not an object")
        if not _integer(ann.get("image_id")) or ann["image_id"] not in images:
            raise DataError(f"{path}: annotations[{k}] names no image of the file (image_id)")
        if not _integer(ann.get("category_id")) or not 1 <= ann["category_id"] <= len(ids):
            raise DataError(f"{path}: annotations[{k}] names no category 1..{len(ids)}")
        box = ann.get("bbox")
        if (
            not isinstance(box, list)
            or len(box) != 4
            or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in box)
            or not all(abs(v) <= MOST_PIXELS for v in box)  # NaN fails it too
        ):
            raise DataError(
                f"{path}: annotations[{k}].bbox must be four finite numbers [x, y, width, "
                f"height] in pixels, each within {MOST_PIXELS:.0e}"
            )


def collate_detection(
    items: list[tuple[Tensor, ViewTarget]],
) -> tuple[list[Tensor], list[ViewTarget]]:
    """torchvision detectors take lists of images and targets, not stacked tensors."""
    return [image for image, _ in items], [target for _, target in items]
