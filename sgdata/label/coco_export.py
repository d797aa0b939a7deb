"""``sgdata export coco``: a dataset's views as COCO instances files and image files.

Layout of the output folder::

    annotations/instances_<split>.json   one COCO file per split
    images/<split>/<obs_id, / as __>.png the views' images (file_name in the JSON)

Each visible object is one annotation: ``bbox`` ``[u1, v1, u2 - u1, v2 - v1]`` (COCO's x, y,
width, height, pixels, the same edges as the stored box), ``area`` its visible pixels (the
area of its mask), ``iscrowd`` 0 and, with ``masks``, ``segmentation`` as compressed RLE of
its pixels in the instance mask (pycocotools' encoding). Category ids are the manifest class
index + 1 (COCO keeps 0 for background), so a category id is also the value of that class in
the class mask (:func:`sgdata.dataset.channels.class_mask`); every catalog class is listed.
An image entry carries its view's camera where the dataset has it: ``intrinsics`` (K, 3 x 3)
and ``camera_to_world`` (4 x 4, OpenCV axes; :mod:`sgdata.dataset.camera`).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from sgdata.errors import ConfigError, DatasetError
from sgdata.label.detector_files import is_real

__all__ = ["CocoSummary", "export_coco"]


@dataclass
class CocoSummary:
    """What :func:`export_coco` wrote."""

    root: Path
    files: list[Path] = field(default_factory=list)  # the instances JSON files
    images: int = 0
    annotations: int = 0
    masks: bool = False


def export_coco(
    dataset_dir: Path,
    out: Path,
    *,
    split: str | None = None,
    masks: bool = False,
    force: bool = False,
) -> CocoSummary:
    """Write the views of ``dataset_dir`` (every split, or ``split``) as COCO under ``out``.

    Args:
        dataset_dir: the dataset root.
        out: the output folder: absent or empty, or replaced whole with ``force``.
        split: export this split only.
        masks: add RLE segmentations from the ``instances`` channel (needs pycocotools).
        force: replace a non-empty ``out``.

    Raises:
        ConfigError: ``masks`` on a dataset without instance masks, or without pycocotools;
            ``out`` not empty; an unknown split. Nothing is written then.
        DatasetError: ``dataset_dir`` is not a readable dataset, or a view cannot be written
            (a box off its image, an unknown class, a mask of another size). Nothing is
            written then.
    """
    from sgdata.dataset import Dataset
    from sgdata.dataset.channels import decode_channel
    from sgdata.fileio import atomic_write_bytes, atomic_write_text
    from sgdata.label.detector_files import (
        export_splits,
        image_file_name,
        staged_dir,
        view_rows,
    )

    ds = Dataset.open(dataset_dir)
    splits = export_splits(ds, split)
    encode = _rle_encoder() if masks else None
    if masks:
        _require_masks(ds, dataset_dir)
    categories = [
        {"id": c.id + 1, "name": c.name, "supercategory": c.dynamics} for c in ds.manifest.classes
    ]
    summary = CocoSummary(Path(out), masks=masks)
    extra = ["intrinsics", "camera_to_world", *(["instances"] if masks else [])]
    with staged_dir(Path(out), force=force) as stage:
        for name in splits:
            images, annotations = [], []
            for row in view_rows(ds, [name], extra):
                file_name = image_file_name(row["obs_id"], row["image_format"])
                atomic_write_bytes(stage / "images" / name / file_name, row["image"])
                width, height = row["camera"]["width"], row["camera"]["height"]
                image_id = len(images) + 1
                images.append(
                    {
                        "id": image_id,
                        "file_name": file_name,
                        "width": width,
                        "height": height,
                        "obs_id": row["obs_id"],
                        **_camera(row),
                    }
                )
                mask = None
                if encode is not None:
                    if row["instances"] is None:
                        raise ConfigError(
                            f"--masks: view {row['obs_id']} has no instance mask; "
                            "export without --masks"
                        )
                    mask = decode_channel(row["instances"], where=f"{row['obs_id']}: instances")
                    _check_mask(mask, row)
                for k, obj in enumerate(row["objects"]):
                    u1, v1, u2, v2 = obj["box2d"]
                    ann: dict[str, Any] = {
                        "id": len(annotations) + 1,
                        "image_id": image_id,
                        "category_id": obj["class_id"] + 1,
                        "bbox": [u1, v1, u2 - u1, v2 - v1],
                        "area": obj["visible_pixels"],
                        "iscrowd": 0,
                        "instance": obj["instance"],
                    }
                    if mask is not None and encode is not None:
                        ann["segmentation"] = encode(mask == k + 1)
                    annotations.append(ann)
            document = {
                "info": {
                    "description": f"{ds.manifest.name} {ds.manifest.version}, split {name}",
                    "version": ds.manifest.version,
                },
                "images": images,
                "annotations": annotations,
                "categories": categories,
            }
            path = stage / "annotations" / f"instances_{name}.json"
            atomic_write_text(path, json.dumps(document, separators=(",", ":")) + "\n")
            summary.files.append(Path(out) / path.relative_to(stage))
            summary.images += len(images)
            summary.annotations += len(annotations)
    return summary


def _camera(row: dict[str, Any]) -> dict[str, Any]:
    """An image entry's camera (a dataset older than 2.2.0 has none until migrated): K as a
    3 x 3 matrix and the 4 x 4 camera-to-world pose, as :mod:`sgdata.dataset.camera` states
    them (OpenCV axes)."""
    out: dict[str, Any] = {}
    if row["intrinsics"] is not None:
        fx, fy, cx, cy = row["intrinsics"]
        out["intrinsics"] = [[fx, 0.0, cx], [0.0, fy, cy], [0.0, 0.0, 1.0]]
    if row["camera_to_world"] is not None:
        pose = row["camera_to_world"]
        out["camera_to_world"] = [pose[4 * k : 4 * k + 4] for k in range(4)]
    return out


def _check_mask(mask: np.ndarray, row: dict[str, Any]) -> None:
    """Refuse an instance mask of another size than its view, or naming an unlisted object."""
    size, count = (row["camera"]["height"], row["camera"]["width"]), len(row["objects"])
    if mask.shape != size:
        raise DatasetError(
            f"view {row['obs_id']}: instance mask of {mask.shape[1]} x {mask.shape[0]} pixels; "
            f"expected the camera's {size[1]} x {size[0]}"
        )
    if int(mask.max(initial=0)) > count:
        raise DatasetError(
            f"view {row['obs_id']}: instance mask holds {int(mask.max())} but the view lists "
            f"{count} objects"
        )


def _require_masks(ds: Any, dataset_dir: Path) -> None:
    """Refuse ``--masks`` on a dataset that stores no instance masks."""
    from sgdata.dataset.channels import stored_channels

    if "instances" not in stored_channels(ds.manifest.config, ds.manifest.format_version):
        real = "a real (labelled) dataset has none; " if is_real(ds) else ""
        raise ConfigError(
            f"--masks: {dataset_dir} has no instance masks ({real}generate it with "
            "[outputs] instances = true, or export without --masks)"
        )


def _rle_encoder() -> Any:
    """pycocotools' RLE encoder as ``bool mask -> JSON-able RLE``.

    Raises:
        ConfigError: pycocotools is not installed.
    """
    try:
        from pycocotools import mask as mask_utils
    except ImportError:
        raise ConfigError(
            "--masks needs pycocotools: pip install 'sgdata[coco]' (or pip install pycocotools)"
        ) from None

    def encode(pixels: np.ndarray) -> dict[str, Any]:
        rle = mask_utils.encode(np.asfortranarray(pixels.astype(np.uint8)))
        return {"size": [int(v) for v in rle["size"]], "counts": rle["counts"].decode("ascii")}

    return encode
