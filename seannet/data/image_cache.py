"""A decoded-image cache: every view of a split resized to the model's input size, memory-mapped.

Decoding PNG is most of what a :class:`~seannet.data.datasets.TripletDataset` item costs. The cache
decodes every view of a split once, resizes it exactly as :class:`ImageTransform` does (the
cache calls the transform itself, so both give the same pixels), and keeps the result as one
uint8 array per split and size::

    <cache dir>/<split>.npy     (N, S, S, 3) uint8, views in storage order (manifest room
                                order, then row order), read through a memory map
    <cache dir>/<split>.json    what it was built from: the dataset (name, version, seed), the
                                split's observation files with their manifest sha256, the size,
                                a fingerprint of the resize, and the index (obs ids and each
                                view's decoded height and width, for scaling boxes)

The default cache dir is ``<root>/.cache/images-<S>`` (:func:`default_cache_dir`); a user may
name another. :func:`open_image_cache` builds the cache when it is missing, and rebuilds it
when it is stale (another file list or sha256 in the manifest, another size or resize); a cache
dir given explicitly that holds a cache of *another* dataset (name, version or seed) is refused
rather than overwritten. The manifest's digests are trusted, not recomputed (``sgdata
validate`` checks them against the files).

Both files are written through a temporary file and a rename (:mod:`sgdata.fileio`), the array
first and the JSON last, so a killed build leaves either the old cache or none; the bytes
depend only on the dataset and the size. :class:`CachedImages` holds only plain state when
pickled and maps the file lazily in each process that reads (``DataLoader`` workers included).
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import torch

from seannet.data.view_inputs import ImageTransform
from seannet.errors import DataError
from sgdata.dataset import Dataset, decode_image, observations_schema, read_table
from sgdata.errors import DatasetError
from sgdata.fileio import atomic_file, atomic_write_text

__all__ = [
    "CACHE_FORMAT",
    "CachedImages",
    "build_image_cache",
    "default_cache_dir",
    "open_image_cache",
    "resize_like_transform",
]

CACHE_FORMAT = 1  # bump when the layout of <split>.npy / <split>.json changes
_DEFAULT_DIR = ".cache/images-{size}"  # under the dataset root


def default_cache_dir(root: str | Path, size: int) -> Path:
    """Where a dataset's images at ``size`` px are cached by default."""
    return Path(root) / _DEFAULT_DIR.format(size=int(size))


def resize_like_transform(rgb: np.ndarray, transform: ImageTransform) -> np.ndarray:
    """``rgb`` (H, W, 3) uint8 resized to (S, S, 3) uint8 exactly as ``transform`` resizes it.

    Runs ``transform`` itself with mean 0 and std 1/255, under which its normalisation is the
    identity on the uint8 values (a multiply by 1.0 and an add of 0 in float32), so the cache
    holds the very pixels the transform would have normalised, whatever resampling it uses.
    """
    plain = dataclasses.replace(transform, mean=(0.0, 0.0, 0.0), std=(1 / 255,) * 3)
    image, _ = plain(rgb, np.zeros((0, 4), dtype=np.float32))
    out = image.permute(1, 2, 0).round_().clamp_(0, 255).to(torch.uint8)
    return np.ascontiguousarray(out.numpy())


def _resize_fingerprint(transform: ImageTransform) -> str:
    """SHA-256 of a fixed odd-sized probe image resized by ``transform``: changes with the
    resampling, so a cache built by an older resize is rebuilt rather than silently reused."""
    probe = np.random.default_rng(20261122).integers(0, 256, (37, 53, 3), dtype=np.uint8)
    return hashlib.sha256(resize_like_transform(probe, transform).tobytes()).hexdigest()


def _dataset_key(ds: Dataset) -> dict[str, Any]:
    m = ds.manifest
    return {"name": m.name, "version": m.version, "seed": int(m.seed)}


def _expected(ds: Dataset, split: str, transform: ImageTransform) -> dict[str, Any]:
    """The part of ``<split>.json`` that must match for the cache to be fresh."""
    try:
        paths = [p.relative_to(ds.root).as_posix() for p in ds.observation_files(split)]
        files = [{"path": p, "sha256": ds.manifest.file(p).sha256} for p in paths]
    except DatasetError as exc:
        raise DataError(" ".join(str(exc).split())) from None
    return {
        "cache_format": CACHE_FORMAT,
        "dataset": _dataset_key(ds),
        "split": split,
        "size": int(transform.size),
        "resize_sha256": _resize_fingerprint(transform),
        "files": files,
    }


@dataclass
class CachedImages:
    """The cached views of one split: an index and a lazily memory-mapped array.

    Attributes:
        path: the ``<split>.npy`` file.
        size: S, the side of every cached view.
        obs_ids: observation ids in array order (storage order).
        source_hw: (N, 2) int64, each view's decoded height and width before resizing.
    """

    path: Path
    size: int
    obs_ids: list[str]
    source_hw: np.ndarray
    _pid: int | None = dataclasses.field(default=None, repr=False)
    _array: np.ndarray | None = dataclasses.field(default=None, repr=False)

    def __len__(self) -> int:
        return len(self.obs_ids)

    def __getstate__(self) -> dict[str, Any]:
        state = dict(self.__dict__)
        state["_pid"], state["_array"] = None, None  # each process maps the file itself
        return state

    @property
    def array(self) -> np.ndarray:
        """(N, S, S, 3) uint8, read-only, mapped on first use in this process."""
        pid = os.getpid()
        if self._array is None or self._pid != pid:
            try:
                self._array = np.load(self.path, mmap_mode="r")
            except (OSError, ValueError) as exc:
                raise DataError(f"image cache {self.path}: unreadable ({exc})") from None
            self._pid = pid
        return self._array

    def image(self, i: int) -> np.ndarray:
        """View ``i`` as (S, S, 3) uint8 (a read-only view into the map)."""
        return self.array[i]


