"""PyTorch datasets over an sgdata dataset: triplets and single views as SceneBatch tensors.

The reader side of the on-disk format (docs/dataset.md) for training and evaluation:

- :class:`ImageTransform` resizes a view and its boxes together and normalises the image.
- :func:`graph_tensors` turns one row's ``objects`` and ``relations`` into slot, class, box and
  row-normalised adjacency tensors (DESIGN §8).
- :class:`TripletDataset` (training) and :class:`ObservationDataset` (evaluation) yield those
  tensors per view; :func:`collate_triplets` and :func:`collate_views` batch them into
  :class:`~seannet.batch.SceneBatch` objects for ``torch.utils.data.DataLoader``.
- :func:`dataset_identity` names the data a model was trained on, for checkpoints.

With ``cache=True`` (or a cache directory) the datasets read images from the decoded-image
cache of :mod:`seannet.image_cache` (built on first use, rebuilt when stale) instead of
decoding PNG per view; the tensors are the same either way.

Files are opened lazily in each process that reads (``DataLoader`` workers included): a
dataset object holds only plain Python and numpy state until its first item is read, and the
per-process cache is keyed by ``os.getpid()`` so nothing read before a fork is reused after it.
"""

from __future__ import annotations

import hashlib
import json
import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import torch
from torch import Tensor
from torch.utils.data import Dataset as TorchDataset

from seannet.batch import NUM_RELATIONS, SceneBatch
from seannet.errors import DataError
from seannet.image_cache import CachedImages, open_image_cache
from seannet.view_inputs import (
    IMAGENET_MEAN,
    IMAGENET_STD,
    ImageTransform,
    dense_adjacency,
    graph_from_columns,
    graph_tensors,
    struct_columns,
)
from sgdata.dataset import Dataset, decode_image, observations_schema, read_table
from sgdata.errors import DatasetError

__all__ = [
    "IMAGENET_MEAN",
    "IMAGENET_STD",
    "ImageTransform",
    "ObservationDataset",
    "ObservationItem",
    "TripletDataset",
    "TripletItem",
    "ViewTensors",
    "collate_triplets",
    "collate_views",
    "dataset_identity",
    "graph_tensors",
    "open_dataset",
]

# Observation columns a view needs: the encoded image and the scene graph (image first).
_VIEW_COLUMNS = ("image", "objects", "relations")
# Observation columns kept per view for evaluation (ObservationItem).
_META_COLUMNS = ("obs_id", "room_id", "layout", "grid_i", "grid_j", "heading")


# ---------------------------------------------------------------------------------- opening


def open_dataset(root: str | Path) -> Dataset:
    """:meth:`sgdata.dataset.Dataset.open`, with its errors as one-line :class:`DataError`.

    Raises:
        DataError: ``root`` is missing, not an sgdata dataset, or of an unreadable format.
    """
    try:
        return Dataset.open(root)
    except DatasetError as exc:
        raise DataError(_one_line(f"dataset {root}: {exc}")) from None


def dataset_identity(root: str | Path | Dataset) -> dict[str, Any]:
    """What a model trained on this dataset depends on; checkpoints store it to refuse others.

    Returns:
        ``{"name", "version", "format_version", "num_slots", "vocabulary_sha256"}``; the hash
        covers the class vocabulary in id order with each class's slot run (name, id,
        slot_start, slot_count) and the relation type names, as canonical JSON.

    Raises:
        DataError: ``root`` is not a readable dataset.
    """
    ds = root if isinstance(root, Dataset) else open_dataset(root)
    m = ds.manifest
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


def _one_line(text: str) -> str:
    return " ".join(text.split())


@dataclass
class ViewTensors:
    """One view ready for the model (see :class:`~seannet.batch.SceneBatch` for the meaning).

    Attributes:
        image: (3, S, S) float32, normalised.
        boxes: (K, 4) float32 pixel boxes in the S x S frame.
        class_ids: (K,) long.
        slots: (K,) long.
        edge_index: (3, E) long, [relation, src slot, dst slot] of each non-zero adjacency
            cell (relation 0 on, 1 in, 2 proximity).
        edge_weight: (E,) float32, the row-normalised value of each cell.
        num_slots: M.

    The adjacency travels sparse (a dense one is 3 x M x M floats, 786 KB at M = 256) and is
    made dense once per batch by the collate functions; :attr:`adjacency` gives it per view.
    """

    image: Tensor
    boxes: Tensor
    class_ids: Tensor
    slots: Tensor
    edge_index: Tensor
    edge_weight: Tensor
    num_slots: int

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


