"""Label Studio JSON: its rectangles and relations read as :class:`ForeignPhoto`, and written.

Reading takes a Label Studio JSON export (a list of tasks; each task's first annotation that
was not cancelled): ``rectanglelabels`` results (``x, y, width, height`` in percent of
``original_width`` x ``original_height``) become boxes, ``relation`` results become relations
(``right``: from -> to, ``left``: to -> from, ``bi``: symmetric). Writing turns every row of a
dataset into a task with the same results, so that writing then reading keeps every box to the
pixel and every on / in / proximity relation.
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass
from pathlib import Path
from urllib.parse import quote

from sgdata.label.annotations import (
    FieldReader,
    ForeignBox,
    ForeignPhoto,
    ForeignRelation,
    image_name,
    read_json,
)

__all__ = ["LabelStudioSummary", "read_labelstudio", "export_labelstudio"]

FROM_NAME = "label"  # the <RectangleLabels name=...> of the labeling config (docs/labeling.md)
TO_NAME = "image"  # the <Image name=...>; also the task data key of the image
DIRECTIONS = ("right", "left", "bi")
POSE_KEYS = ("layout", "grid_i", "grid_j", "heading")
_EXPORTED_ID = re.compile(r"^o(\d{1,9})$")  # result ids written by export_labelstudio


def read_labelstudio(path: Path) -> tuple[list[ForeignPhoto], list[str]]:
    """The photos, boxes and relations of a Label Studio JSON export.

    A task's ``data`` may also carry ``room_id``, ``room_type`` and a pose (``layout``,
    ``grid_i``, ``grid_j``, ``heading``), as :func:`export_labelstudio` writes them.

    Returns:
        ``(photos, notes)``: one record per task, and what was skipped.

    Raises:
        AnnotationFormatError: a missing or mistyped field, named with its task and result.
    """
    f = FieldReader(Path(path))
    tasks = read_json(path)
    tasks = [tasks] if isinstance(tasks, dict) else f.items(tasks, "top level")
    photos, notes = [], []
    skipped, next_id = 0, 0  # ids of boxes without sgdata's o<instance> ids run across tasks
    for t, task in enumerate(tasks):
        where = f"[{t}]"
        task = f.obj(task, where)
        data = f.get(task, "data", where, "object")
        photo = ForeignPhoto(
            image_name(_image_ref(f, data, f"{where}.data")), None, None, f"{path}: {where}"
        )
        _read_meta(f, data, f"{where}.data", photo)
        annotations = f.get(task, "annotations", where, "list", default=[])
        chosen = [
            (k, a)
            for k, a in enumerate(annotations)
            if not f.obj(a, f"{where}.annotations[{k}]").get("was_cancelled", False)
        ]
        if len(chosen) > 1:
            notes.append(f"task {where}: {len(chosen)} annotations; read the first")
        if chosen:
            k, annotation = chosen[0]
            more, next_id = _read_results(
                f, annotation, f"{where}.annotations[{k}]", photo, next_id
            )
            skipped += more
        photos.append(photo)
    if skipped:
        notes.append(
            f"skipped {skipped} Label Studio result(s) that are not rectangles or relations"
        )
    return photos, notes


def _image_ref(f: FieldReader, data: dict, where: str) -> str:
    if TO_NAME in data:
        return f.get(data, TO_NAME, where, "str")
    texts = [v for v in data.values() if isinstance(v, str)]
    if len(texts) != 1:
        raise f.fail(f"{where}.{TO_NAME}", "the image of the task")
    return texts[0]


def _read_meta(f: FieldReader, data: dict, where: str, photo: ForeignPhoto) -> None:
    photo.room_id = f.get(data, "room_id", where, "str", default=None)
    photo.room_type = f.get(data, "room_type", where, "str", default=None)
    pose = {k: f.get(data, k, where, "int", default=None) for k in POSE_KEYS}
    if any(pose[k] is not None for k in POSE_KEYS[1:]):
        if any(pose[k] is None for k in POSE_KEYS[1:]):
            raise f.fail(where, "grid_i, grid_j and heading all set or all null")
        photo.pose = {
            "layout": pose["layout"] or 0,
            "i": pose["grid_i"],
            "j": pose["grid_j"],
            "heading": pose["heading"],
        }


def _read_results(
    f: FieldReader, annotation: dict, where: str, photo: ForeignPhoto, next_id: int
) -> tuple[int, int]:
    """Boxes and relations of one annotation into ``photo``, new box ids from ``next_id``;
    returns how many results were skipped, and the next free id."""
    results = f.get(annotation, "result", where, "list")
    rects, relations, skipped = [], [], 0
    for k, result in enumerate(results):
        at = f"{where}.result[{k}]"
        result = f.obj(result, at)
        kind = f.get(result, "type", at, "str")
        if kind == "rectanglelabels":
            rects.append((at, result))
        elif kind == "relation":
            relations.append((at, result))
        else:
            skipped += 1
    matches = [_EXPORTED_ID.match(str(r.get("id", ""))) for _, r in rects]
    reuse = all(matches) and len({m.group(1) for m in matches}) == len(matches)
    ids: dict[str, int] = {}
    for n, (at, result) in enumerate(rects):
        rid = f.get(result, "id", at, "str")
        if rid in ids:
            raise f.fail(f"{at}.id", f"an id no other result has, not {rid!r} again")
        ids[rid] = int(matches[n].group(1)) if reuse else next_id + n
        photo.boxes.append(_rectangle(f, result, at, ids[rid], photo))
    for at, result in relations:
        ends = []
        for key in ("from_id", "to_id"):
            rid = f.get(result, key, at, "str")
            if rid not in ids:
                raise f.fail(f"{at}.{key}", f"the id of a rectangle result, not {rid!r}")
            ends.append(ids[rid])
        direction = f.get(result, "direction", at, "str", default="right")
        if direction not in DIRECTIONS:
            raise f.fail(f"{at}.direction", f"one of {', '.join(DIRECTIONS)}, not {direction!r}")
        labels = f.get(result, "labels", at, "list", default=[])
        if len(labels) > 1 or not all(isinstance(v, str) for v in labels):
            raise f.fail(f"{at}.labels", "at most one relation label")
        src, dst = ends if direction != "left" else ends[::-1]
        label = labels[0] if labels else ""
        photo.relations.append(ForeignRelation(src, dst, label, direction == "bi", at))
    return skipped, next_id + (0 if reuse else len(rects))


def _rectangle(f: FieldReader, result: dict, at: str, oid: int, photo: ForeignPhoto) -> ForeignBox:
    width, height = f.size(result, at, ("original_width", "original_height"))
    if width is None or height is None:
        raise f.fail(at, "original_width and original_height (the photo's size)")
    if photo.width is None:
        photo.width, photo.height = width, height
    elif (photo.width, photo.height) != (width, height):
        raise f.fail(
            at,
            f"the size {photo.width}x{photo.height} of the task's other results, "
            f"not {width}x{height}",
        )
    value = f.get(result, "value", at, "object")
    x, y, w, h = (f.get(value, k, f"{at}.value", "number") for k in ("x", "y", "width", "height"))
    if f.get(value, "rotation", f"{at}.value", "number", default=0):
        raise f.fail(f"{at}.value.rotation", "0 (rotated rectangles are not boxes)")
    labels = f.get(value, "rectanglelabels", f"{at}.value", "list")
    if len(labels) > 1 or not all(isinstance(v, str) for v in labels):
        raise f.fail(f"{at}.value.rectanglelabels", "one class label")
    box = f.box(
        x * width / 100,
        y * height / 100,
        (x + w) * width / 100,
        (y + h) * height / 100,
        (width, height),
        f"{at}.value",
    )
    return ForeignBox(oid, labels[0] if labels else "", box, at)


# ---------------------------------------------------------------------------------- writing


@dataclass
class LabelStudioSummary:
    """What :func:`export_labelstudio` wrote."""

    path: Path
    images: Path
    tasks: int = 0
    boxes: int = 0
    relations: int = 0


def export_labelstudio(
    dataset_dir: Path, out_file: Path, *, images_dir: Path | None = None
) -> LabelStudioSummary:
    """Write every observation of a dataset as a Label Studio task, and its image as a file.

    Boxes become ``rectanglelabels`` results (ids ``o<instance>``, percent of the image size),
    ``on`` / ``in`` relations ``right`` relations, ``proximity`` (stored both ways) one ``bi``
    relation; ``disjoint`` is left out (it is every other pair). The task data names the image
    file (``<obs_id with / as __>.png|.jpg`` in ``images_dir``, default ``<out stem>_images``
    beside ``out_file``) and carries the row's room, room type, split and pose.

    Raises:
        DatasetError: ``dataset_dir`` is not a readable dataset.
    """
    from sgdata.dataset import Dataset, observations_schema, read_table
    from sgdata.fileio import atomic_write_bytes, atomic_write_text, prepare_output_dir
    from sgdata.label.export import FILE_SEP
    from sgdata.label.proposals import RELATION_NAMES

    out_file = Path(out_file)
    images_dir = Path(images_dir or out_file.parent / f"{out_file.stem}_images")
    ds = Dataset.open(dataset_dir)
    prepare_output_dir(images_dir)
    summary = LabelStudioSummary(out_file, images_dir)
    columns = [
        "obs_id",
        "room_id",
        "room_type",
        "split",
        *POSE_KEYS,
        "camera",
        "image",
        "image_format",
        "objects",
        "relations",
    ]
    tasks = []
    for split in ds.splits:
        for shard in ds.observation_files(split):
            for row in read_table(shard, observations_schema(), columns=columns).to_pylist():
                name = row["obs_id"].replace("/", FILE_SEP) + (
                    ".jpg" if row["image_format"] == "jpeg" else ".png"
                )
                atomic_write_bytes(images_dir / name, row["image"])
                width, height = row["camera"]["width"], row["camera"]["height"]
                result = [_box_result(o, width, height) for o in row["objects"]]
                summary.boxes += len(result)
                for r in row["relations"]:
                    kind = RELATION_NAMES[r["type"]]
                    if kind in ("on", "in") or (kind == "proximity" and r["src"] < r["dst"]):
                        result.append(
                            {
                                "type": "relation",
                                "from_id": f"o{r['src']}",
                                "to_id": f"o{r['dst']}",
                                "direction": "bi" if kind == "proximity" else "right",
                                "labels": [kind],
                            }
                        )
                        summary.relations += 1
                # a reference, as Label Studio gives it: '#', '?', '%' must not end the path
                data = {TO_NAME: quote(name), **{k: row[k] for k in columns[:8]}}
                tasks.append(
                    {
                        "id": len(tasks) + 1,
                        "data": data,
                        "annotations": [{"result": result, "was_cancelled": False}],
                    }
                )
    summary.tasks = len(tasks)
    atomic_write_text(out_file, json.dumps(tasks, indent=1, ensure_ascii=False) + "\n")
    return summary


def _box_result(obj: dict, width: int, height: int) -> dict:
    u1, v1, u2, v2 = obj["box2d"]
    return {
        "id": f"o{obj['instance']}",
        "type": "rectanglelabels",
        "from_name": FROM_NAME,
        "to_name": TO_NAME,
        "original_width": width,
        "original_height": height,
        "image_rotation": 0,
        "value": {
            "x": 100 * u1 / width,
            "y": 100 * v1 / height,
            "width": 100 * (u2 - u1) / width,
            "height": 100 * (v2 - v1) / height,
            "rotation": 0,
            "rectanglelabels": [obj["class_name"]],
        },
    }
