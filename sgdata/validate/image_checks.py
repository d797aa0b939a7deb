"""Image checks: every ``image`` cell decodes as its ``image_format`` at the row's camera size."""

from __future__ import annotations

import io
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
from PIL import Image

from sgdata.dataset.schema import observations_schema
from sgdata.dataset.storage import memory_column
from sgdata.errors import DatasetError
from sgdata.validate.problems import Collector

__all__ = ["check_images", "inspect_image"]

_PIL_FORMAT = {"png": "PNG", "jpeg": "JPEG"}


def inspect_image(data: bytes | None, fmt: str, width: int, height: int) -> list[tuple[str, str]]:
    """``(check, message)`` for each problem of one encoded image (empty when sound)."""
    if not data:
        return [("images.decode", "empty image bytes")]
    try:
        with Image.open(io.BytesIO(data)) as image:
            found = image.format
            size = image.size
            image.load()  # decode every byte: truncated data fails here
    except (OSError, ValueError, Image.DecompressionBombError) as exc:
        return [("images.decode", f"{len(data)} bytes are not a readable image ({exc})")]
    out = []
    if found != _PIL_FORMAT.get(fmt):
        out.append(("images.decode", f"encoded as {found}; image_format says {fmt}"))
    if size != (width, height):
        out.append(("images.size", f"{size[0]}x{size[1]} pixels; camera says {width}x{height}"))
    return out


def check_images(root: Path, files: list[str], out: Collector, *, workers: int = 8) -> None:
    """Decode every image of the given observation shards (Pillow releases the GIL)."""
    columns = ["image", "image_format", "camera"]
    with ThreadPoolExecutor(max_workers=workers) as pool:
        for rel in files:
            try:
                table = pq.read_table(root / rel, columns=columns)
            except (pa.ArrowException, OSError, ValueError):
                continue  # reported by the table checks
            expected = observations_schema()
            # image is checked by memory_column below (stored as a struct in 2.x, bytes in 1.x)
            if any(
                not table.schema.field(c).type.equals(expected.field(c).type) for c in columns[1:]
            ):
                continue  # a column of another type: reported by the table checks
            camera = table.column("camera").combine_chunks()
            width = camera.field("width").to_numpy(zero_copy_only=False).astype(np.int64)
            height = camera.field("height").to_numpy(zero_copy_only=False).astype(np.int64)
            try:  # the {bytes, path} struct (2.x) or bytes (1.x)
                images = memory_column(table.column("image"), f"{rel}: column image").to_pylist()
            except DatasetError:
                continue  # the wrong type is reported by the table checks
            formats = table.column("image_format").to_pylist()
            jobs = zip(images, formats, width.tolist(), height.tolist(), strict=True)
            results = pool.map(lambda job: inspect_image(*job), jobs)
            out.count("images.decode", table.num_rows)
            out.count("images.size", table.num_rows)
            for row, problems in enumerate(results):
                for check, message in problems:
                    out.add(check, rel, message, row=row, field="image")
