"""Triplets per second: the SeanNet DataLoader against raw Parquet read + PNG decode.

    python bench/loader.py                  # generates the `tiny` preset into a temp dir
    python bench/loader.py --data out/tiny --size 112 --epochs 3 --threads 1

The lower bound reads the image column of every observation shard of the split once and
decodes the three images of every triplet (no resize, normalisation or graph tensors). The
loader runs `DataLoader(TripletDataset, batch_size=8, collate_fn=collate_triplets)` with 0 and
2 workers (persistent, so epochs after the first reuse the workers' shard caches); it prints
the first (cold) epoch and the mean of the later (warm) ones, each as a ratio to the bound.
``--threads`` sets the main process's torch threads (workers always use 1): on a small or
busy machine, torch's intra-op pool can make collation (torch.stack) tens of times slower.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import pyarrow.parquet as pq
import torch

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from torch.utils.data import DataLoader  # noqa: E402

from seannet.data import ImageTransform, TripletDataset, collate_triplets  # noqa: E402
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


def loader_epochs(
    root: Path, split: str, size: int, workers: int, epochs: int, batch_size: int
) -> list[float]:
    """Seconds per epoch of a DataLoader over a fresh TripletDataset."""
    t0 = time.perf_counter()
    data = TripletDataset(root, split, transform=ImageTransform(size=size))
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

    raw_epoch(root, args.split)  # warm the page cache
    raw = min(raw_epoch(root, args.split) for _ in range(3))
    bound = n / raw
    print(f"{'raw Parquet read + PNG decode (bound)':<40} {bound:8.1f} triplets/s")
    for workers in (0, 2):
        times = loader_epochs(root, args.split, args.size, workers, args.epochs, args.batch_size)
        cold = n / times[0]
        label = f"DataLoader num_workers={workers}"
        line = f"{label + ', epoch 1':<40} {cold:8.1f} triplets/s  ({cold / bound:.2f} x bound)"
        print(line)
        if len(times) > 1:
            warm = n / (sum(times[1:]) / len(times[1:]))
            label = f"{label}, epochs 2-{len(times)}"
            print(f"{label:<40} {warm:8.1f} triplets/s  ({warm / bound:.2f} x bound)")
    if tmp is not None:
        tmp.cleanup()


if __name__ == "__main__":
    main()