# ---------------------------------------------------------------------------------- storage


class _Shard:
    """One observation file's view columns, held as Arrow / numpy in one process.

    Images stay encoded (PNG/JPEG bytes in the Arrow column) and are decoded on access, or
    are not read at all (``with_images=False``, when the image cache serves them); the scene
    graphs are flattened once into numpy columns with per-row offsets, and each row's graph
    tensors are kept once computed (``graphs``: a few KB a view, the largest per-view cost
    after PNG decoding).
    """

    def __init__(self, path: Path, *, with_images: bool = True) -> None:
        columns = _VIEW_COLUMNS if with_images else _VIEW_COLUMNS[1:]
        try:
            table = read_table(path, observations_schema(), columns=columns)
        except DatasetError as exc:
            raise DataError(_one_line(str(exc))) from None
        self.images = table.column("image") if with_images else None
        self.obj_offsets, obj = _flatten_lists(
            table.column("objects"), ("instance", "class_id", "slot", "box2d")
        )
        self.rel_offsets, rel = _flatten_lists(table.column("relations"), ("src", "dst", "type"))
        self.instance, self.class_id, self.slot, self.box2d = (
            obj["instance"],
            obj["class_id"],
            obj["slot"],
            obj["box2d"],
        )
        self.src, self.dst, self.type = rel["src"], rel["dst"], rel["type"]
        self.graphs: list[tuple[Tensor, ...] | None] = [None] * (len(self.obj_offsets) - 1)

    def graph(self, row: int, num_slots: int) -> tuple[Tensor, ...]:
        """Row ``row``'s :func:`graph_from_columns` tensors, computed on first use.

        Callers must not modify them in place (:meth:`_ViewStore.view` hands out copies).
        """
        graph = self.graphs[row]
        if graph is None:
            o0, o1 = self.obj_offsets[row], self.obj_offsets[row + 1]
            r0, r1 = self.rel_offsets[row], self.rel_offsets[row + 1]
            graph = self.graphs[row] = graph_from_columns(
                self.instance[o0:o1],
                self.class_id[o0:o1],
                self.slot[o0:o1],
                self.box2d[o0:o1],
                self.src[r0:r1],
                self.dst[r0:r1],
                self.type[r0:r1],
                num_slots,
            )
        return graph


def _flatten_lists(
    column: pa.ChunkedArray, names: Sequence[str]
) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """A list<struct> column as (offsets (N+1,), {field: values}) numpy arrays."""
    lists = column.combine_chunks() if column.num_chunks != 1 else column.chunk(0)
    offsets = lists.offsets.to_numpy().astype(np.int64)
    values = struct_columns(lists.flatten(), names)
    return offsets - offsets[0], values


