"""The per-view channels as loader arrays: metric depth, the instance, class and structure masks.

The datasets (:class:`~seannet.data.datasets.ObservationDataset`,
:class:`~seannet.data.datasets.TripletDataset`) read them when asked
(``channels=("depth", "instances")``) from the optional 16-bit PNG columns of
:mod:`sgdata.dataset.channels`, and hand them over resized to the image's ``S x S`` by nearest
neighbour (a mask's values are labels and a depth's zeros mean "no hit": neither may be
blended), one ``(S, S)`` array per view and channel:

- ``depth``: float32 metres along the camera axis, 0 where nothing was hit;
- ``instances``: int64, 0 background, k the k-th object of the row's ``objects`` list;
- ``classes``: int64, the objects' class mask derived from ``instances`` and the objects'
  class ids (:func:`sgdata.dataset.channels.class_mask`: class id + 1, 0 elsewhere);
- ``structure``: int64, the part of the room seen where no object is (1 wall, 2 floor,
  3 ceiling, 4 door; 0 elsewhere), stored since format 2.3.0. Ask for it beside ``classes``
  for the room's parts as classes too (``class_mask``'s ``structure`` argument).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from seannet.errors import DataError
from sgdata.dataset.channels import (
    CHANNELS,
    class_mask,
    decode_channel,
    depth_metres,
    stored_channels,
)
from sgdata.errors import DatasetError

__all__ = [
    "LOADER_CHANNELS",
    "check_loader_channels",
    "decode_view_channels",
    "empty_channels",
    "nearest_rows",
    "stored_columns",
]

LOADER_CHANNELS = ("depth", "instances", "classes", "structure")  # what a loader can be asked
# loader channel -> the column it is read from
_SOURCE = {
    "depth": "depth",
    "instances": "instances",
    "classes": "instances",
    "structure": "structure",
}
_DTYPES = {"depth": np.float32, "instances": np.int64, "classes": np.int64, "structure": np.int64}
_HOW = {  # how to make a dataset that stores a column
    "depth": "[outputs] depth = true",
    "instances": "[outputs] instances = true",
    "structure": "[outputs] instances = true (format 2.3.0 on; sgdata migrate an older one)",
}


def check_loader_channels(ds: Any, channels: Iterable[str], *, root: str | Path) -> tuple[str, ...]:
    """The channels asked of an opened dataset, checked against what it stores.

    Raises:
        DataError: an unknown or repeated channel name, or one the dataset does not store
            (a real labelled dataset stores none), naming the dataset and the channel.
    """
    names = tuple(channels)
    unknown = [c for c in names if c not in LOADER_CHANNELS]
    if unknown or len(set(names)) != len(names):
        raise DataError(
            f"channels {names}: expected distinct names among {', '.join(LOADER_CHANNELS)}"
        )
    stored = stored_channels(ds.manifest.config, ds.manifest.format_version)
    for name in names:
        column = _SOURCE[name]
        if column not in stored:
            raise DataError(
                f"dataset {root} ({ds.manifest.name}) has no {name} channel (a real labelled "
                f"dataset has none; generate one with {_HOW[column]}), or ask for "
                "no channels"
            )
    return names


def stored_columns(channels: Sequence[str]) -> tuple[str, ...]:
    """The observation columns the loader channels ``channels`` are read from, schema order."""
    wanted = {_SOURCE[c] for c in channels}
    return tuple(c for c in CHANNELS if c in wanted)


def nearest_rows(source: int, size: int) -> np.ndarray:
    """The source pixel each of ``size`` output pixels takes (nearest neighbour, pixel
    centres aligned: ``floor((i + 0.5) * source / size)``, Pillow's ``NEAREST``)."""
    at = ((np.arange(size, dtype=np.float64) + 0.5) * (source / size)).astype(np.int64)
    return np.minimum(at, source - 1)


def decode_view_channels(
    cells: dict[str, bytes | None],
    class_ids: np.ndarray,
    channels: Sequence[str],
    size: int,
    *,
    where: str,
) -> dict[str, np.ndarray]:
    """One row's channels ``channels`` as ``(size, size)`` arrays.

    Args:
        cells: stored column name -> the row's encoded PNG (None: the row has none).
        class_ids: the row's ``objects[].class_id``, in list order.
        channels: loader channel names (:data:`LOADER_CHANNELS`).
        size: the output side, the image transform's.
        where: names the row in errors.

    Raises:
        DataError: the row lacks a channel, a PNG does not decode, or the mask names an
            object the row does not list.
    """
    decoded: dict[str, np.ndarray] = {}
    for column in stored_columns(channels):
        data = cells.get(column)
        if data is None:
            raise DataError(f"{where}: no {column} in this row; the dataset stores it elsewhere")
        try:
            values = decode_channel(data, where=f"{where} {column}")
        except DatasetError as exc:
            raise DataError(str(exc)) from None
        h, w = values.shape
        decoded[column] = values[nearest_rows(h, size)[:, None], nearest_rows(w, size)[None, :]]
    out: dict[str, np.ndarray] = {}
    for name in channels:
        values = decoded[_SOURCE[name]]
        if name == "depth":
            out[name] = depth_metres(values)
        elif name == "classes":
            try:
                out[name] = class_mask(values, class_ids).astype(_DTYPES[name])
            except DatasetError as exc:
                raise DataError(f"{where}: {exc}") from None
        else:
            out[name] = values.astype(_DTYPES[name])
    return out


def empty_channels(channels: Sequence[str], n: int, size: int) -> dict[str, np.ndarray]:
    """Uninitialised ``(n, size, size)`` batch arrays for ``channels``, of their dtypes."""
    return {c: np.empty((n, size, size), dtype=_DTYPES[c]) for c in channels}
