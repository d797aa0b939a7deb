"""Reading a dataset directory: the manifest, the observation shards and the triplet tables.

Only pyarrow, numpy and Pillow: the PyTorch data loader builds on this. The files themselves
need no sgdata code at all (see docs/dataset.md for pyarrow, polars, DuckDB and ``datasets``).
"""

from __future__ import annotations

import hashlib
import io
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
from PIL import Image

from sgdata.dataset.manifest import Manifest, manifest_bytes, parse_manifest
from sgdata.dataset.paths import MANIFEST, observations_path, triplets_path
from sgdata.dataset.schema import FORMAT_VERSION, observations_schema, since, triplets_schema
from sgdata.dataset.storage import image_bytes, is_image_field, memory_column
from sgdata.errors import DatasetError, one_line
from sgdata.fileio import sha256_file

__all__ = ["Dataset", "decode_image", "read_table"]


def decode_image(data: bytes | Mapping[str, object]) -> np.ndarray:
    """An ``(H, W, 3)`` uint8 array from an ``image`` cell: encoded PNG or JPEG bytes, or the
    ``{"bytes", "path"}`` dict a format 2.x file gives plain pyarrow.

    Raises:
        DatasetError: the cell is not a readable image.
    """
    data = image_bytes(data)
    try:
        with Image.open(io.BytesIO(data)) as image:
            return np.asarray(image.convert("RGB"))
    except (OSError, ValueError) as exc:
        raise DatasetError(
            f"image bytes ({len(data)} B) are not a readable PNG/JPEG: {exc}"
        ) from None


def read_table(
    path: Path, schema: pa.Schema, *, columns: Sequence[str] | None = None, cast: bool = False
) -> pa.Table:
    """Read ``columns`` (default: every column of ``schema``) of one Parquet file of the format.

    The one reader of observation and triplet files: :class:`Dataset`, ``sgdata validate`` and
    the training loader all come through here. Columns the file has beyond the schema (a newer
    minor format) are not read; columns a later minor added (``since`` in the schema) that an
    older file lacks come back as nulls. Image columns come back as encoded bytes whether the
    file stores them as the ``{bytes, path}`` struct (2.x) or as bytes (1.x).

    Args:
        cast: cast columns whose type differs but converts (``validate`` reports the type
            separately); otherwise a differing column is an error.

    Raises:
        DatasetError: the file is missing, unreadable, lacks a column, holds a corrupt one
            (text that is not UTF-8), or a column differs from the schema (and does not cast,
            with ``cast``).
    """
    name = schema.metadata[b"name"].decode() if schema.metadata else "sgdata"
    if not path.is_file():
        raise DatasetError(
            f"{path}: listed by {MANIFEST} but missing; the dataset is incomplete "
            "(copy it again, or run sgdata generate --resume)"
        )
    names = list(schema.names if columns is None else columns)
    expected = pa.schema([schema.field(n) for n in names])
    try:
        found = pq.read_schema(path)
        absent = [n for n in names if n not in found.names]
        added = {n for n in absent if since(schema.field(n))}
        missing = [n for n in absent if n not in added]
        if missing:
            raise DatasetError(
                f"{path}: no column(s) {missing}; not a format {FORMAT_VERSION} {name} table"
            )
        table = pq.read_table(path, columns=[n for n in names if n not in added])
        for n, column in zip(table.column_names, table.columns, strict=True):
            try:  # Parquet reads text unchecked: a flipped byte is invalid UTF-8 much later
                column.validate(full=True)
            except pa.ArrowInvalid as exc:
                raise DatasetError(
                    f"{path}: column {n!r} is corrupt ({one_line(exc)}); copy the file again, "
                    "or regenerate the dataset"
                ) from None
        for n in names:
            if n not in added and is_image_field(schema.field(n)):
                at = table.schema.get_field_index(n)
                table = table.set_column(
                    at, expected.field(n), memory_column(table.column(at), f"{path}: column {n}")
                )
        if added:  # an older minor's file: the columns added since are null
            table = pa.Table.from_arrays(
                [
                    pa.nulls(table.num_rows, expected.field(n).type)
                    if n in added
                    else table.column(n)
                    for n in names
                ],
                schema=pa.schema(
                    [expected.field(n) if n in added else table.schema.field(n) for n in names],
                    metadata=table.schema.metadata,  # the file's: name, doc, format_version
                ),
            )
        if cast and not table.schema.equals(expected):
            table = table.cast(expected)
    except (pa.ArrowException, OSError, ValueError) as exc:
        raise DatasetError(
            f"{path}: not a readable Parquet file of {name} ({one_line(exc)})"
        ) from None
    if not table.schema.equals(expected):
        wrong = [f.name for f in table.schema if not f.equals(expected.field(f.name))]
        raise DatasetError(
            f"{path}: column(s) {wrong} differ from the format {FORMAT_VERSION} schema "
            "(see docs/dataset.md)"
        )
    return table