def _read_meta(path: Path) -> dict[str, Any] | None:
    try:
        meta = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return meta if isinstance(meta, dict) else None


def _npy_shape(path: Path) -> tuple[int, ...] | None:
    try:
        array = np.load(path, mmap_mode="r")
    except (OSError, ValueError):
        return None
    return tuple(array.shape) if array.dtype == np.uint8 else None


def _fresh(meta: dict[str, Any], expected: dict[str, Any], npy: Path) -> bool:
    if any(meta.get(k) != v for k, v in expected.items()):
        return False
    n, s = len(meta.get("obs_ids", [])), expected["size"]
    return len(meta.get("source_hw", [])) == n and _npy_shape(npy) == (n, s, s, 3)


def open_image_cache(
    ds: Dataset,
    split: str,
    transform: ImageTransform,
    *,
    cache_dir: str | Path | None = None,
) -> CachedImages:
    """The image cache of ``split`` at ``transform.size``, built or rebuilt first if needed.

    Args:
        ds: the open dataset.
        split: ``train``, ``val`` or ``test``.
        transform: the transform whose size and resampling the cache reproduces.
        cache_dir: where the cache lives (default :func:`default_cache_dir`). Given
            explicitly, a cache there of another dataset is refused, never overwritten.

    Raises:
        DataError: the split is missing, an explicit ``cache_dir`` holds another dataset's
            cache or is not a directory, or the cache cannot be written or read.
    """
    explicit = cache_dir is not None
    directory = Path(cache_dir) if explicit else default_cache_dir(ds.root, transform.size)
    if directory.exists() and not directory.is_dir():
        raise DataError(f"image cache {directory}: is a file; expected a cache directory")
    expected = _expected(ds, split, transform)
    npy, meta_path = directory / f"{split}.npy", directory / f"{split}.json"
    meta = _read_meta(meta_path)
    if explicit and meta is not None and meta.get("dataset") != expected["dataset"]:
        other = meta.get("dataset") or {}
        raise DataError(
            f"image cache {directory} holds {split} of dataset {other.get('name')!r} "
            f"{other.get('version')} (seed {other.get('seed')}), not {ds.manifest.name!r} "
            f"{ds.manifest.version} (seed {ds.manifest.seed}); give this dataset its own cache dir"
        )
    if meta is None or not _fresh(meta, expected, npy):
        meta = build_image_cache(ds, split, transform, directory, expected=expected)
    return CachedImages(
        path=npy,
        size=int(transform.size),
        obs_ids=list(meta["obs_ids"]),
        source_hw=np.asarray(meta["source_hw"], dtype=np.int64).reshape(-1, 2),
    )


def build_image_cache(
    ds: Dataset,
    split: str,
    transform: ImageTransform,
    directory: str | Path,
    *,
    expected: dict[str, Any] | None = None,
) -> dict[str, Any]:
    """Decode and resize every view of ``split`` into ``directory`` (atomically); its metadata.

    Raises:
        DataError: an observation file or image cannot be read, or ``directory`` not written.
    """
    directory = Path(directory)
    expected = expected or _expected(ds, split, transform)
    s = int(transform.size)
    try:
        files = ds.observation_files(split)
        counts = [_rows(p) for p in files]
    except OSError as exc:
        raise DataError(f"image cache {directory}: cannot write ({exc.strerror or exc})") from None
    obs_ids: list[str] = []
    source_hw: list[list[int]] = []
    try:
        with atomic_file(directory / f"{split}.npy") as tmp:
            shape = (sum(counts), s, s, 3)
            out = np.lib.format.open_memmap(tmp, mode="w+", dtype=np.uint8, shape=shape)
            at = 0
            for path in files:
                table = _read(path, ("obs_id", "image"))
                ids = table.column("obs_id").to_pylist()
                images = table.column("image")
                for k, obs in enumerate(ids):
                    try:
                        rgb = decode_image(images[k].as_py())
                    except DatasetError as exc:
                        raise DataError(f"observation {obs!r}: {exc}") from None
                    source_hw.append([int(rgb.shape[0]), int(rgb.shape[1])])
                    out[at] = resize_like_transform(rgb, transform)
                    at += 1
                obs_ids += ids
            out.flush()
            del out
            # no moment where an old JSON vouches for the new array
            (directory / f"{split}.json").unlink(missing_ok=True)
    except OSError as exc:
        raise DataError(f"image cache {directory}: cannot write ({exc.strerror or exc})") from None
    meta = {**expected, "obs_ids": obs_ids, "source_hw": source_hw}
    try:  # the JSON goes last: it is what marks the array as fresh
        atomic_write_text(directory / f"{split}.json", json.dumps(meta, sort_keys=True) + "\n")
    except OSError as exc:
        raise DataError(f"image cache {directory}: cannot write ({exc.strerror or exc})") from None
    return meta


def _read(path: Path, columns: tuple[str, ...]) -> Any:
    try:
        return read_table(path, observations_schema(), columns=columns)
    except DatasetError as exc:
        raise DataError(" ".join(str(exc).split())) from None


def _rows(path: Path) -> int:
    return _read(path, ("obs_id",)).num_rows
