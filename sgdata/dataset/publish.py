"""Publishing a dataset's metadata: the card, ``croissant.json`` and ``dataset.json``, in that
order (the manifest lists the other two and is written last: no manifest = unfinished).

This module sits above :mod:`sgdata.dataset.manifest`, :mod:`sgdata.dataset.card` and
:mod:`sgdata.dataset.croissant`, so the manifest knows neither writer (no import circle).
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

from sgdata.dataset.card import write_card
from sgdata.dataset.croissant import write_croissant
from sgdata.dataset.manifest import META_FILES, Manifest, file_entry
from sgdata.dataset.paths import MANIFEST
from sgdata.fileio import atomic_write_text

__all__ = ["write_manifest"]


def write_manifest(manifest: Manifest, root: Path) -> Path:
    """The last step of every writer (generate, label export and import, migrate): the dataset
    card ``README.md`` and ``croissant.json`` from ``manifest``, then ``root/dataset.json``
    listing them too; each written atomically, the manifest last (no manifest = unfinished)."""
    root = Path(root)
    data = replace(manifest, files=tuple(f for f in manifest.files if f.path not in META_FILES))
    write_card(root, data)
    write_croissant(root, data)
    files = (*data.files, *(file_entry(root, name) for name in META_FILES))
    path = root / MANIFEST
    atomic_write_text(
        path, replace(data, files=tuple(sorted(files, key=lambda f: f.path))).to_json()
    )
    return path
