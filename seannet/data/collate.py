"""Dataset items and their collation into :class:`~seannet.data.batch.SceneBatch` objects.

A view travels from the datasets to the model in the compact form of ``SceneBatch``: its
pixels as the uint8 the image cache (or the PNG decoder and the resize) gives, its adjacency
as the sparse edge list :func:`~seannet.data.view_inputs.graph_from_columns` gives. The models
normalise on their own device (``SceneBatch.prepare``; SeanNet's GCN reads the edges as they
are), so the loader does no float work and copies each view's pixels once.

The datasets read a whole batch at once (``__getitems__``, which ``DataLoader`` calls): they
gather its views straight into one :class:`ViewArrays`, and hand it over as a
:class:`TripletItems` or :class:`ObservationItems` that the collate functions turn into
batches without copying pixels again. Lists of single items (``dataset[i]``, or views built
elsewhere, as :mod:`seannet.data.live_views` does) collate to the same batches.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, overload

import numpy as np
import torch
from torch import Tensor

from seannet.data.batch import NUM_RELATIONS, SceneBatch
from seannet.data.view_inputs import dense_adjacency
from seannet.errors import DataError

__all__ = [
    "ObservationItem",
    "ObservationItems",
    "TripletItem",
    "TripletItems",
    "ViewArrays",
    "ViewTensors",
    "collate_triplets",
    "collate_views",
]

Triple = tuple[float, float, float]


@dataclass
class ViewTensors:
    """One view ready for the model (see :class:`~seannet.data.batch.SceneBatch` for the meaning).

    Attributes:
        image: (3, S, S) uint8 pixels, resized (any strides: a channels-last view of the
            (S, S, 3) pixels is what the datasets give).
        boxes: (K, 4) float32 pixel boxes in the S x S frame.
        class_ids: (K,) long.
        slots: (K,) long.
        edge_index: (3, E) long, [relation, src slot, dst slot] of each non-zero adjacency
            cell (relation 0 on, 1 in, 2 proximity).
        edge_weight: (E,) float32, the row-normalised value of each cell.
        num_slots: M.
        mean: per-channel mean (RGB, [0, 1] scale) the model's input is normalised with.
        std: per-channel std, as ``mean``.
        channels: the view's channels asked of the dataset (:mod:`seannet.data.view_channels`),
            name -> (S, S) tensor: ``depth`` float32 metres, ``instances`` and ``classes``
            int64; empty unless asked for.

    The adjacency travels sparse (a dense one is 3 x M x M floats, 786 KB at M = 256) and is
    made dense on the model's device; :attr:`adjacency` gives it per view.
    """

    image: Tensor
    boxes: Tensor
    class_ids: Tensor
    slots: Tensor
    edge_index: Tensor
    edge_weight: Tensor
    num_slots: int
    mean: Triple
    std: Triple
    channels: dict[str, Tensor] = field(default_factory=dict)

    @property
    def adjacency(self) -> Tensor:
        """(3, M, M) float32, row-normalised on / in / proximity (absent nodes: zero rows)."""
        return dense_adjacency(self.edge_index, self.edge_weight, self.num_slots)


@dataclass
class TripletItem:
    """One training triplet: three views of one room, its cascade tier and its ids."""

    anchor: ViewTensors
    positive: ViewTensors
    negative: ViewTensors
    tier: int  # cascade tier 0..4
    triplet_id: int  # row of triplets/<split>.parquet
    room_id: str
    ids: tuple[str, str, str]  # obs ids of anchor, positive, negative


@dataclass
class ObservationItem:
    """One view of a split with its pose metadata (nullable fields are None for real photos)."""

    view: ViewTensors
    obs_id: str
    room_id: str
    layout: int
    grid_i: int | None
    grid_j: int | None
    heading: int | None


# ---------------------------------------------------------------------------------- gathered


@dataclass
class ViewArrays:
    """n views gathered into batch arrays: objects and edges concatenated in view order.

    The views form consecutive blocks of ``block`` views, one :class:`SceneBatch` each
    (:meth:`batch`): a triplet batch's anchors, then its positives, then its negatives.

    Attributes:
        pixels: (n, S, S, 3) uint8.
        boxes: (K, 4) float32, in the S x S frame.
        class_ids: (K,) int64.
        slots: (K,) int64.
        box_view: (K,) int64, the view of each object, counted within its block.
        box_offsets: (n + 1,) int64, view k's objects are rows ``box_offsets[k]:[k + 1]``.
        edges: (4, E) int64, [view (within its block), relation, row slot, column slot] of
            each adjacency cell.
        edge_weight: (E,) float32.
        edge_offsets: (n + 1,) int64, view k's cells are columns ``edge_offsets[k]:[k + 1]``.
        num_slots: M.
        mean: the normalisation of the views' transform (as :class:`ViewTensors`).
        std: as ``mean``.
        block: views per batch (n for a single batch).
        in_range: the edges are known to lie in range (the datasets gather them from
            :func:`~seannet.data.view_inputs.graph_from_columns`, which checks): :meth:`batch`
            skips torch's check of the sparse indices.
        channels: name -> (n, S, S) array of each channel asked of the dataset (as
            :class:`ViewTensors`); empty unless asked for.
    """

    pixels: np.ndarray
    boxes: np.ndarray
    class_ids: np.ndarray
    slots: np.ndarray
    box_view: np.ndarray
    box_offsets: np.ndarray
    edges: np.ndarray
    edge_weight: np.ndarray
    edge_offsets: np.ndarray
    num_slots: int
    mean: Triple
    std: Triple
    block: int
    in_range: bool = False
    channels: dict[str, np.ndarray] = field(default_factory=dict)

    def __len__(self) -> int:
        return self.pixels.shape[0]

    @classmethod
    def from_views(cls, views: Sequence[ViewTensors], *, block: int | None = None) -> ViewArrays:
        """Views built one by one, gathered (their pixels copied once, here), in blocks of
        ``block`` views (default: one block).

        Raises:
            DataError: no views, or views of different M, image size or normalisation.
        """
        if not views:
            raise DataError("no views to batch; expected at least one")
        first = views[0]
        for name in ("num_slots", "mean", "std"):
            found = {tuple(np.ravel(getattr(v, name)).tolist()) for v in views}
            if len(found) > 1:
                raise DataError(f"views with {name} {sorted(found)} in one batch; expected one")
        sizes = {tuple(v.image.shape) for v in views}
        if len(sizes) > 1 or any(v.image.dtype != torch.uint8 for v in views):
            raise DataError(f"view images {sorted(sizes)}; expected one (3, S, S) uint8 size")
        names = {tuple(v.channels) for v in views}
        if len(names) > 1:
            raise DataError(f"views with channels {sorted(names)} in one batch; expected one")
        n = len(views)
        block = n if block is None else block
        if block < 1 or n % block:
            raise DataError(f"{n} views in blocks of {block}; expected a divisor of {n}")
        local = np.arange(n, dtype=np.int64) % block
        objects = np.asarray([v.boxes.reshape(-1, 4).shape[0] for v in views], dtype=np.int64)
        cells = np.asarray([v.edge_weight.shape[0] for v in views], dtype=np.int64)
        edges = torch.cat([v.edge_index.reshape(3, -1) for v in views], dim=1).numpy()
        return cls(
            pixels=torch.stack([v.image.permute(1, 2, 0) for v in views]).numpy(),
            boxes=torch.cat([v.boxes.reshape(-1, 4) for v in views]).numpy(),
            class_ids=torch.cat([v.class_ids for v in views]).numpy(),
            slots=torch.cat([v.slots for v in views]).numpy(),
            box_view=np.repeat(local, objects),
            box_offsets=np.concatenate(([0], np.cumsum(objects))),
            edges=np.concatenate((np.repeat(local, cells)[None], edges)),
            edge_weight=torch.cat([v.edge_weight for v in views]).numpy(),
            edge_offsets=np.concatenate(([0], np.cumsum(cells))),
            num_slots=first.num_slots,
            mean=first.mean,
            std=first.std,
            block=block,
            channels={
                c: torch.stack([v.channels[c] for v in views]).numpy() for c in first.channels
            },
        )

    def view(self, k: int) -> ViewTensors:
        """View ``k`` as :class:`ViewTensors` (sharing this object's memory)."""
        k0, k1 = self.box_offsets[k], self.box_offsets[k + 1]
        e0, e1 = self.edge_offsets[k], self.edge_offsets[k + 1]
        return ViewTensors(
            image=torch.from_numpy(self.pixels[k]).permute(2, 0, 1),
            boxes=torch.from_numpy(self.boxes[k0:k1]),
            class_ids=torch.from_numpy(self.class_ids[k0:k1]),
            slots=torch.from_numpy(self.slots[k0:k1]),
            edge_index=torch.from_numpy(self.edges[1:, e0:e1]),
            edge_weight=torch.from_numpy(self.edge_weight[e0:e1]),
            num_slots=self.num_slots,
            mean=self.mean,
            std=self.std,
            channels={c: torch.from_numpy(a[k]) for c, a in self.channels.items()},
        )

    def batch(self, j: int) -> SceneBatch:
        """Block ``j`` (views ``j * block`` to ``(j + 1) * block - 1``) as a compact
        :class:`SceneBatch`, sharing this object's memory."""
        b, m = self.block, self.num_slots
        lo, hi = j * b, (j + 1) * b
        k0, k1 = self.box_offsets[lo : hi + 1 : b].tolist()
        e0, e1 = self.edge_offsets[lo : hi + 1 : b].tolist()
        adjacency = torch.sparse_coo_tensor(
            torch.from_numpy(self.edges[:, e0:e1]),
            torch.from_numpy(self.edge_weight[e0:e1]),
            (b, NUM_RELATIONS, m, m),
            check_invariants=not self.in_range,
        )
        return SceneBatch(
            images=torch.from_numpy(self.pixels[lo:hi]).permute(0, 3, 1, 2),
            boxes=torch.from_numpy(self.boxes[k0:k1]),
            box_view=torch.from_numpy(self.box_view[k0:k1]),
            class_ids=torch.from_numpy(self.class_ids[k0:k1]),
            slots=torch.from_numpy(self.slots[k0:k1]),
            adjacency=adjacency,
            mean=self.mean,
            std=self.std,
            channels={c: torch.from_numpy(a[lo:hi]) for c, a in self.channels.items()},
        )


def _item_index(i: int, n: int) -> int:
    if not -n <= i < n:
        raise IndexError(f"item {i} out of range for {n} items")
    return i % n


class TripletItems(Sequence[TripletItem]):
    """Triplets read together (``TripletDataset.__getitems__``), their views already gathered.

    A sequence of :class:`TripletItem` (built on access); :func:`collate_triplets` batches
    the gathered views directly. ``views`` holds the n anchors, then the n positives, then the
    n negatives.
    """

    def __init__(
        self,
        views: ViewArrays,
        *,
        tiers: np.ndarray,
        triplet_ids: np.ndarray,
        room_ids: list[str],
        ids: list[tuple[str, str, str]],
    ) -> None:
        if len(views) != 3 * len(ids) or views.block != len(ids):
            raise DataError(
                f"{len(views)} views in blocks of {views.block} for {len(ids)} triplets; "
                "expected 3 blocks of one view per triplet"
            )
        self.views = views
        self.tiers = tiers
        self.triplet_ids = triplet_ids
        self.room_ids = room_ids
        self.ids = ids

    def __len__(self) -> int:
        return len(self.ids)

    @overload
    def __getitem__(self, i: int) -> TripletItem: ...
    @overload
    def __getitem__(self, i: slice) -> list[TripletItem]: ...
    def __getitem__(self, i: int | slice) -> TripletItem | list[TripletItem]:
        n = len(self)
        if isinstance(i, slice):
            return [self[k] for k in range(n)[i]]
        b = _item_index(i, n)
        return TripletItem(
            anchor=self.views.view(b),
            positive=self.views.view(n + b),
            negative=self.views.view(2 * n + b),
            tier=int(self.tiers[b]),
            triplet_id=int(self.triplet_ids[b]),
            room_id=self.room_ids[b],
            ids=self.ids[b],
        )


class ObservationItems(Sequence[ObservationItem]):
    """Views read together (``ObservationDataset.__getitems__``), already gathered.

    A sequence of :class:`ObservationItem` (built on access); :func:`collate_views` batches the
    gathered views directly. ``meta`` holds the item fields besides the view, a list each.
    """

    def __init__(self, views: ViewArrays, meta: dict[str, list[Any]]) -> None:
        self.views = views
        self.meta = meta

    def __len__(self) -> int:
        return len(self.views)

    @overload
    def __getitem__(self, i: int) -> ObservationItem: ...
    @overload
    def __getitem__(self, i: slice) -> list[ObservationItem]: ...
    def __getitem__(self, i: int | slice) -> ObservationItem | list[ObservationItem]:
        if isinstance(i, slice):
            return [self[k] for k in range(len(self))[i]]
        b = _item_index(i, len(self))
        return ObservationItem(view=self.views.view(b), **{k: v[b] for k, v in self.meta.items()})


# ---------------------------------------------------------------------------------- collation


def collate_triplets(
    items: Sequence[TripletItem],
) -> tuple[SceneBatch, SceneBatch, SceneBatch, dict[str, Any]]:
    """Batch triplets as ``(anchors, positives, negatives, meta)`` (the ``collate_fn``).

    Row b of each of the three batches is triplet b; the batches are compact (uint8 images,
    sparse adjacency: the models call ``SceneBatch.prepare``). ``meta`` holds ``tier`` and
    ``triplet_id`` ((B,) long tensors), ``room_id`` and ``anchor`` / ``positive`` /
    ``negative`` obs ids (lists of str).
    """
    if not items:
        raise DataError("collate_triplets: no items; expected at least one triplet")
    if not isinstance(items, TripletItems):
        items = TripletItems(
            ViewArrays.from_views(
                [getattr(t, role) for role in ("anchor", "positive", "negative") for t in items],
                block=len(items),
            ),
            tiers=np.asarray([t.tier for t in items], dtype=np.int64),
            triplet_ids=np.asarray([t.triplet_id for t in items], dtype=np.int64),
            room_ids=[t.room_id for t in items],
            ids=[t.ids for t in items],
        )
    anchor, positive, negative = map(list, zip(*items.ids, strict=True))
    meta: dict[str, Any] = {
        "tier": torch.as_tensor(items.tiers, dtype=torch.long),
        "triplet_id": torch.as_tensor(items.triplet_ids, dtype=torch.long),
        "room_id": list(items.room_ids),
        "anchor": anchor,
        "positive": positive,
        "negative": negative,
    }
    views = items.views
    return views.batch(0), views.batch(1), views.batch(2), meta


_POSE_FIELDS = ("layout", "grid_i", "grid_j", "heading")


def collate_views(
    items: Sequence[ObservationItem | ViewTensors],
) -> tuple[SceneBatch, dict[str, Any]]:
    """Batch single views as ``(batch, meta)`` (the ``collate_fn`` of ObservationDataset).

    The batch is compact, as :func:`collate_triplets`'. ``meta`` holds ``obs_id`` and
    ``room_id`` (lists of str) and ``layout``, ``grid_i``, ``grid_j``, ``heading`` ((B,) long
    tensors; -1 where the field is null, as for an unposed photo). Bare :class:`ViewTensors`
    items give an empty ``meta``.
    """
    if not items:
        raise DataError("collate_views: no items; expected at least one view")
    if all(isinstance(x, ViewTensors) for x in items):
        return ViewArrays.from_views(items).batch(0), {}  # type: ignore[arg-type]
    if not isinstance(items, ObservationItems):
        if not all(isinstance(x, ObservationItem) for x in items):
            raise DataError("collate_views: items mix ObservationItem and ViewTensors")
        names = ("obs_id", "room_id", *_POSE_FIELDS)
        items = ObservationItems(
            ViewArrays.from_views([x.view for x in items]),  # type: ignore[union-attr]
            {name: [getattr(x, name) for x in items] for name in names},
        )

    def ints(values: list[int | None]) -> Tensor:
        return torch.tensor([-1 if v is None else int(v) for v in values], dtype=torch.long)

    meta: dict[str, Any] = {
        "obs_id": list(items.meta["obs_id"]),
        "room_id": list(items.meta["room_id"]),
        **{name: ints(items.meta[name]) for name in _POSE_FIELDS},
    }
    return items.views.batch(0), meta
