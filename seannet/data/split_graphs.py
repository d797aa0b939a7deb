"""The scene graphs of a whole split as flat numpy arrays, built once per reading process, and
the vectorised lookups that gather a batch's objects and adjacency cells from them."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
import pyarrow as pa

from seannet.data.view_inputs import struct_columns

__all__ = ["SplitGraphs", "flatten_lists", "offsets_of", "view_spans"]


def flatten_lists(
    column: pa.ChunkedArray, names: Sequence[str]
) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """A list<struct> column as (offsets (N+1,), {field: values}) numpy arrays."""
    lists = column.combine_chunks() if column.num_chunks != 1 else column.chunk(0)
    offsets = lists.offsets.to_numpy().astype(np.int64)
    values = struct_columns(lists.flatten(), names)
    return offsets - offsets[0], values


@dataclass
class SplitGraphs:
    """Every view's graph tensors of one split, concatenated in storage order (numpy).

    View v's objects are rows ``box_offsets[v]:[v + 1]`` of ``slots``, ``class_ids`` and
    ``boxes``; its adjacency cells columns ``edge_offsets[v]:[v + 1]`` of ``edges`` (3, E)
    [relation, row slot, column slot] and ``edge_weight`` (E,). A batch is gathered from
    them with a few vectorised takes (``seannet.data.datasets``'s view store), whatever its size.
    """

    box_offsets: np.ndarray
    slots: np.ndarray
    class_ids: np.ndarray
    boxes: np.ndarray  # (K, 4) float32: in the cached S x S frame with the cache, else as stored
    edge_offsets: np.ndarray
    edges: np.ndarray
    edge_weight: np.ndarray

    spans: np.ndarray = field(init=False)  # (N, 4): first object, objects, first cell, cells

    def __post_init__(self) -> None:
        b, e = self.box_offsets, self.edge_offsets
        self.spans = np.stack((b[:-1], np.diff(b), e[:-1], np.diff(e)), axis=1)


def offsets_of(counts: Sequence[int]) -> np.ndarray:
    """(N + 1,) int64 start offsets of N consecutive runs of ``counts`` items."""
    return np.concatenate(([0], np.cumsum(np.asarray(counts, dtype=np.int64))))


def view_spans(
    spans: np.ndarray, rows: np.ndarray, local: np.ndarray
) -> tuple[np.ndarray, np.ndarray, list[np.ndarray], list[np.ndarray]]:
    """The objects and the adjacency cells of views ``rows``, concatenated in row order.

    Args:
        spans: (N, 4) int64 per view: first object, object count, first cell, cell count.
        rows: (n,) the views.
        local: (n,) each row's view index within its batch.

    Returns:
        ``(box_offsets, edge_offsets, [object index, cell index], [object view, cell view])``:
        (n + 1,) offsets of each row's range in the concatenation, the (K,) and (E,) indices
        into the split's arrays, and the ``local`` view of each.
    """
    sp = spans[rows]
    out = np.zeros((len(rows) + 1, 2), dtype=np.int64)
    np.cumsum(sp[:, 1::2], axis=0, out=out[1:])
    index, owner = [], []
    for k in (0, 1):
        starts, counts = sp[:, 2 * k], sp[:, 2 * k + 1]
        index.append(np.arange(out[-1, k]) + (starts - out[:-1, k]).repeat(counts))
        owner.append(local.repeat(counts))
    return out[:, 0], out[:, 1], index, owner
