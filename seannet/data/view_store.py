"""Where the views of one split live in one process: shards of observation columns read
lazily, the split's graph tensors built once, and pixel buffers reused between batches.

:class:`ViewStore` is what :class:`~seannet.data.datasets.TripletDataset` and
:class:`~seannet.data.datasets.ObservationDataset` hold; it takes an opened dataset (never a
path it would open again), keeps only plain state when pickled, and reads its files again in
each process that asks for a view (``os.getpid()`` keys the cache).
"""

from __future__ import annotations

import os
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow.parquet as pq
from torch import Tensor

from seannet.data.box_noise import BoxNoise
from seannet.data.collate import ViewArrays
from seannet.data.image_cache import CachedImages
from seannet.data.split_graphs import SplitGraphs, flatten_lists, offsets_of, view_spans
from seannet.data.view_channels import decode_view_channels, empty_channels, stored_columns
from seannet.data.view_inputs import ImageTransform, graph_from_columns
from seannet.errors import DataError
from sgdata.dataset import Dataset, decode_image, observations_schema, read_table
from sgdata.dataset.storage import image_bytes
from sgdata.errors import DatasetError, one_line

__all__ = ["META_COLUMNS", "PixelBuffers", "Shard", "ViewStore", "call_reader"]

# Observation columns a view needs: the encoded image and the scene graph (image first).
VIEW_COLUMNS = ("image", "objects", "relations")
# Observation columns kept per view for evaluation (ObservationItem).
META_COLUMNS = ("obs_id", "room_id", "layout", "grid_i", "grid_j", "heading")


class Shard:
    """One observation file's view columns, held as Arrow / numpy in one process.

    Images stay encoded (PNG/JPEG bytes in the Arrow column) and are decoded on access, or
    are not read at all (``with_images=False``, when the image cache serves them); so do the
    channel columns named in ``channels`` (none by default). The scene graphs are flattened
    into numpy columns with per-row offsets.
    """

    def __init__(
        self, path: Path, *, with_images: bool = True, channels: Sequence[str] = ()
    ) -> None:
        columns = [*(VIEW_COLUMNS if with_images else VIEW_COLUMNS[1:]), *channels]
        try:
            table = read_table(path, observations_schema(), columns=columns)
        except DatasetError as exc:
            raise DataError(one_line(str(exc))) from None
        self.images = table.column("image") if with_images else None
        self.channels = {c: table.column(c) for c in channels}
        self.obj_offsets, obj = flatten_lists(
            table.column("objects"), ("instance", "class_id", "slot", "box2d")
        )
        self.rel_offsets, rel = flatten_lists(table.column("relations"), ("src", "dst", "type"))
        self.instance, self.class_id, self.slot, self.box2d = (
            obj["instance"],
            obj["class_id"],
            obj["slot"],
            obj["box2d"],
        )
        self.src, self.dst, self.type = rel["src"], rel["dst"], rel["type"]

    def channel_cells(self, row: int) -> dict[str, bytes | None]:
        """Row ``row``'s encoded channel PNGs, column name -> bytes (None where null)."""
        cells = {c: column[row].as_py() for c, column in self.channels.items()}
        return {c: None if v is None else image_bytes(v) for c, v in cells.items()}

    def __len__(self) -> int:
        return len(self.obj_offsets) - 1

    def graph(self, row: int, num_slots: int, noise: Noise | None = None) -> tuple[Tensor, ...]:
        """Row ``row``'s :func:`graph_from_columns` tensors (its boxes under ``noise``:
        ``(BoxNoise, obs_id, slot_runs, image_hw)``, when given)."""
        o0, o1 = self.obj_offsets[row], self.obj_offsets[row + 1]
        r0, r1 = self.rel_offsets[row], self.rel_offsets[row + 1]
        objects = (self.instance[o0:o1], self.class_id[o0:o1], self.slot[o0:o1], self.box2d[o0:o1])
        relations = (self.src[r0:r1], self.dst[r0:r1], self.type[r0:r1])
        if noise is not None:
            box_noise, obs_id, slot_runs, image_hw = noise
            objects, relations = box_noise.apply(
                obs_id, objects, relations, slot_runs=slot_runs, image_hw=image_hw
            )
        return graph_from_columns(*objects, *relations, num_slots)


