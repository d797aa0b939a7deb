"""Triplets per second: the SeanNet DataLoader decoding PNG and reading the image cache.

    python bench/loader.py                  # generates the `tiny` preset into a temp dir
    python bench/loader.py --data out/tiny --size 112 --epochs 3 --threads 1

Two raw reads bound the two loader paths. The PNG bound reads the image column of every
observation shard of the split once and decodes the three images of every triplet; the cache
bound copies the three cached (S, S, 3) uint8 views of every triplet out of the memory-mapped
image cache (:mod:`seannet.image_cache`). Neither resizes, normalises or builds graph tensors.
The loader runs `DataLoader(TripletDataset, batch_size=8, collate_fn=collate_triplets)` with 0
and 2 workers (persistent, so epochs after the first reuse the workers' shard caches), once
decoding PNG and once with ``cache=True``; it prints the first (cold) epoch and the mean of the
later (warm) ones, each as a ratio to its path's bound, as one Markdown table. The cache is
built (or found fresh) under ``<data>/.cache/images-<size>`` before timing, or in
``--cache-dir``; its build time is printed apart.
``--threads`` sets the main process's torch threads (workers always use 1): on a small or
busy machine, torch's intra-op pool can make collation (torch.stack) tens of times slower.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import torch

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from torch.utils.data import DataLoader  # noqa: E402

from seannet.data import ImageTransform, TripletDataset, collate_triplets  # noqa: E402
from seannet.image_cache import open_image_cache  # noqa: E402
from sgdata.dataset import Dataset, decode_image  # noqa: E402


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


def raw_cache_epoch(root: Path, split: str, size: int, cache_dir: Path | None) -> float:
    """Seconds to copy each triplet's three views out of the memory-mapped image cache.

    Opening the cache (its freshness check) and reading the triplet table are not timed: the
    bound is the reads alone, what every epoch of a loader over the cache must do.
    """
    ds = Dataset.open(root)
    images = open_image_cache(ds, split, ImageTransform(size=size), cache_dir=cache_dir)
    row = {obs: i for i, obs in enumerate(images.obs_ids)}
    triplets = pq.read_table(ds.root / "triplets" / f"{split}.parquet")
    rows = [
        row[o] for n in ("anchor", "positive", "negative") for o in triplets.column(n).to_pylist()
    ]
    t0 = time.perf_counter()
    array = np.load(images.path, mmap_mode="r")
    for i in rows:
        np.array(array[i])
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
    """Seconds per epoch of a DataLoader over a fresh TripletDataset."""
    t0 = time.perf_counter()
    data = TripletDataset(root, split, transform=ImageTransform(size=size), cache=cache)
    loader = DataLoader(
        data,
        batch_size=batch_size,
        shuffle=True,
        num_workers=workers,
        collate_fn=collate_triplets,
        persistent_workers=workers > 0,
    )
    times = []
    for _ in range(epochs):
        for _batch in loader:
            pass
        times.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
    return times


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", type=Path, help="dataset root (default: generate tiny)")
    parser.add_argument("--split", default="train")
    parser.add_argument("--size", type=int, default=224, help="ImageTransform size")
    parser.add_argument("--epochs", type=int, default=3)
    parser.add_argument("--batch-size", type=int, default=8)
    parser.add_argument("--threads", type=int, default=1, help="main-process torch threads")
    parser.add_argument("--cache-dir", type=Path, help="image cache dir (default: under --data)")
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
        f"{args.threads} torch thread(s)"
    )

    t0 = time.perf_counter()
    open_image_cache(ds, args.split, ImageTransform(size=args.size), cache_dir=args.cache_dir)
    print(f"image cache built or found fresh in {time.perf_counter() - t0:.2f} s")

    raw_epoch(root, args.split)  # warm the page cache
    png_bound = n / min(raw_epoch(root, args.split) for _ in range(3))
    raw_cache_epoch(root, args.split, args.size, args.cache_dir)
    cache_bound = n / min(
        raw_cache_epoch(root, args.split, args.size, args.cache_dir) for _ in range(3)
    )
    rows = [("raw Parquet read + PNG decode (PNG bound)", png_bound, 1.0)]
    rows.append(("raw memmap read of the cache (cache bound)", cache_bound, 1.0))
    for path, cache, bound in (
        ("PNG", False, png_bound),
        ("cache", args.cache_dir or True, cache_bound),
    ):
        for workers in (0, 2):
            times = loader_epochs(
                root, args.split, args.size, workers, args.epochs, args.batch_size, cache
            )
            label = f"DataLoader {path}, num_workers={workers}"
            rows.append((f"{label}, epoch 1", n / times[0], n / times[0] / bound))
            if len(times) > 1:
                warm = n / (sum(times[1:]) / len(times[1:]))
                rows.append((f"{label}, epochs 2-{len(times)}", warm, warm / bound))
    print("\n| | triplets/s | / bound |\n|---|---|---|")
    for label, rate, ratio in rows:
        print(f"| {label} | {rate:.1f} | {ratio:.2f} |")
    if tmp is not None:
        tmp.cleanup()


if __name__ == "__main__":
    main()
