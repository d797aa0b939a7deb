"""A run's embeddings of a split kept beside its checkpoint, so a split is embedded once.

One run is evaluated many times on the same views: plain, ``+boxes``, ``+box-kernel``, under
each box noise, and every test evaluation embeds val too (epsilon and lambda are read there).
The embeddings are stored in ``<run>/embeddings/<split>[_<noise>].npz`` under a key: the
sha256 of the checkpoint and of the dataset's manifest, the split and the noise. A retrained
run or another dataset changes the key, and a file whose key differs is embedded again and
replaced: a stale file is never read. Files are written atomically (temp + rename).
"""

from __future__ import annotations

import io
import json
from collections.abc import Callable
from dataclasses import asdict
from pathlib import Path

import numpy as np

from seannet.data.box_noise import BoxNoise
from seannet.evaluation.metrics import Embeddings
from seannet.training.runs import BEST
from sgdata.dataset.paths import MANIFEST
from sgdata.fileio import atomic_write_bytes, sha256_file

__all__ = ["CACHE_DIR", "cached_embeddings"]

CACHE_DIR = "embeddings"
_ARRAYS = ("vectors", "room", "layout", "grid_i", "grid_j", "heading")


def cached_embeddings(
    run: Path,
    data: Path,
    split: str,
    noise: BoxNoise | None,
    embed: Callable[[], Embeddings],
) -> Embeddings:
    """``embed()``, or what it returned for the same checkpoint, dataset, split and noise."""
    key = json.dumps(
        {
            "checkpoint_sha256": sha256_file(run / BEST)[0],
            "manifest_sha256": sha256_file(data / MANIFEST)[0],
            "split": split,
            "noise": asdict(noise) if noise is not None and noise.active else None,
        },
        sort_keys=True,
    )
    name = split + (f"_{noise.label()}" if noise is not None and noise.active else "")
    path = run / CACHE_DIR / f"{name}.npz"
    if path.exists():
        try:
            with np.load(path, allow_pickle=False) as stored:
                if str(stored["key"]) == key:
                    return _embeddings(stored)
        except (OSError, ValueError, KeyError):  # unreadable: embed again and replace it
            pass
    embeddings = embed()
    buffer = io.BytesIO()
    assert embeddings.slot_boxes is not None  # embed_split always fills it
    offsets, slots, boxes = embeddings.slot_boxes
    np.savez(
        buffer,
        key=np.array(key),
        obs_ids=np.array(embeddings.obs_ids),
        num_slots=np.array(embeddings.num_slots),
        box_offsets=offsets,
        box_slots=slots,
        boxes=boxes,
        **{name: getattr(embeddings, name) for name in _ARRAYS},
    )
    atomic_write_bytes(path, buffer.getvalue())
    return embeddings


def _embeddings(stored: np.lib.npyio.NpzFile) -> Embeddings:
    return Embeddings(
        obs_ids=stored["obs_ids"].tolist(),
        **{name: stored[name] for name in _ARRAYS},
        slot_boxes=(stored["box_offsets"], stored["box_slots"], stored["boxes"]),
        num_slots=int(stored["num_slots"]),
    )
