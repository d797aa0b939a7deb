"""PyTorch datasets over an sgdata dataset: triplets and single views as SceneBatch tensors.

The reader side of the on-disk format (docs/dataset.md) for training and evaluation:

- :class:`ImageTransform` resizes a view and its boxes together and normalises the image.
- :func:`graph_tensors` turns one row's ``objects`` and ``relations`` into slot, class, box and
  row-normalised adjacency tensors (DESIGN §8).
- :class:`TripletDataset` (training) and :class:`ObservationDataset` (evaluation) yield those
  tensors per view, and whole batches of views gathered at once (``__getitems__``, what
  ``torch.utils.data.DataLoader`` asks for); :func:`collate_triplets` and
  :func:`collate_views` (:mod:`seannet.data.collate`) batch them into
  :class:`~seannet.data.batch.SceneBatch` objects in the compact form: uint8 pixels and sparse
  adjacency, normalised and densified by the model on its own device.
- They take a dataset opened once (:mod:`seannet.data.opening`) or its root; a root is opened
  there, a handle is used as it is.

With ``cache=True`` (or a cache directory) the datasets read images from the decoded-image
cache of :mod:`seannet.data.image_cache` (built on first use, rebuilt when stale) instead of
decoding PNG per view; the tensors are the same either way. Reading a batch from the cache
is one copy of its pixels out of the memory map plus a few vectorised takes of the split's
graph arrays (built once per process).

Files are opened lazily in each process that reads (``DataLoader`` workers included): a
dataset object holds only plain Python and numpy state until its first item is read, and the
per-process cache is keyed by ``os.getpid()`` so nothing read before a fork is reused after it.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
from torch.utils.data import Dataset as TorchDataset

from seannet.data.box_noise import BoxNoise
from seannet.data.collate import (
    ObservationItem,
    ObservationItems,
    TripletItem,
    TripletItems,
    ViewTensors,
    collate_triplets,
    collate_views,
)
from seannet.data.image_cache import open_image_cache
from seannet.data.opening import DataSource, dataset_identity, open_dataset
from seannet.data.view_channels import check_loader_channels
from seannet.data.view_inputs import ImageTransform, graph_tensors
from seannet.data.view_store import META_COLUMNS, ViewStore, call_reader
from seannet.errors import DataError
from sgdata.dataset import Dataset

__all__ = [
    "ImageTransform",
    "ObservationDataset",
    "ObservationItem",
    "ObservationItems",
    "TripletDataset",
    "TripletItem",
    "TripletItems",
    "ViewTensors",
    "collate_triplets",
    "collate_views",
    "dataset_identity",
    "graph_tensors",
    "open_dataset",
]


def _indices(indices: Sequence[int]) -> np.ndarray:
    """Item indices as an int64 array (numpy's indexing then checks their range)."""
    return np.asarray(indices, dtype=np.int64).reshape(-1)


# ---------------------------------------------------------------------------------- datasets


def _open_split(
    target: TripletDataset | ObservationDataset,
    data: DataSource,
    split: str,
    transform: ImageTransform | None,
    cache: bool | str | Path,
    noise: BoxNoise | None = None,
    channels: Sequence[str] = (),
) -> Dataset:
    """The attributes both datasets share: root, split, transform, identity and view store
    (``data`` opened here only when it is a path)."""
    ds = open_dataset(data)
    names = check_loader_channels(ds, channels, root=ds.root)
    target.root = ds.root
    target.split = split
    target.transform = transform or ImageTransform()
    target.identity = dataset_identity(ds)
    images = None
    if cache is not False and cache is not None:
        cache_dir = None if cache is True else Path(cache)
        images = open_image_cache(ds, split, target.transform, cache_dir=cache_dir)
    target._store = ViewStore(ds, split, target.transform, images, noise, names)
    return ds


class TripletDataset(TorchDataset):
    """The triplets of one split; item ``i`` is triplet ``i`` as a :class:`TripletItem`.

    Construction reads only the triplet table and the ``obs_id`` column of the split's
    observation shards (to index every view by id, and to check every triplet's views
    exist). Each process that reads items (the main one, or each ``DataLoader`` worker) reads
    the objects and relations columns of every shard on its first item and builds every
    view's graph tensors once; without the cache it keeps the encoded image columns too and
    decodes per item, with ``cache`` it reads the pixels from the memory-mapped image cache.
    Memory per reading process is therefore about the size of the split's observation files
    (plus the cache pages it touches, shared between processes through the page cache).

    ``DataLoader`` reads a batch through :meth:`__getitems__` (its views gathered at once,
    for :func:`collate_triplets`); ``dataset[i]`` gives one :class:`TripletItem`.

    Args:
        root: the dataset directory, or the dataset opened already
            (:func:`~seannet.data.opening.open_dataset`: its manifest is not read again).
        split: ``train``, ``val`` or ``test``.
        transform: image size and normalisation (default 224 px, ImageNet statistics).
        cache: read images from the decoded-image cache (:mod:`seannet.data.image_cache`) instead
            of decoding PNG per view: ``True`` for the default cache dir under the dataset
            root, or a directory of the caller's; built on first use, rebuilt when stale.
            Default ``False`` (decode per view).
        channels: per-view channels to return beside the image, any of ``depth``,
            ``instances``, ``classes`` (:mod:`seannet.data.view_channels`): each batch's
            ``SceneBatch.channels`` then holds them as (B, S, S) tensors, resized like the
            image (nearest neighbour). Read and decoded per view, cache or not. Default none.

    Raises:
        DataError: the dataset or split is missing or malformed, a triplet names an
            observation the split does not hold, the image cache cannot be used, or a
            channel is asked for that the dataset does not store.
    """

    def __init__(
        self,
        root: DataSource,
        split: str,
        *,
        transform: ImageTransform | None = None,
        cache: bool | str | Path = False,
        channels: Sequence[str] = (),
    ) -> None:
        ds = _open_split(self, root, split, transform, cache, channels=channels)
        table = call_reader(ds.triplets, split)
        self.triplet_ids = table.column("triplet_id").to_numpy().astype(np.int64)
        self.tiers = table.column("tier").to_numpy().astype(np.int64)
        self.room_ids: list[str] = table.column("room_id").to_pylist()
        names = ("anchor", "positive", "negative")
        ids = [table.column(n).to_pylist() for n in names]
        self.obs: list[tuple[str, str, str]] = list(zip(*ids, strict=True))
        rows = []
        for k, triple in enumerate(self.obs):
            try:
                rows.append([self._store.locate(o) for o in triple])
            except DataError as exc:
                raise DataError(f"triplet {int(self.triplet_ids[k])} of {split}: {exc}") from None
        # (3, T): the storage rows of the anchors, positives and negatives
        self._rows = np.asarray(rows, dtype=np.int64).reshape(-1, 3).T.copy()

    def __len__(self) -> int:
        return len(self.obs)

    def __getitem__(self, i: int) -> TripletItem:
        if not -len(self) <= i < len(self):
            raise IndexError(f"triplet index {i} out of range for {len(self)} triplets")
        return self.__getitems__([i])[0]

    def __getitems__(self, indices: Sequence[int]) -> TripletItems:
        """Triplets ``indices`` read together (what ``DataLoader`` asks for per batch).

        Their views are gathered into one :class:`ViewArrays` (pixels copied once), which
        :func:`collate_triplets` turns into the three batches without another copy.
        """
        idx = _indices(indices)
        rows = self._rows[:, idx].reshape(-1)  # IndexError for an index out of range
        at = idx.tolist()
        return TripletItems(
            self._store.gather(rows, len(idx)),
            tiers=self.tiers[idx],
            triplet_ids=self.triplet_ids[idx],
            room_ids=[self.room_ids[i] for i in at],
            ids=[self.obs[i] for i in at],
        )


class ObservationDataset(TorchDataset):
    """Every observation of one split, once (to embed all views for evaluation).

    Items are in storage order (manifest room order, then row order) as
    :class:`ObservationItem`; files are read lazily per process as in :class:`TripletDataset`.

    Args:
        root: the dataset directory, or the dataset opened already
            (:func:`~seannet.data.opening.open_dataset`: its manifest is not read again).
        split: ``train``, ``val`` or ``test``.
        transform: image size and normalisation (default 224 px, ImageNet statistics).
        cache: as for :class:`TripletDataset` (default ``False``: decode per view).
        noise: the boxes as a labeler or detector would give them (:class:`BoxNoise`;
            default: the dataset's own boxes).
        channels: as for :class:`TripletDataset` (default none); the masks stay the stored
            ones under ``noise``.

    Raises:
        DataError: the dataset or split is missing or malformed, the image cache cannot
            be used, or a channel is asked for that the dataset does not store.
    """

    def __init__(
        self,
        root: DataSource,
        split: str,
        *,
        transform: ImageTransform | None = None,
        cache: bool | str | Path = False,
        noise: BoxNoise | None = None,
        channels: Sequence[str] = (),
    ) -> None:
        _open_split(self, root, split, transform, cache, noise, channels)

    def __len__(self) -> int:
        return len(self._store.obs_ids)

    @property
    def obs_ids(self) -> list[str]:
        """Observation ids in item order."""
        return list(self._store.obs_ids)

    @property
    def num_slots(self) -> int:
        """M, the dataset's GCN node slots."""
        return self._store.num_slots

    def slot_boxes(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Every view's objects as the model sees them (noise included), in item order:
        ``(offsets (N + 1,), slots (K,), boxes (K, 4))``; view v's are ``offsets[v]:[v + 1]``
        (boxes in the stored image's pixels, or the cache's frame with the cache)."""
        g = self._store.graphs()
        return g.box_offsets, g.slots, g.boxes

    def __getitem__(self, i: int) -> ObservationItem:
        if not -len(self) <= i < len(self):
            raise IndexError(f"observation index {i} out of range for {len(self)} views")
        return self.__getitems__([i])[0]

    def __getitems__(self, indices: Sequence[int]) -> ObservationItems:
        """Views ``indices`` read together, gathered as for :meth:`TripletDataset.__getitems__`."""
        idx, n = _indices(indices), len(self)
        if idx.size and (idx.min() < -n or idx.max() >= n):
            raise IndexError(f"observation indices {indices} out of range for {n} views")
        rows = idx % n
        at = rows.tolist()
        m = self._store.meta
        meta = {name: [m[name][i] for i in at] for name in META_COLUMNS}
        meta["layout"] = [int(x) for x in meta["layout"]]
        return ObservationItems(self._store.gather(rows, len(rows)), meta)