class PixelBuffers:
    """Reused (n, S, S, 3) uint8 arrays to gather batches of pixels into, in one process.

    A fresh array of a few MB comes from the kernel a page at a time: glibc maps it, or grows
    its heap and trims it again once the batch is freed, so every batch pays a page fault per
    4 KB (measured: ~400 faults and ~1 ms a 224 px batch of 8 triplets, more than copying the
    pixels in). A kept array is handed out again only when nothing else refers to it any more
    (every tensor made from it is gone): its reference count is back to its idle value, the
    count with only this object holding it. At most :attr:`KEEP` arrays are kept.
    """

    KEEP = 4  # arrays kept: a training loop holds one or two batches while the next is read

    def __init__(self) -> None:
        self._arrays: list[np.ndarray] = [np.empty(0, dtype=np.uint8)]
        # the same expression as in take(): the list's reference and the call's argument
        self._idle = sys.getrefcount(self._arrays[0])
        self._arrays.clear()

    def take(self, shape: tuple[int, ...]) -> np.ndarray:
        """An uninitialised uint8 array of ``shape`` that nobody else uses."""
        for k in reversed(range(len(self._arrays))):  # the most recently used first: cache-warm
            if self._arrays[k].shape == shape and sys.getrefcount(self._arrays[k]) == self._idle:
                self._arrays.append(self._arrays.pop(k))  # most recently used last
                return self._arrays[-1]
        self._arrays.append(np.empty(shape, dtype=np.uint8))
        if len(self._arrays) > self.KEEP:
            del self._arrays[0]  # forgotten, not freed while in use
        return self._arrays[-1]


