"""``sgdata migrate``: rewrite a dataset of an older format in the current one, in place.

Reading needs no migration (:func:`~sgdata.dataset.reader.read_table` reads 1.x files as they
are); migrating is for the tools that read the files with no sgdata code: ``datasets`` decodes
images only from the 2.x storage, and only 2.x has the card and ``croissant.json``. Each table
is read through the reader (1.x images, columns a later minor added as nulls) and written again
with :func:`~sgdata.dataset.rows.write_parquet`; the manifest is written last, so a run that
stops half way leaves a dataset that still reads, and running again finishes it. PNG images of
a dataset older than :data:`~sgdata.dataset.rows.PNG_STRATEGY_SINCE` are decoded and encoded
again as ``generate`` now encodes them (lossless: the same pixels); JPEGs are kept as they are.
Views of a dataset older than :data:`~sgdata.dataset.camera.CAMERA_SINCE` get their camera
columns derived from their pose columns, as ``generate`` now writes them. A dataset older than
:data:`~sgdata.dataset.channels.STRUCTURE_SINCE` that stores instance masks gets the structure
mask of those views, drawn again from their scene layers by the drawer the caller passes
(``sgdata migrate`` renders; this stage does not).
Every table is written with the current schema's metadata (its ``format_version``, name and
field docs): the reader keeps a file's own, which names the old version.
"""

from __future__ import annotations

import io
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
from PIL import Image

from sgdata.dataset.camera import CAMERA_SINCE, camera_columns
from sgdata.dataset.channels import STRUCTURE_SINCE, stored_channels
from sgdata.dataset.manifest import FileEntry, Manifest, read_manifest
from sgdata.dataset.paths import observations_path, triplets_path
from sgdata.dataset.publish import write_manifest
from sgdata.dataset.reader import read_table
from sgdata.dataset.rows import PNG_STRATEGY_SINCE, encode_image, write_parquet
from sgdata.dataset.schema import (
    FORMAT_VERSION,
    observations_schema,
    parse_version,
    triplets_schema,
)
from sgdata.errors import DatasetError

__all__ = ["StructureDrawer", "migrate_dataset"]

# (dataset root, observation table, the manifest's config) -> the encoded structure column
StructureDrawer = Callable[[Path, pa.Table, dict[str, Any]], pa.Array]


def migrate_dataset(root: str | Path, *, draw_structure: StructureDrawer | None = None) -> Manifest:
    """Bring the dataset at ``root`` to :data:`~sgdata.dataset.schema.FORMAT_VERSION`.

    Rewrites every observation and triplet table, then writes the card, ``croissant.json``
    and ``dataset.json`` (sizes and sha256 of the new files, the new ``format_version``). A
    current dataset gets its card and Croissant file written again and nothing else.

    Args:
        root: the dataset.
        draw_structure: ``(root, table, config) -> column``, the structure masks of a
            table's views drawn from their scene layers; needed only for a dataset older
            than :data:`~sgdata.dataset.channels.STRUCTURE_SINCE` that stores instance masks
            (``sgdata migrate`` passes :func:`sgdata.pipeline.structure_masks.structure_column`:
            this stage does not render).

    Returns:
        the manifest written.

    Raises:
        DatasetError: not a dataset, a format this sgdata cannot read, a table that does not
            read (the message names the file), or masks to draw and no ``draw_structure``.
    """
    root = Path(root)
    manifest = read_manifest(root)
    if manifest.format_version == FORMAT_VERSION:
        write_manifest(manifest, root)
        return read_manifest(root)
    tables = {
        observations_path(s, r): observations_schema()
        for s, rs in manifest.splits.items()
        for r in rs
    }
    tables |= {triplets_path(s): triplets_schema() for s in manifest.splits}
    old_png = parse_version(manifest.format_version) < parse_version(PNG_STRATEGY_SINCE)
    no_camera = parse_version(manifest.format_version) < parse_version(CAMERA_SINCE)
    no_structure = "instances" in stored_channels(manifest.config, manifest.format_version) and (
        parse_version(manifest.format_version) < parse_version(STRUCTURE_SINCE)
    )
    if no_structure and draw_structure is None:
        raise DatasetError(
            f"{root}: its instance masks need structure masks drawn from the scene layers "
            "(format 2.3.0); run `sgdata migrate`, which renders them"
        )
    files = []
    for entry in manifest.files:
        schema = tables.get(entry.path)
        if schema is not None:
            table = read_table(root / entry.path, schema)
            if old_png and "image" in table.column_names:
                table = _reencode_pngs(table, entry.path)
            if no_camera and "camera_to_world" in table.column_names:
                table = _with_cameras(table)
            if no_structure and draw_structure and "structure" in table.column_names:
                at = table.schema.get_field_index("structure")
                column = draw_structure(root, table, manifest.config)
                table = table.set_column(at, table.schema.field(at), column)
            table = _with_current_metadata(table, schema)
            info = write_parquet(table, root / entry.path)
            entry = FileEntry(entry.path, info.rows, info.sha256, info.bytes)
        files.append(entry)
    write_manifest(replace(manifest, format_version=FORMAT_VERSION, files=tuple(files)), root)
    return read_manifest(root)


def _with_current_metadata(table: pa.Table, schema: pa.Schema) -> pa.Table:
    """``table`` (read by :func:`read_table`, so of ``schema``'s columns and types) under the
    current schema's field and file metadata, not the old file's."""
    fields = [schema.field(n) for n in table.column_names]
    return pa.Table.from_arrays(table.columns, schema=pa.schema(fields, metadata=schema.metadata))


def _with_cameras(table: pa.Table) -> pa.Table:
    """The observation table with each view's camera derived from its pose columns (read
    from an older file, they came back null)."""
    intrinsics, poses = camera_columns(table)
    table = table.set_column(table.schema.get_field_index("intrinsics"), "intrinsics", intrinsics)
    at = table.schema.get_field_index("camera_to_world")
    return table.set_column(at, "camera_to_world", poses)


def _reencode_pngs(table: pa.Table, where: str) -> pa.Table:
    """The observation table with its PNG images encoded as ``generate`` encodes them now."""
    images = table.column("image").to_pylist()
    formats = table.column("image_format").to_pylist()
    out = []
    for data, fmt in zip(images, formats, strict=True):
        if fmt == "png":
            try:
                with Image.open(io.BytesIO(data)) as image:
                    data = encode_image(np.asarray(image.convert("RGB")), "png")
            except (OSError, ValueError, Image.DecompressionBombError) as exc:
                raise DatasetError(f"{where}: an image does not decode as PNG ({exc})") from None
        out.append(data)
    at = table.schema.get_field_index("image")
    return table.set_column(at, table.schema.field(at), pa.array(out, type=pa.binary()))
