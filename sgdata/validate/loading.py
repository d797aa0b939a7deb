"""Reading what the checks need once: the raw manifest and the tables of every split.

Tables are read without the ``image`` column (the image checks stream it per shard). A file
whose columns cannot be brought to the format's schema (a column missing, a type that does not
cast) is reported by the table checks and left out of the deeper checks.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc

from sgdata.dataset.reader import read_table
from sgdata.errors import DatasetError

__all__ = ["SplitTables", "Flat", "read_table_as", "flatten_list", "fixed_numpy", "column_numpy"]


@dataclass
class SplitTables:
    """One split's observation rows (all its shards, no images) and its triplet table."""

    split: str
    observations: pa.Table | None  # concatenated shards that could be read, in room order
    files: list[str]  # relative path per shard index
    file_index: np.ndarray  # (rows,) index into ``files`` per observation row
    file_row: np.ndarray  # (rows,) row within its shard
    triplets: pa.Table | None  # None when missing or unreadable
    triplets_file: str

    def where(self, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(file index, row in file) of concatenated observation rows."""
        return self.file_index[rows], self.file_row[rows]


def read_table_as(path: Path, schema: pa.Schema, *, skip: tuple[str, ...] = ()) -> pa.Table | str:
    """``path`` read and cast to ``schema`` (minus ``skip``); else why it cannot be (a column
    that does not cast is reported by the schema check too, a corrupt one only here)."""
    try:
        return read_table(
            path, schema, columns=[n for n in schema.names if n not in skip], cast=True
        )
    except DatasetError as exc:
        return str(exc).removeprefix(f"{path}: ")


def column_numpy(table: pa.Table | pa.StructArray, name: str, fill: Any = None) -> np.ndarray:
    """A column as numpy; nulls replaced by ``fill`` when given."""
    col = table.column(name) if isinstance(table, pa.Table) else pc.struct_field(table, name)
    if isinstance(col, pa.ChunkedArray):
        col = col.combine_chunks()
    if fill is not None:
        col = col.fill_null(fill)
    return col.to_numpy(zero_copy_only=False)


def fixed_numpy(array: pa.Array, size: int, dtype: type) -> tuple[np.ndarray, np.ndarray]:
    """A fixed_size_list array as ``(n, size)`` numpy (zeros where null) and its valid mask."""
    n = len(array)
    child = array.values.slice(array.offset * size, n * size)
    values = child.fill_null(0).to_numpy(zero_copy_only=False).astype(dtype, copy=False)
    valid = ~array.is_null().to_numpy(zero_copy_only=False)
    return values.reshape(n, size), valid


@dataclass
class Flat:
    """A list<struct> column flattened: ``parent[k]`` is the row of element ``k``."""

    parent: np.ndarray  # (E,) row index
    position: np.ndarray  # (E,) index of the element within its row's list
    values: pa.StructArray

    def get(self, name: str, fill: Any = None) -> np.ndarray:
        return column_numpy(self.values, name, fill)

    def fixed(self, name: str, size: int, dtype: type) -> tuple[np.ndarray, np.ndarray]:
        return fixed_numpy(pc.struct_field(self.values, name), size, dtype)


def flatten_list(table: pa.Table, name: str) -> Flat:
    """Flatten the list column ``name`` of ``table``."""
    col = table.column(name).combine_chunks()
    parent = pc.list_parent_indices(col).to_numpy(zero_copy_only=False).astype(np.int64)
    values = pc.list_flatten(col)
    if isinstance(values, pa.ChunkedArray):
        values = values.combine_chunks()
    lengths = pc.list_value_length(col).fill_null(0).to_numpy(zero_copy_only=False)
    starts = np.concatenate([[0], np.cumsum(lengths)[:-1]]).astype(np.int64)
    position = np.arange(len(parent), dtype=np.int64) - starts[parent] if len(parent) else parent
    return Flat(parent, position, values)