class _ViewStore:
    """Per-process access to the views of one split: obs index, lazy shards, transform.

    Holds only plain state when pickled or forked; shards are read in the process that asks
    for a view (``os.getpid()`` keys the cache, so a fork never reuses the parent's).
    """

    def __init__(
        self,
        ds: Dataset,
        split: str,
        transform: ImageTransform,
        images: CachedImages | None = None,
    ) -> None:
        self.split = split
        self.transform = transform
        self.num_slots = int(ds.manifest.num_slots)
        self.files = [str(p) for p in _call(ds.observation_files, split)]
        table = _call(ds.observations, split, columns=list(_META_COLUMNS))
        self.meta: dict[str, list[Any]] = {n: table.column(n).to_pylist() for n in _META_COLUMNS}
        self.obs_ids: list[str] = self.meta["obs_id"]
        rows = [pq.read_metadata(p).num_rows for p in self.files]
        if sum(rows) != len(self.obs_ids):
            raise DataError(f"split {split!r}: observation shards changed while being read")
        self.file_starts = np.concatenate(([0], np.cumsum(rows))).astype(np.int64)
        self.locations: list[tuple[int, int]] = [
            (f, r) for f, n in enumerate(rows) for r in range(n)
        ]
        self.index = dict(zip(self.obs_ids, self.locations, strict=True))
        if len(self.index) != len(self.obs_ids):
            raise DataError(f"split {split!r}: an obs_id repeats across its observation shards")
        self._pid: int | None = None
        self._shards: dict[int, _Shard] = {}
        self.cached = images
        if images is not None and images.obs_ids != self.obs_ids:
            raise DataError(
                f"image cache {images.path}: its views are not split {split!r}'s; delete it "
                "to rebuild"
            )

    def __getstate__(self) -> dict[str, Any]:
        state = dict(self.__dict__)
        state["_pid"], state["_shards"] = None, {}
        return state

    def locate(self, obs_id: str) -> tuple[int, int]:
        try:
            return self.index[obs_id]
        except KeyError:
            raise DataError(
                f"observation {obs_id!r} is not in split {self.split!r}'s observation shards"
            ) from None

    def shard(self, f: int) -> _Shard:
        pid = os.getpid()
        if self._pid != pid:  # first access in this process (a fresh DataLoader worker)
            self._pid, self._shards = pid, {}
        shard = self._shards.get(f)
        if shard is None:
            shard = self._shards[f] = _Shard(Path(self.files[f]), with_images=self.cached is None)
        return shard

    def view(self, f: int, row: int) -> ViewTensors:
        s = self.shard(f)
        obs = self.obs_ids_of(f, row)
        try:
            slots, class_ids, boxes, edge_index, edge_weight = s.graph(row, self.num_slots)
            if self.cached is None:
                rgb, box = decode_image(s.images[row].as_py()), boxes.numpy()  # type: ignore[index]
            else:
                at = int(self.file_starts[f]) + row
                h, w = self.cached.source_hw[at]
                rgb, box = self.cached.image(at), self._scaled_boxes(int(h), int(w), boxes.numpy())
        except (DataError, DatasetError) as exc:
            raise DataError(f"observation {obs!r}: {exc}") from None
        image, boxes = self.transform(rgb, box)  # new boxes: the kept ones stay untouched
        kept = (class_ids, slots, edge_index, edge_weight)
        class_ids, slots, edge_index, edge_weight = (t.clone() for t in kept)
        return ViewTensors(image, boxes, class_ids, slots, edge_index, edge_weight, self.num_slots)

    def _scaled_boxes(self, h: int, w: int, boxes: np.ndarray) -> np.ndarray:
        """Boxes of a cached view scaled from its decoded h x w frame to the cached one, with
        ImageTransform's factors and float32 arithmetic (the transform then leaves a view
        already at its size, and its boxes, as they are)."""
        s = self.transform.size
        scale = np.asarray([s / w, s / h, s / w, s / h], dtype=np.float32)
        return np.asarray(boxes, dtype=np.float32).reshape(-1, 4) * scale

    def obs_ids_of(self, f: int, row: int) -> str:
        return self.obs_ids[int(self.file_starts[f]) + row]


def _call(fn: Any, *args: Any, **kwargs: Any) -> Any:
    """Call an sgdata reader method, turning its DatasetError into a one-line DataError."""
    try:
        return fn(*args, **kwargs)
    except DatasetError as exc:
        raise DataError(_one_line(str(exc))) from None


# ---------------------------------------------------------------------------------- datasets


def _open_split(
    target: TripletDataset | ObservationDataset,
    root: str | Path,
    split: str,
    transform: ImageTransform | None,
    cache: bool | str | Path,
) -> Dataset:
    """The attributes both datasets share: root, split, transform, identity and view store."""
    ds = open_dataset(root)
    target.root = Path(root)
    target.split = split
    target.transform = transform or ImageTransform()
    target.identity = dataset_identity(ds)
    images = None
    if cache is not False and cache is not None:
        cache_dir = None if cache is True else Path(cache)
        images = open_image_cache(ds, split, target.transform, cache_dir=cache_dir)
    target._store = _ViewStore(ds, split, target.transform, images)
    return ds