class Dataset:
    """An sgdata dataset on disk; open it with :meth:`Dataset.open`.

    Tables come back as ``pyarrow.Table`` with the schemas of :mod:`sgdata.dataset.schema`; convert
    with ``.to_pandas()`` or ``polars.from_arrow`` as needed.
    """

    def __init__(
        self, root: Path, manifest: Manifest, *, manifest_sha256: str | None = None
    ) -> None:
        self._root = Path(root)
        self._manifest = manifest
        self._manifest_sha256 = manifest_sha256

    @classmethod
    def open(cls, root: str | Path) -> Dataset:
        """Read and validate ``root/dataset.json`` (format version check included), once:
        the opened dataset holds the manifest and its sha256, so pass it on rather than the
        path (a function given the object reads nothing again).

        Raises:
            DatasetError: no manifest (unfinished generation or not a dataset), an invalid
                one, or one of a format this sgdata cannot read (``FormatVersionError``).
        """
        root = Path(root)
        if not root.is_dir():
            raise DatasetError(f"{root}: no such directory; expected an sgdata dataset root")
        raw = manifest_bytes(root)
        manifest = parse_manifest(raw, root / MANIFEST)
        return cls(root, manifest, manifest_sha256=hashlib.sha256(raw).hexdigest())

    def __repr__(self) -> str:
        m = self._manifest
        counts = ", ".join(f"{s}={n}" for s, n in m.counts.observations.items())
        return f"Dataset({str(self._root)!r}, name={m.name!r}, observations: {counts})"

    # ------------------------------------------------------------------ metadata

    @property
    def root(self) -> Path:
        """The dataset directory."""
        return self._root

    @property
    def manifest(self) -> Manifest:
        """The validated ``dataset.json``."""
        return self._manifest

    @property
    def manifest_sha256(self) -> str:
        """The sha256 of ``dataset.json`` as read at :meth:`open` (the data's fingerprint)."""
        if self._manifest_sha256 is None:  # made from a Manifest, not opened: the file's
            self._manifest_sha256 = sha256_file(self._root / MANIFEST)[0]
        return self._manifest_sha256

    @property
    def splits(self) -> list[str]:
        """Split names present, in train/val/test order."""
        return list(self._manifest.to_dict()["splits"])

    def rooms(self, split: str) -> list[str]:
        """Room ids of ``split`` in storage order."""
        return list(self._split(split))

    @property
    def class_names(self) -> list[str]:
        """Class names in id order (``objects[].class_id`` indexes this)."""
        return [c.name for c in self._manifest.classes]

    @property
    def slot_runs(self) -> dict[str, tuple[int, int]]:
        """Class name -> (first GCN slot, run length)."""
        return self._manifest.slot_runs

    @property
    def relation_types(self) -> list[str]:
        """Relation names (``relations[].type`` indexes this)."""
        return list(self._manifest.relation_types)

    def _split(self, split: str) -> tuple[str, ...]:
        try:
            return self._manifest.splits[split]
        except KeyError:
            raise DatasetError(
                f"split {split!r} is not in {self._root / MANIFEST}; "
                f"it holds: {', '.join(self.splits) or 'none'}"
            ) from None

    # ------------------------------------------------------------------ tables

    def observation_files(self, split: str) -> list[Path]:
        """The observation shards of ``split``, one per room, in manifest room order."""
        return [self._root / observations_path(split, room) for room in self._split(split)]

    def observations(self, split: str, *, columns: Sequence[str] | None = None) -> pa.Table:
        """All observation rows of ``split`` (its room shards concatenated in room order).

        Args:
            columns: read only these columns (e.g. leave out ``image`` for metadata scans).
        """
        schema = observations_schema()
        if columns is not None:
            unknown = [c for c in columns if c not in schema.names]
            if unknown:
                raise DatasetError(f"unknown observation columns {unknown}; known: {schema.names}")
        tables = [read_table(p, schema, columns=columns) for p in self.observation_files(split)]
        if not tables:
            names = schema.names if columns is None else list(columns)
            return pa.schema([schema.field(n) for n in names]).empty_table()
        return pa.concat_tables(tables)

    def triplets(self, split: str) -> pa.Table:
        """The triplets of ``split`` (``triplet_id`` is the row index)."""
        self._split(split)
        return read_table(self._root / triplets_path(split), triplets_schema())

    # ------------------------------------------------------------------ images and checks

    @staticmethod
    def read_image(data: bytes) -> np.ndarray:
        """Decode one ``image`` cell: see :func:`decode_image`."""
        return decode_image(data)

    def verify(self, *, checksums: bool = True) -> list[str]:
        """Problems with the files the manifest lists: missing, wrong size, wrong sha256.

        Returns an empty list for a sound dataset (nothing is raised).
        """
        problems = []
        for entry in self._manifest.files:
            path = self._root / entry.path
            if not path.is_file():
                problems.append(f"{entry.path}: missing")
                continue
            if path.stat().st_size != entry.bytes:
                problems.append(
                    f"{entry.path}: {path.stat().st_size} bytes, expected {entry.bytes}"
                )
            elif checksums and sha256_file(path)[0] != entry.sha256:
                problems.append(f"{entry.path}: sha256 differs from {MANIFEST}")
        return problems
