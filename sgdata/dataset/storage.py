"""How image columns lie on disk versus in memory: Hugging Face ``Image`` storage since 2.0.0.

In memory (the schemas of :mod:`sgdata.dataset.schema`, what the writer builds and
:func:`~sgdata.dataset.reader.read_table` returns) an ``image`` cell is the encoded PNG/JPEG
bytes. On disk, since format 2.0.0, it is the storage of the ``datasets`` ``Image`` feature, a
struct ``{bytes, path}`` (path null), and the file's schema metadata carries the ``huggingface``
features entry, so ``datasets.load_dataset("parquet", ...)`` decodes it as a picture while
pyarrow, polars and DuckDB read ``image.bytes``. Format 1.x stored the bare bytes; both read
back the same here.
"""

from __future__ import annotations

import json
from collections.abc import Mapping

import pyarrow as pa
import pyarrow.compute as pc

from sgdata.errors import DatasetError

__all__ = [
    "HF_METADATA_KEY",
    "IMAGE_STORAGE",
    "IMAGE_STORAGE_SINCE",
    "file_table",
    "hf_schema_metadata",
    "image_bytes",
    "image_field_names",
    "is_image_field",
    "memory_column",
    "stored_image_field",
]

# The datasets ``Image`` feature's Arrow storage. Its fields are nullable and so is the column:
# ``datasets`` takes the metadata's feature only for a field equal to its own.
IMAGE_STORAGE = pa.struct([pa.field("bytes", pa.binary()), pa.field("path", pa.string())])
IMAGE_STORAGE_SINCE = "2.0.0"  # the format version that stores images as IMAGE_STORAGE
HF_METADATA_KEY = b"huggingface"  # the schema-metadata key datasets reads its features from
STORAGE_KEY = b"storage"  # field metadata naming a column's on-disk form (b"image")


def is_image_field(field: pa.Field) -> bool:
    """Whether ``field`` is an image column (DSL type ``image``)."""
    return (field.metadata or {}).get(STORAGE_KEY) == b"image"


def image_field_names(schema: pa.Schema) -> list[str]:
    """Names of the image columns of ``schema``."""
    return [f.name for f in schema if is_image_field(f)]


def stored_image_field(field: pa.Field) -> pa.Field:
    """The on-disk field of image column ``field`` (format 2.0.0 on)."""
    return pa.field(field.name, IMAGE_STORAGE, nullable=True, metadata=field.metadata)


def hf_schema_metadata(schema: pa.Schema) -> bytes:
    """The ``huggingface`` schema-metadata value: the ``Image`` feature of each image column.

    Only image columns are described: ``datasets`` infers the others from their Arrow types
    (lists of structs come back as lists of dicts), and features in the ``Value``/``Image``
    vocabulary alone read in every ``datasets`` release since 2.x.
    """
    features = {name: {"_type": "Image"} for name in image_field_names(schema)}
    return json.dumps({"info": {"features": features}}, sort_keys=True).encode()


def file_table(table: pa.Table) -> pa.Table:
    """``table`` as the current format writes it: image columns as :data:`IMAGE_STORAGE`
    (path null) and the ``huggingface`` metadata; a table without image columns as is, and
    one already in that form (read back with pyarrow) too."""
    names = [
        n for n in image_field_names(table.schema) if pa.types.is_binary(table.schema.field(n).type)
    ]
    if not names:
        return table
    fields, columns = [], []
    for field, column in zip(table.schema, table.columns, strict=True):
        if field.name in names:
            chunks = [
                pa.StructArray.from_arrays(
                    [chunk, pa.nulls(len(chunk), pa.string())],
                    fields=list(IMAGE_STORAGE),
                    mask=chunk.is_null(),
                )
                for chunk in column.chunks
            ]
            column = pa.chunked_array(chunks, type=IMAGE_STORAGE)
            field = stored_image_field(field)
        fields.append(field)
        columns.append(column)
    metadata = dict(table.schema.metadata or {})
    metadata[HF_METADATA_KEY] = hf_schema_metadata(table.schema)
    return pa.Table.from_arrays(columns, schema=pa.schema(fields, metadata=metadata))


def memory_column(column: pa.ChunkedArray, where: str) -> pa.ChunkedArray:
    """An image column as read from a file (either format) as encoded bytes.

    Raises:
        DatasetError: the column is neither binary nor ``{bytes, path}``; ``where`` names it.
    """
    if pa.types.is_binary(column.type):
        return column
    if pa.types.is_struct(column.type) and column.type.get_field_index("bytes") >= 0:
        field = column.type.field("bytes")
        if pa.types.is_binary(field.type):
            return pa.chunked_array(
                [pc.struct_field(chunk, "bytes") for chunk in column.chunks], type=pa.binary()
            )
    raise DatasetError(
        f"{where}: type {column.type}; expected the image struct {{bytes: binary, path: string}} "
        "(or binary, format 1.x)"
    )


def image_bytes(cell: bytes | Mapping[str, object] | None) -> bytes:
    """The encoded bytes of one image cell whatever its form: bytes (format 1.x, or a table from
    :func:`~sgdata.dataset.reader.read_table`) or a ``{"bytes", "path"}`` dict (2.x read with
    plain pyarrow).

    Raises:
        DatasetError: the cell holds no bytes.
    """
    data = cell.get("bytes") if isinstance(cell, Mapping) else cell
    if not isinstance(data, bytes | bytearray | memoryview):
        raise DatasetError(
            f"image cell {type(cell).__name__}: expected encoded bytes or a dict with 'bytes'"
        )
    return bytes(data)