class TripletDataset(TorchDataset):
    """The triplets of one split; item ``i`` is triplet ``i`` as a :class:`TripletItem`.

    Construction reads only the triplet table and the ``obs_id`` column of the split's
    observation shards (to index every view by id, and to check every triplet's views
    exist). Each process that reads items (the main one, or each ``DataLoader`` worker) loads
    the image, objects and relations columns of a room shard on its first view from it and
    keeps them (images still encoded) for later items; images are decoded per item, or read
    from the memory-mapped image cache with ``cache``. Memory per reading process is therefore
    about the size of the split's observation files (plus the cache pages it touches, shared
    between processes through the page cache).

    Args:
        root: the dataset directory.
        split: ``train``, ``val`` or ``test``.
        transform: image size and normalisation (default 224 px, ImageNet statistics).
        cache: read images from the decoded-image cache (:mod:`seannet.image_cache`) instead
            of decoding PNG per view: ``True`` for the default cache dir under the dataset
            root, or a directory of the caller's; built on first use, rebuilt when stale.
            Default ``False`` (decode per view).

    Raises:
        DataError: the dataset or split is missing or malformed, a triplet names an
            observation the split does not hold, or the image cache cannot be used.
    """

    def __init__(
        self,
        root: str | Path,
        split: str,
        *,
        transform: ImageTransform | None = None,
        cache: bool | str | Path = False,
    ) -> None:
        ds = _open_split(self, root, split, transform, cache)
        table = _call(ds.triplets, split)
        self.triplet_ids = table.column("triplet_id").to_numpy().astype(np.int64)
        self.tiers = table.column("tier").to_numpy().astype(np.int64)
        self.room_ids: list[str] = table.column("room_id").to_pylist()
        names = ("anchor", "positive", "negative")
        ids = [table.column(n).to_pylist() for n in names]
        self.obs: list[tuple[str, str, str]] = list(zip(*ids, strict=True))
        locs = []
        for k, triple in enumerate(self.obs):
            try:
                locs.append(tuple(self._store.locate(o) for o in triple))
            except DataError as exc:
                raise DataError(f"triplet {int(self.triplet_ids[k])} of {split}: {exc}") from None
        self._locations: list[tuple[tuple[int, int], ...]] = locs

    def __len__(self) -> int:
        return len(self.obs)

    def __getitem__(self, i: int) -> TripletItem:
        if not -len(self) <= i < len(self):
            raise IndexError(f"triplet index {i} out of range for {len(self)} triplets")
        a, p, n = (self._store.view(f, r) for f, r in self._locations[i])
        return TripletItem(
            anchor=a,
            positive=p,
            negative=n,
            tier=int(self.tiers[i]),
            triplet_id=int(self.triplet_ids[i]),
            room_id=self.room_ids[i],
            ids=self.obs[i],
        )


class ObservationDataset(TorchDataset):
    """Every observation of one split, once (to embed all views for evaluation).

    Items are in storage order (manifest room order, then row order) as
    :class:`ObservationItem`; files are read lazily per process as in :class:`TripletDataset`.

    Args:
        root: the dataset directory.
        split: ``train``, ``val`` or ``test``.
        transform: image size and normalisation (default 224 px, ImageNet statistics).
        cache: as for :class:`TripletDataset` (default ``False``: decode per view).

    Raises:
        DataError: the dataset or split is missing or malformed, or the image cache cannot
            be used.
    """

    def __init__(
        self,
        root: str | Path,
        split: str,
        *,
        transform: ImageTransform | None = None,
        cache: bool | str | Path = False,
    ) -> None:
        _open_split(self, root, split, transform, cache)

    def __len__(self) -> int:
        return len(self._store.obs_ids)

    @property
    def obs_ids(self) -> list[str]:
        """Observation ids in item order."""
        return list(self._store.obs_ids)

    def __getitem__(self, i: int) -> ObservationItem:
        if not -len(self) <= i < len(self):
            raise IndexError(f"observation index {i} out of range for {len(self)} views")
        i = i % len(self)
        f, r = self._store.locations[i]
        m = self._store.meta
        return ObservationItem(
            view=self._store.view(f, r),
            obs_id=self._store.obs_ids[i],
            room_id=m["room_id"][i],
            layout=int(m["layout"][i]),
            grid_i=m["grid_i"][i],
            grid_j=m["grid_j"][i],
            heading=m["heading"][i],
        )


