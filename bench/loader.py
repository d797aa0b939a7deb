"""Triplets per second: the SeanNet DataLoader decoding PNG and reading the image cache.

    python bench/loader.py                  # generates the `tiny` preset into a temp dir
    python bench/loader.py --data out/tiny --size 112 --epochs 3 --threads 1
    python bench/loader.py --data /work/data/medium --no-png --cache-dir /tmp/c224

Two raw reads bound the two loader paths. The PNG bound reads the image column of every
observation shard of the split once and decodes the three images of every triplet; the cache
bound copies the three cached (S, S, 3) uint8 views of every triplet out of the memory-mapped
image cache (:mod:`seannet.data.image_cache`). Neither resizes, normalises or builds graph tensors.
The loader runs `DataLoader(TripletDataset, batch_size=8, collate_fn=collate_triplets)` with 0
and 2 workers (persistent, so epochs after the first reuse the workers' shard caches), once
decoding PNG and once with ``cache=True``; it prints the first (cold) epoch and the mean of the
later (warm) ones, each as a ratio to its path's bound, as one Markdown table. The batches are
the loader's compact ones (uint8 pixels, sparse adjacency: ``SceneBatch.prepare`` converts
them on the model's device), so the table measures what a training process's CPU does.

The headline, printed last: the cache path (``num_workers=0``) against the raw cache read,
measured in alternating epochs (``--rounds`` of each, after a warm-up) so that both see the
same machine load, as the median of each and their ratio; the aims are >= 1,000 triplets/s and
>= 0.8 of the raw read. The cache is built (or found fresh) under
``<data>/.cache/images-<size>`` before timing, or in ``--cache-dir``; its build time is
printed apart. ``--threads`` sets the main process's torch threads (workers always use 1).
"""

from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import torch
from torch.utils.data import DataLoader

from seannet.data.datasets import ImageTransform, TripletDataset, collate_triplets
from seannet.data.image_cache import open_image_cache
from sgdata.dataset import Dataset, decode_image
from sgdata.markdown import table


def generate_tiny(root: Path) -> None:
    from sgdata.pipeline.config import load_config
    from sgdata.pipeline.generate import generate_dataset

    print(f"generating the tiny preset into {root} ...", flush=True)
    generate_dataset(load_config("tiny"), root, workers=2)


def raw_epoch(root: Path, split: str) -> float:
    """Seconds to read every shard's image column and decode each triplet's three images."""
    t0 = time.perf_counter()
    ds = Dataset.open(root)
    images = {}
    for path in ds.observation_files(split):
        table = pq.read_table(path, columns=["obs_id", "image"])
        images.update(zip(table.column("obs_id").to_pylist(), table.column("image"), strict=True))
    triplets = pq.read_table(ds.root / "triplets" / f"{split}.parquet")
    for name in ("anchor", "positive", "negative"):
        for obs in triplets.column(name).to_pylist():
            decode_image(images[obs].as_py())
    return time.perf_counter() - t0


def raw_cache_reader(
    root: Path, split: str, size: int, cache_dir: Path | None, *, batch_size: int = 0
) -> Callable[[], float]:
    """A function timing one raw read of the cache.

    ``batch_size`` 0 (the bound): each triplet's three views copied out one by one
    (``np.array(view)``, each dropped before the next, so its buffer is reused warm). Otherwise
    the pixel work of a batch loader and nothing else: the 3 x ``batch_size`` views of each
    batch of triplets, in a shuffled order, taken into one batch array (two kept in turn,
    as a training loop holds one batch while the next is read).

    Opening the cache (its freshness check) and reading the triplet table are not timed: the
    bound is mapping the array and the reads, what every epoch of a loader over the cache must
    do at least.
    """
    ds = Dataset.open(root)
    images = open_image_cache(ds, split, ImageTransform(size=size), cache_dir=cache_dir)
    row = {obs: i for i, obs in enumerate(images.obs_ids)}
    triplets = pq.read_table(ds.root / "triplets" / f"{split}.parquet")
    names = ("anchor", "positive", "negative")
    rows = np.asarray([[row[o] for o in triplets.column(n).to_pylist()] for n in names])
    order = np.random.default_rng(0).permutation(rows.shape[1])
    batches = [
        rows[:, order[k : k + batch_size]].ravel() for k in range(0, len(order), batch_size or 1)
    ]
    buffers = [np.empty((3 * batch_size, size, size, 3), np.uint8) for _ in range(2)]

    def epoch() -> float:
        t0 = time.perf_counter()
        array = np.load(images.path, mmap_mode="r")
        if not batch_size:
            for i in rows.ravel().tolist():
                np.array(array[i])
        else:
            for k, b in enumerate(batches):
                out = buffers[k % 2][: len(b)]
                np.take(array, b, axis=0, out=out, mode="clip")
        return time.perf_counter() - t0

    return epoch


def triplet_loader(
    root: Path, split: str, size: int, workers: int, batch_size: int, cache: bool | Path = False
) -> DataLoader:
    """A DataLoader over a fresh TripletDataset, as training builds one."""
    data = TripletDataset(root, split, transform=ImageTransform(size=size), cache=cache)
    return DataLoader(
        data,
        batch_size=batch_size,
        shuffle=True,
        num_workers=workers,
        collate_fn=collate_triplets,
        persistent_workers=workers > 0,
    )


def loader_epoch(loader: DataLoader) -> float:
    """Seconds to draw every batch of one epoch."""
    t0 = time.perf_counter()
    for _batch in loader:
        pass
    return time.perf_counter() - t0


