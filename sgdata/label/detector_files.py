"""What the COCO and YOLO exports share: the format names, the staged output folder, the rows
they read and the image files they write.

An export is written into a hidden sibling folder and renamed into place only once complete,
so a failure (a bad row, a full disk, Ctrl-C) leaves no half-written output, and an existing
non-empty output folder is replaced only with ``force``.
"""

from __future__ import annotations

import shutil
import tempfile
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from sgdata.errors import ConfigError, DatasetError

__all__ = [
    "DETECTOR_FORMATS",
    "EXPORT_FORMATS",
    "check_format",
    "check_view_row",
    "export_splits",
    "image_file_name",
    "is_real",
    "staged_dir",
    "view_rows",
]

DETECTOR_FORMATS = ("coco", "yolo")  # exports to a folder, for detector trainers
EXPORT_FORMATS = ("coco", "labelstudio", "yolo")  # every `sgdata export FORMAT`
ROW_COLUMNS = ("obs_id", "split", "domain", "camera", "image", "image_format", "objects")


def check_format(fmt: str) -> str:
    """``fmt`` if it names an export format.

    Raises:
        ConfigError: an unknown format, naming the known ones.
    """
    if fmt not in EXPORT_FORMATS:
        raise ConfigError(f"export format {fmt!r}: expected one of {', '.join(EXPORT_FORMATS)}")
    return fmt


def image_file_name(obs_id: str, image_format: str) -> str:
    """The file name of a view's image: its obs id with ``/`` as ``__``, then .png or .jpg."""
    from sgdata.label.export import FILE_SEP

    return obs_id.replace("/", FILE_SEP) + (".jpg" if image_format == "jpeg" else ".png")


@contextmanager
def staged_dir(out: Path, *, force: bool) -> Iterator[Path]:
    """A fresh folder to write an export into; renamed to ``out`` when the block ends cleanly,
    removed on any error (``out`` then untouched).

    Raises:
        ConfigError: ``out`` is a file, or a non-empty folder and not ``force``; or its parent
            cannot be written.
    """
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise ConfigError(f"{out}: is a file; expected a folder to export into")
    if out.is_dir() and any(out.iterdir()) and not force:
        raise ConfigError(f"{out}: exists and is not empty; pick another -o or pass --force")
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        stage = Path(tempfile.mkdtemp(dir=out.parent, prefix=f".{out.name}.", suffix=".tmp"))
    except OSError as exc:
        raise ConfigError(f"{out.parent}: cannot write here ({exc.strerror})") from None
    try:
        yield stage
        if out.exists():
            shutil.rmtree(out)
        stage.rename(out)
    except BaseException:
        shutil.rmtree(stage, ignore_errors=True)
        raise


def view_rows(
    dataset: Any, splits: Sequence[str], extra: Sequence[str] = ()
) -> Iterator[dict[str, Any]]:
    """The rows of ``splits`` of an opened :class:`~sgdata.dataset.Dataset`, shard by shard,
    with the columns the exports need (images as encoded bytes) and ``extra``.

    Raises:
        DatasetError: a row the exports cannot write (:func:`check_view_row`).
    """
    from sgdata.dataset import observations_schema, read_table

    columns = [*ROW_COLUMNS, *extra]
    classes = len(dataset.manifest.classes)
    for split in splits:
        for shard in dataset.observation_files(split):
            for row in read_table(shard, observations_schema(), columns=columns).to_pylist():
                yield check_view_row(row, classes)


def check_view_row(row: dict[str, Any], classes: int) -> dict[str, Any]:
    """``row`` if the detector files can hold it: a camera of positive size, every object's
    class one of the ``classes`` of the vocabulary, its box ``[u1, v1, u2, v2]`` inside the
    image with ``u1 <= u2`` and ``v1 <= v2``, its visible pixels not negative.

    Raises:
        DatasetError: naming the view, the value and what was expected (``sgdata validate``
            reports the dataset's other problems).
    """
    width, height = row["camera"]["width"], row["camera"]["height"]
    where = f"view {row['obs_id']}"
    if width < 1 or height < 1:
        raise DatasetError(f"{where}: camera {width} x {height}; expected a positive size")
    for obj in row["objects"]:
        u1, v1, u2, v2 = obj["box2d"]
        if not 0 <= obj["class_id"] < classes:
            raise DatasetError(
                f"{where}: object {obj['instance']} of class id {obj['class_id']}; expected "
                f"0 to {classes - 1} (the manifest's classes)"
            )
        if not (0 <= u1 <= u2 <= width and 0 <= v1 <= v2 <= height):
            raise DatasetError(
                f"{where}: object {obj['instance']} box {[u1, v1, u2, v2]}; expected "
                f"[u1, v1, u2, v2] with 0 <= u1 <= u2 <= {width} and 0 <= v1 <= v2 <= {height}"
            )
        if obj["visible_pixels"] < 0:
            raise DatasetError(
                f"{where}: object {obj['instance']} has {obj['visible_pixels']} visible pixels; "
                "expected 0 or more"
            )
    return row


def export_splits(dataset: Any, split: str | None) -> list[str]:
    """The splits an export covers: all of the dataset's, or the one asked for.

    Raises:
        ConfigError: ``split`` is not one of the dataset's.
    """
    if split is None:
        return list(dataset.splits)
    if split not in dataset.splits:
        raise ConfigError(f"--split {split!r}: this dataset has {', '.join(dataset.splits)}")
    return [split]


def is_real(dataset: Any) -> bool:
    """Whether an opened dataset holds labelled photos (its rows' ``domain`` is ``real``):
    it has boxes but no depth or masks."""
    for split in dataset.splits:
        domains = dataset.observations(split, columns=["domain"]).column("domain").to_pylist()
        if domains:
            return domains[0] == "real"
    return False