# ---------------------------------------------------------------------------------- collation


def _scene_batch(views: Sequence[ViewTensors]) -> SceneBatch:
    """Stack images and adjacency; concatenate boxes with the view index of each."""
    counts = torch.tensor([v.boxes.shape[0] for v in views], dtype=torch.long)
    m = views[0].num_slots
    if any(v.num_slots != m for v in views):
        raise DataError(f"views with {sorted({v.num_slots for v in views})} slots in one batch")
    adjacency = torch.zeros((len(views), NUM_RELATIONS, m, m), dtype=torch.float32)
    edges = torch.cat([v.edge_index for v in views], dim=1)
    edge_view = torch.repeat_interleave(
        torch.arange(len(views)), torch.tensor([v.edge_index.shape[1] for v in views])
    )
    adjacency[edge_view, edges[0], edges[1], edges[2]] = torch.cat([v.edge_weight for v in views])
    return SceneBatch(
        images=torch.stack([v.image for v in views]),
        boxes=torch.cat([v.boxes.reshape(-1, 4) for v in views]),
        box_view=torch.repeat_interleave(torch.arange(len(views)), counts),
        class_ids=torch.cat([v.class_ids for v in views]),
        slots=torch.cat([v.slots for v in views]),
        adjacency=adjacency,
    )


def collate_triplets(
    items: Sequence[TripletItem],
) -> tuple[SceneBatch, SceneBatch, SceneBatch, dict[str, Any]]:
    """Batch triplets as ``(anchors, positives, negatives, meta)`` (the ``collate_fn``).

    Row b of each of the three batches is triplet b. ``meta`` holds ``tier`` and
    ``triplet_id`` ((B,) long tensors), ``room_id`` and ``anchor`` / ``positive`` /
    ``negative`` obs ids (lists of str).
    """
    if not items:
        raise DataError("collate_triplets: no items; expected at least one triplet")
    meta: dict[str, Any] = {
        "tier": torch.tensor([t.tier for t in items], dtype=torch.long),
        "triplet_id": torch.tensor([t.triplet_id for t in items], dtype=torch.long),
        "room_id": [t.room_id for t in items],
        "anchor": [t.ids[0] for t in items],
        "positive": [t.ids[1] for t in items],
        "negative": [t.ids[2] for t in items],
    }
    return (
        _scene_batch([t.anchor for t in items]),
        _scene_batch([t.positive for t in items]),
        _scene_batch([t.negative for t in items]),
        meta,
    )


def collate_views(
    items: Sequence[ObservationItem | ViewTensors],
) -> tuple[SceneBatch, dict[str, Any]]:
    """Batch single views as ``(batch, meta)`` (the ``collate_fn`` of ObservationDataset).

    ``meta`` holds ``obs_id`` and ``room_id`` (lists of str) and ``layout``, ``grid_i``,
    ``grid_j``, ``heading`` ((B,) long tensors; -1 where the field is null, as for an unposed
    photo). Bare :class:`ViewTensors` items give an empty ``meta``.
    """
    if not items:
        raise DataError("collate_views: no items; expected at least one view")
    if all(isinstance(x, ViewTensors) for x in items):
        return _scene_batch(list(items)), {}
    if not all(isinstance(x, ObservationItem) for x in items):
        raise DataError("collate_views: items mix ObservationItem and ViewTensors")

    def ints(name: str) -> Tensor:
        values = [getattr(x, name) for x in items]
        return torch.tensor([-1 if v is None else int(v) for v in values], dtype=torch.long)

    meta: dict[str, Any] = {
        "obs_id": [x.obs_id for x in items],
        "room_id": [x.room_id for x in items],
        **{name: ints(name) for name in ("layout", "grid_i", "grid_j", "heading")},
    }
    return _scene_batch([x.view for x in items]), meta