def loader_epochs(
    root: Path,
    split: str,
    size: int,
    workers: int,
    epochs: int,
    batch_size: int,
    cache: bool | Path = False,
) -> list[float]:
    """Seconds per epoch of a DataLoader over a fresh TripletDataset (its opening included
    in the first)."""
    t0 = time.perf_counter()
    loader = triplet_loader(root, split, size, workers, batch_size, cache)
    times = [loader_epoch(loader) + time.perf_counter() - t0]
    times += [loader_epoch(loader) for _ in range(epochs - 1)]
    return times


def interleaved(
    root: Path, split: str, size: int, batch_size: int, cache: bool | Path, rounds: int
) -> tuple[float, float, float]:
    """Median seconds of the raw cache read, the raw batch gather and a cache loader epoch
    (``num_workers=0``), measured in turn ``rounds`` times each after one warm-up."""
    cache_dir = None if cache is True else Path(cache)
    raw = raw_cache_reader(root, split, size, cache_dir)
    gather = raw_cache_reader(root, split, size, cache_dir, batch_size=batch_size)
    loader = triplet_loader(root, split, size, 0, batch_size, cache)
    raw(), gather(), loader_epoch(loader)  # warm: page cache, graph arrays, buffers
    times: list[list[float]] = [[], [], []]
    for _ in range(rounds):
        for kind, run in enumerate((raw, gather, lambda: loader_epoch(loader))):
            times[kind].append(run())
    raw_s, gather_s, load_s = (statistics.median(t) for t in times)
    return raw_s, gather_s, load_s


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", type=Path, help="dataset root (default: generate tiny)")
    parser.add_argument("--split", default="train")
    parser.add_argument("--size", type=int, default=224, help="ImageTransform size")
    parser.add_argument("--epochs", type=int, default=3)
    parser.add_argument("--batch-size", type=int, default=8)
    parser.add_argument("--threads", type=int, default=1, help="main-process torch threads")
    parser.add_argument("--cache-dir", type=Path, help="image cache dir (default: under --data)")
    parser.add_argument("--rounds", type=int, default=20, help="alternating epochs, headline")
    parser.add_argument("--no-png", action="store_true", help="skip the PNG rows (big data)")
    args = parser.parse_args()
    torch.set_num_threads(args.threads)

    tmp = None
    root = args.data
    if root is None:
        tmp = tempfile.TemporaryDirectory(prefix="seannet-loader-")
        root = Path(tmp.name) / "tiny"
        generate_tiny(root)
    n = len(TripletDataset(root, args.split))
    ds = Dataset.open(root)
    print(
        f"dataset {ds.manifest.name} {args.split}: {n} triplets, "
        f"{ds.manifest.image.width}x{ds.manifest.image.height} {ds.manifest.image.format}; "
        f"resize to {args.size}, batch {args.batch_size}, {args.epochs} epochs, "
        f"{args.threads} torch thread(s); load average {os.getloadavg()[0]:.1f}"
    )

    t0 = time.perf_counter()
    open_image_cache(ds, args.split, ImageTransform(size=args.size), cache_dir=args.cache_dir)
    print(f"image cache built or found fresh in {time.perf_counter() - t0:.2f} s")

    rows = []
    paths = [("cache", args.cache_dir or True)]
    if not args.no_png:
        raw_epoch(root, args.split)  # warm the page cache
        png_bound = n / min(raw_epoch(root, args.split) for _ in range(3))
        rows.append(("raw Parquet read + PNG decode (PNG bound)", png_bound, 1.0))
        paths.insert(0, ("PNG", False))
    read = raw_cache_reader(root, args.split, args.size, args.cache_dir)
    read()
    cache_bound = n / min(read() for _ in range(3))
    rows.append(("raw memmap read of the cache (cache bound)", cache_bound, 1.0))
    bounds = {"PNG": rows[0][1], "cache": cache_bound}
    for path, cache in paths:
        for workers in (0, 2):
            times = loader_epochs(
                root, args.split, args.size, workers, args.epochs, args.batch_size, cache
            )
            label = f"DataLoader {path}, num_workers={workers}"
            bound = bounds[path]
            rows.append((f"{label}, epoch 1", n / times[0], n / times[0] / bound))
            if len(times) > 1:
                warm = n / (sum(times[1:]) / len(times[1:]))
                rows.append((f"{label}, epochs 2-{len(times)}", warm, warm / bound))
    cells = ((label, f"{rate:,.1f}", f"{ratio:.2f}") for label, rate, ratio in rows)
    print("\n" + "\n".join(table(("", "triplets/s", "/ bound"), cells)))

    raw_s, gather_s, load_s = interleaved(
        root, args.split, args.size, args.batch_size, args.cache_dir or True, args.rounds
    )
    ratio = raw_s / load_s
    print(
        f"\ncache path, num_workers=0, batch {args.batch_size}, {args.size} px: medians of "
        f"{args.rounds} rounds, each a raw read, a raw batch gather and a loader epoch "
        f"(load average {os.getloadavg()[0]:.1f})\n"
        f"  raw read (the cache bound)       {n / raw_s:9,.0f} triplets/s\n"
        f"  raw batch gather (pixels only)   {n / gather_s:9,.0f} triplets/s\n"
        f"  TripletDataset + DataLoader      {n / load_s:9,.0f} triplets/s: "
        f"{ratio:.2f} of the raw read, {gather_s / load_s:.2f} of the batch gather\n"
        f"  aims: >= 1,000 triplets/s {'met' if n / load_s >= 1000 else 'NOT met'}; "
        f">= 0.8 of the raw read {'met' if ratio >= 0.8 else 'NOT met'}"
    )
    if tmp is not None:
        tmp.cleanup()


if __name__ == "__main__":
    main()
