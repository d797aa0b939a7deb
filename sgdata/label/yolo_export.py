"""``sgdata export yolo``: a dataset's views in the folder layout YOLO trainers read.

Ultralytics' convention::

    data.yaml                           path, train / val / test image folders, names
    images/<split>/<obs_id, / as __>.png
    labels/<split>/<same stem>.txt      one line per object: class cx cy w h (0..1)

The class index is the manifest class index (``objects[].class_id``), ``names`` lists every
catalog class in that order; centre and size are the stored box ``[u1, v1, u2, v2]`` divided
by the image width and height. A view with no visible object gets an empty label file (a
background image).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

__all__ = ["YoloSummary", "export_yolo", "yolo_line"]


@dataclass
class YoloSummary:
    """What :func:`export_yolo` wrote."""

    root: Path
    images: int = 0
    boxes: int = 0


def yolo_line(class_id: int, box: list[int], width: int, height: int) -> str:
    """One label line: ``class cx cy w h``, normalised, six decimals."""
    u1, v1, u2, v2 = box
    cx, cy = (u1 + u2) / 2 / width, (v1 + v2) / 2 / height
    return f"{class_id} {cx:.6f} {cy:.6f} {(u2 - u1) / width:.6f} {(v2 - v1) / height:.6f}"


def export_yolo(
    dataset_dir: Path, out: Path, *, split: str | None = None, force: bool = False
) -> YoloSummary:
    """Write the views of ``dataset_dir`` (every split, or ``split``) as a YOLO folder ``out``.

    Raises:
        ConfigError: ``out`` not empty (without ``force``), an unknown split; nothing is
            written then.
        DatasetError: ``dataset_dir`` is not a readable dataset, or a view cannot be written
            (a box off its image, an unknown class). Nothing is written then.
    """
    from sgdata.dataset import Dataset
    from sgdata.fileio import atomic_write_bytes, atomic_write_text
    from sgdata.label.detector_files import export_splits, image_file_name, staged_dir, view_rows

    ds = Dataset.open(dataset_dir)
    splits = export_splits(ds, split)
    summary = YoloSummary(Path(out))
    with staged_dir(Path(out), force=force) as stage:
        for name in splits:
            (stage / "images" / name).mkdir(parents=True, exist_ok=True)
            for row in view_rows(ds, [name]):
                file_name = image_file_name(row["obs_id"], row["image_format"])
                atomic_write_bytes(stage / "images" / name / file_name, row["image"])
                width, height = row["camera"]["width"], row["camera"]["height"]
                lines = [
                    yolo_line(o["class_id"], o["box2d"], width, height) for o in row["objects"]
                ]
                label = stage / "labels" / name / f"{Path(file_name).stem}.txt"
                atomic_write_text(label, "".join(f"{line}\n" for line in lines))
                summary.images += 1
                summary.boxes += len(lines)
        # YAML by hand: JSON strings are YAML scalars, so no YAML library is needed
        text = [f"path: {json.dumps(str(Path(out).resolve()))}"]
        text += [f"{name}: images/{name}" for name in splits]
        text += ["names:"]
        text += [f"  {c.id}: {json.dumps(c.name)}" for c in ds.manifest.classes]
        atomic_write_text(stage / "data.yaml", "\n".join(text) + "\n")
    return summary
