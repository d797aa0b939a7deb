"""``sgdata migrate``: rewrite a dataset of an older format (1.x) in the current one, in place.

Reading needs no migration (:func:`~sgdata.dataset.reader.read_table` reads 1.x files as they
are); migrating is for the tools that read the files with no sgdata code: ``datasets`` decodes
images only from the 2.x storage, and only 2.x has the card and ``croissant.json``. Each table
is read through the reader (1.x images, columns a later minor added as nulls) and written again
with :func:`~sgdata.dataset.rows.write_parquet`; the manifest is written last, so a run that
stops half way leaves a dataset that still reads, and running again finishes it.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

from sgdata.dataset.manifest import FileEntry, Manifest, read_manifest, write_manifest
from sgdata.dataset.paths import observations_path, triplets_path
from sgdata.dataset.reader import read_table
from sgdata.dataset.rows import write_parquet
from sgdata.dataset.schema import FORMAT_VERSION, observations_schema, triplets_schema

__all__ = ["migrate_dataset"]


def migrate_dataset(root: str | Path) -> Manifest:
    """Bring the dataset at ``root`` to :data:`~sgdata.dataset.schema.FORMAT_VERSION`.

    Rewrites every observation and triplet table, then writes the card, ``croissant.json``
    and ``dataset.json`` (sizes and sha256 of the new files, the new ``format_version``). A
    current dataset gets its card and Croissant file written again and nothing else.

    Returns:
        the manifest written.

    Raises:
        DatasetError: not a dataset, a format this sgdata cannot read, or a table that does not
            read (the message names the file).
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
    files = []
    for entry in manifest.files:
        schema = tables.get(entry.path)
        if schema is not None:
            info = write_parquet(read_table(root / entry.path, schema), root / entry.path)
            entry = FileEntry(entry.path, info.rows, info.sha256, info.bytes)
        files.append(entry)
    write_manifest(replace(manifest, format_version=FORMAT_VERSION, files=tuple(files)), root)
    return read_manifest(root)