class ViewStore:
    """Per-process access to the views of one split: obs index, lazy shards and graphs.

    Holds only plain state when pickled or forked; shards are read in the process that asks
    for a view (``os.getpid()`` keys the cache, so a fork never reuses the parent's). The first
    read in a process reads the split's graph columns and builds every view's graph tensors
    once (:class:`SplitGraphs`; ``medium``'s 8,013 train views: 1.5-2 s here).
    """

    def __init__(
        self,
        ds: Dataset,
        split: str,
        transform: ImageTransform,
        images: CachedImages | None = None,
        noise: BoxNoise | None = None,
        channels: tuple[str, ...] = (),
    ) -> None:
        self.split = split
        self.channels = channels  # loader channel names (seannet.data.view_channels)
        self.transform = transform
        self.num_slots = int(ds.manifest.num_slots)
        self.noise = noise if noise is not None and noise.active else None
        classes = ds.manifest.classes
        self.slot_runs = np.array([(c.slot_start, c.slot_count) for c in classes], np.int64)
        self.image_hw = (int(ds.manifest.image.height), int(ds.manifest.image.width))
        self.files = [str(p) for p in call_reader(ds.observation_files, split)]
        table = call_reader(ds.observations, split, columns=list(META_COLUMNS))
        self.meta: dict[str, list[Any]] = {n: table.column(n).to_pylist() for n in META_COLUMNS}
        self.obs_ids: list[str] = self.meta["obs_id"]
        rows = [pq.read_metadata(p).num_rows for p in self.files]
        if sum(rows) != len(self.obs_ids):
            raise DataError(f"split {split!r}: observation shards changed while being read")
        self.file_starts = offsets_of(rows)
        self.index = {obs: v for v, obs in enumerate(self.obs_ids)}
        if len(self.index) != len(self.obs_ids):
            raise DataError(f"split {split!r}: an obs_id repeats across its observation shards")
        self._pid: int | None = None
        self._shards: dict[int, Shard] = {}
        self._graphs: SplitGraphs | None = None
        self._buffers = PixelBuffers()
        self._local: dict[tuple[int, int], np.ndarray] = {}  # (n, block): view within batch
        self.mean: tuple[float, float, float] = tuple(transform.mean)  # type: ignore[assignment]
        self.std: tuple[float, float, float] = tuple(transform.std)  # type: ignore[assignment]
        self.cached = images
        if images is not None and images.obs_ids != self.obs_ids:
            raise DataError(
                f"image cache {images.path}: its views are not split {split!r}'s; delete it "
                "to rebuild"
            )

    def __getstate__(self) -> dict[str, Any]:
        state = dict(self.__dict__)
        state["_pid"], state["_shards"], state["_graphs"] = None, {}, None
        state["_buffers"] = PixelBuffers()
        return state

    def __len__(self) -> int:
        return len(self.obs_ids)

    def locate(self, obs_id: str) -> int:
        """The view's row in storage order."""
        try:
            return self.index[obs_id]
        except KeyError:
            raise DataError(
                f"observation {obs_id!r} is not in split {self.split!r}'s observation shards"
            ) from None

    def _own(self) -> None:
        pid = os.getpid()
        if self._pid != pid:  # first access in this process (a fresh DataLoader worker)
            self._pid, self._shards, self._graphs = pid, {}, None
            self._buffers = PixelBuffers()

    def shard(self, f: int) -> Shard:
        self._own()
        shard = self._shards.get(f)
        if shard is None:
            shard = self._shards[f] = Shard(
                Path(self.files[f]),
                with_images=self.cached is None,
                channels=stored_columns(self.channels),
            )
        return shard

    def graphs(self) -> SplitGraphs:
        """The split's graph tensors, built on first use in this process."""
        self._own()
        if self._graphs is None:
            self._graphs = self._build_graphs()
        return self._graphs

    def _build_graphs(self) -> SplitGraphs:
        parts: list[tuple[Tensor, ...]] = []
        for f in range(len(self.files)):
            shard = self.shard(f)
            if len(shard) != self.file_starts[f + 1] - self.file_starts[f]:
                raise DataError(f"{self.files[f]}: changed while being read; open it again")
            for row in range(len(shard)):
                obs = self.obs_ids[int(self.file_starts[f]) + row]
                noise = None
                if self.noise is not None:
                    noise = (self.noise, obs, self.slot_runs, self.image_hw)
                try:
                    parts.append(shard.graph(row, self.num_slots, noise))
                except DataError as exc:
                    raise DataError(f"observation {obs!r}: {exc}") from None
        slots, class_ids, boxes, edges, weights = ([p[k].numpy() for p in parts] for k in range(5))
        box_offsets = offsets_of([len(x) for x in slots])
        boxes_all = np.concatenate(boxes).reshape(-1, 4) if parts else np.zeros((0, 4))
        boxes_all = boxes_all.astype(np.float32, copy=False)
        if self.cached is not None:  # into the cached frame, once
            hw = np.repeat(self.cached.source_hw, np.diff(box_offsets), axis=0)
            boxes_all = self.transform.scale_boxes(boxes_all, hw)
        return SplitGraphs(
            box_offsets=box_offsets,
            slots=np.concatenate(slots) if parts else np.zeros(0, np.int64),
            class_ids=np.concatenate(class_ids) if parts else np.zeros(0, np.int64),
            boxes=boxes_all,
            edge_offsets=offsets_of([x.shape[0] for x in weights]),
            edges=np.concatenate(edges, axis=1) if parts else np.zeros((3, 0), np.int64),
            edge_weight=np.concatenate(weights) if parts else np.zeros(0, np.float32),
        )

    def gather(self, rows: np.ndarray, block: int) -> ViewArrays:
        """Views ``rows`` (storage order) as one :class:`ViewArrays` in blocks of ``block``,
        pixels copied once."""
        g = self.graphs()
        local = self._local.get((len(rows), block))
        if local is None:
            local = self._local[len(rows), block] = np.arange(len(rows)) % block
        box_offsets, edge_offsets, (at, cells), (box_view, edge_view) = view_spans(
            g.spans, rows, local
        )
        edges = np.empty((4, len(cells)), dtype=np.int64)
        edges[0] = edge_view
        np.take(g.edges, cells, axis=1, out=edges[1:], mode="clip")
        boxes = g.boxes[at]
        s = self.transform.size
        pixels = self._buffers.take((len(rows), s, s, 3))
        if self.cached is not None:
            # rows are in range; "clip" skips the buffered copy "raise" makes with ``out``
            np.take(self.cached.array, rows, axis=0, out=pixels, mode="clip")
        else:
            hw = np.empty((len(rows), 2), dtype=np.int64)
            for k, v in enumerate(rows.tolist()):
                f = int(np.searchsorted(self.file_starts, v, side="right")) - 1
                images = self.shard(f).images
                try:
                    rgb = decode_image(images[v - int(self.file_starts[f])].as_py())  # type: ignore[index]
                except (DataError, DatasetError) as exc:
                    raise DataError(f"observation {self.obs_ids[v]!r}: {exc}") from None
                hw[k] = rgb.shape[:2]
                pixels[k], _ = self.transform.resize(rgb, NO_BOXES)
            boxes = self.transform.scale_boxes(boxes, np.repeat(hw, np.diff(box_offsets), axis=0))
        channels = empty_channels(self.channels, len(rows), s)
        if self.channels:
            self._gather_channels(rows, channels)
        return ViewArrays(
            pixels=pixels,
            boxes=boxes,
            class_ids=g.class_ids[at],
            slots=g.slots[at],
            box_view=box_view,
            box_offsets=box_offsets,
            edges=edges,
            edge_weight=g.edge_weight[cells],
            edge_offsets=edge_offsets,
            num_slots=self.num_slots,
            mean=self.mean,
            std=self.std,
            block=block,
            in_range=True,
            channels=channels,
        )

    def _gather_channels(self, rows: np.ndarray, out: dict[str, np.ndarray]) -> None:
        """Views ``rows``' channels decoded, resized to the transform's size, into ``out``."""
        for k, v in enumerate(rows.tolist()):
            f = int(np.searchsorted(self.file_starts, v, side="right")) - 1
            shard = self.shard(f)
            row = v - int(self.file_starts[f])
            o0, o1 = shard.obj_offsets[row], shard.obj_offsets[row + 1]
            decoded = decode_view_channels(
                shard.channel_cells(row),
                shard.class_id[o0:o1],
                self.channels,
                self.transform.size,
                where=f"observation {self.obs_ids[v]!r}",
            )
            for name, values in decoded.items():
                out[name][k] = values


NO_BOXES = np.zeros((0, 4), dtype=np.float32)
# a view's box noise: (noise, obs_id, slot runs (C, 2), stored image (height, width))
Noise = tuple[BoxNoise, str, np.ndarray, tuple[int, int]]


def call_reader(fn: Any, *args: Any, **kwargs: Any) -> Any:
    """Call an sgdata reader method, turning its DatasetError into a one-line DataError."""
    try:
        return fn(*args, **kwargs)
    except DatasetError as exc:
        raise DataError(one_line(str(exc))) from None
