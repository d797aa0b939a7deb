"""Opening a dataset once: the handle a command passes down, and the identity a checkpoint
stores.

The handle is sgdata's :class:`~sgdata.dataset.Dataset`: opening it reads ``dataset.json``
once and keeps the manifest (classes, slots, splits) and its sha256. A command opens its
dataset at the top with :func:`open_dataset` and hands the object to everything below it;
:func:`open_dataset` given an object already opened returns it as it is, so a public function
that accepts a path or a handle opens at most once (STYLE.md habit 15).
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Any

from seannet.errors import DataError
from sgdata.dataset import Dataset
from sgdata.errors import DatasetError, one_line

__all__ = ["DataSource", "dataset_identity", "open_dataset"]

# What a public function accepts as its data: a dataset root, or a dataset opened already.
DataSource = str | Path | Dataset


def open_dataset(data: DataSource) -> Dataset:
    """``data`` opened (:meth:`sgdata.dataset.Dataset.open`), or ``data`` itself when it is an
    opened dataset already (nothing is read again).

    Raises:
        DataError: ``data`` is missing, not an sgdata dataset, or of an unreadable format
            (one line).
    """
    if isinstance(data, Dataset):
        return data
    try:
        return Dataset.open(data)
    except DatasetError as exc:
        raise DataError(one_line(f"dataset {data}: {exc}")) from None


def dataset_identity(data: DataSource) -> dict[str, Any]:
    """What a model trained on this dataset depends on; checkpoints store it to refuse others.

    Computed from the opened dataset's manifest (no file is read for a handle).

    Returns:
        ``{"name", "version", "format_version", "num_slots", "vocabulary_sha256"}``; the hash
        covers the class vocabulary in id order with each class's slot run (name, id,
        slot_start, slot_count) and the relation type names, as canonical JSON.

    Raises:
        DataError: ``data`` is not a readable dataset.
    """
    m = open_dataset(data).manifest
    vocabulary = {
        "classes": [[c.name, c.id, c.slot_start, c.slot_count] for c in m.classes],
        "relation_types": list(m.relation_types),
    }
    text = json.dumps(vocabulary, separators=(",", ":"), sort_keys=True)
    return {
        "name": m.name,
        "version": m.version,
        "format_version": m.format_version,
        "num_slots": int(m.num_slots),
        "vocabulary_sha256": hashlib.sha256(text.encode()).hexdigest(),
    }
