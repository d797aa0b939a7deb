"""Readers of COCO and LabelMe files: their rectangles as :class:`ForeignPhoto` records."""

from __future__ import annotations

from pathlib import Path

from sgdata.label.annotations import (
    AnnotationFormatError,
    FieldReader,
    ForeignBox,
    ForeignPhoto,
    image_name,
    read_json,
)

__all__ = ["read_coco", "read_labelme"]


def read_coco(path: Path) -> tuple[list[ForeignPhoto], list[str]]:
    """The photos and boxes of a COCO detection file (``images``, ``annotations``,
    ``categories``; ``bbox`` is x, y, width, height in pixels). COCO has no relations.

    Returns:
        ``(photos, notes)``: one record per image entry, in file order, and what was skipped.

    Raises:
        AnnotationFormatError: a missing or mistyped field, named with its index.
    """
    f = FieldReader(Path(path))
    root = f.obj(read_json(path), "top level")
    categories = {}
    for k, cat in enumerate(f.get(root, "categories", "top level", "list")):
        where = f"categories[{k}]"
        cat = f.obj(cat, where)
        categories[f.get(cat, "id", where, "int")] = f.get(cat, "name", where, "str")
    photos: dict[int, ForeignPhoto] = {}
    for k, image in enumerate(f.get(root, "images", "top level", "list")):
        where = f"images[{k}]"
        image = f.obj(image, where)
        image_id = f.get(image, "id", where, "int")
        if image_id in photos:
            raise f.fail(f"{where}.id", f"an id no other image has, not {image_id} again")
        name = image_name(f.get(image, "file_name", where, "str"))
        width, height = f.size(image, where, ("width", "height"))
        photos[image_id] = ForeignPhoto(name, width, height, f"{path}: {where}")
    notes = []
    # Box ids run across the file: it says nothing of which boxes of two photos are one
    # object, and an id is one object of a room (one class).
    next_id = 0
    for k, ann in enumerate(f.get(root, "annotations", "top level", "list")):
        where = f"annotations[{k}]"
        ann = f.obj(ann, where)
        photo = photos.get(f.get(ann, "image_id", where, "int"))
        if photo is None:
            raise f.fail(f"{where}.image_id", "the id of an entry of images")
        category = f.get(ann, "category_id", where, "int")
        if category not in categories:
            raise f.fail(f"{where}.category_id", "the id of an entry of categories")
        bbox = f.get(ann, "bbox", where, "list")
        if len(bbox) != 4 or not all(
            isinstance(v, int | float) and not isinstance(v, bool) for v in bbox
        ):
            raise f.fail(f"{where}.bbox", "[x, y, width, height] numbers")
        x, y, w, h = bbox
        box = f.box(x, y, x + w, y + h, (photo.width, photo.height), f"{where}.bbox")
        photo.boxes.append(ForeignBox(next_id, categories[category], box, where))
        next_id += 1
    return list(photos.values()), notes


def read_labelme(path: Path) -> tuple[list[ForeignPhoto], list[str]]:
    """The rectangles of a LabelMe file, or of every ``*.json`` file of a directory.

    Shapes whose ``shape_type`` is not ``rectangle`` are skipped and counted in the notes.

    Raises:
        AnnotationFormatError: a missing or mistyped field, named with its file and index.
    """
    path = Path(path)
    files = sorted(path.glob("*.json")) if path.is_dir() else [path]
    if not files:
        raise AnnotationFormatError(f"{path}: no LabelMe *.json files in this directory")
    photos, skipped = [], 0
    next_id = 0  # box ids run across the files, as in read_coco
    for file in files:
        f = FieldReader(file)
        root = f.obj(read_json(file), "top level")
        name = image_name(f.get(root, "imagePath", "top level", "str"))
        width, height = f.size(root, "top level", ("imageWidth", "imageHeight"))
        photo = ForeignPhoto(name, width, height, f"{file}")
        for k, shape in enumerate(f.get(root, "shapes", "top level", "list")):
            where = f"shapes[{k}]"
            shape = f.obj(shape, where)
            if f.get(shape, "shape_type", where, "str", default="polygon") != "rectangle":
                skipped += 1
                continue
            points = f.get(shape, "points", where, "list")
            if len(points) != 2 or not all(
                isinstance(p, list)
                and len(p) == 2
                and all(isinstance(v, int | float) and not isinstance(v, bool) for v in p)
                for p in points
            ):
                raise f.fail(f"{where}.points", "two [x, y] corner points")
            (x1, y1), (x2, y2) = points
            box = f.box(min(x1, x2), min(y1, y2), max(x1, x2), max(y1, y2), (width, height), where)
            label = f.get(shape, "label", where, "str")
            photo.boxes.append(ForeignBox(next_id, label, box, where))
            next_id += 1
        photos.append(photo)
    notes = [f"skipped {skipped} LabelMe shape(s) that are not rectangles"] if skipped else []
    return photos, notes
