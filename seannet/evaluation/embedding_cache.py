"""A run's embeddings of a split kept beside its checkpoint, so a split is embedded once.

One run is evaluated many times on the same views: plain, ``+boxes``, ``+box-kernel``, under
each box noise, and every test evaluation embeds val too (epsilon and lambda are read there).
The embeddings are stored in ``<run>/embeddings/<split>[_<noise>].npz`` under a key: the
sha256 of the checkpoint and of the dataset's manifest, the split, the noise, and the code
that embeds (the sha256 of the source of :data:`EMBEDDING_CODE`: the model, the data
pipeline and transforms, the dataset reader, the embedding loop). A retrained run, another
dataset or a change to a forward or a transform changes the key, and a file whose key differs
is embedded again and replaced: a stale file is never read. Files are written atomically
(temp + rename).
"""

from __future__ import annotations

import functools
import hashlib
import importlib.util
import io
import json
from collections.abc import Callable, Sequence
from dataclasses import asdict
from pathlib import Path

import numpy as np

from seannet.data.box_noise import BoxNoise
from seannet.data.opening import DataSource
from seannet.evaluation.metrics import Embeddings
from seannet.training.runs import BEST
from sgdata.dataset import Dataset
from sgdata.dataset.paths import MANIFEST
from sgdata.fileio import atomic_write_bytes, sha256_file

__all__ = [
    "CACHE_DIR",
    "EMBEDDING_CODE",
    "cached_embeddings",
    "embedding_code_sha256",
    "source_sha256",
]

CACHE_DIR = "embeddings"
# The modules (a package: every .py under it) whose code decides a split's embeddings: the
# networks, what turns rows into tensors (transforms, graphs, box noise), the dataset reader,
# restoring a run, the embedding loop and this file's own stored form
EMBEDDING_CODE = (
    "seannet.model",
    "seannet.data",
    "seannet.weights",
    "seannet.training.config",
    "seannet.training.loop",
    "seannet.training.runs",
    "seannet.evaluation.metrics",
    "seannet.evaluation.embedding_cache",
    "sgdata.dataset",
)
_ARRAYS = ("vectors", "room", "layout", "grid_i", "grid_j", "heading")


def cached_embeddings(
    run: Path,
    data: DataSource,
    split: str,
    noise: BoxNoise | None,
    embed: Callable[[], Embeddings],
) -> Embeddings:
    """``embed()``, or what it returned for the same checkpoint, dataset (opened, or its
    root), split, noise and embedding code."""
    key = json.dumps(
        {
            "checkpoint_sha256": sha256_file(run / BEST)[0],
            "code_sha256": embedding_code_sha256(),
            "manifest_sha256": _manifest_sha256(data),
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


def _manifest_sha256(data: DataSource) -> str:
    """The fingerprint of the dataset: an opened one's, read with its manifest (nothing is
    read again), or the file's at ``data/dataset.json`` for a root."""
    if isinstance(data, Dataset):
        return data.manifest_sha256
    return sha256_file(Path(data) / MANIFEST)[0]


@functools.cache
def embedding_code_sha256() -> str:
    """:func:`source_sha256` of :data:`EMBEDDING_CODE`, read once per process at its first
    use (a source edited between a process's imports and that use would be keyed as the
    edited code: evaluate in a fresh process after editing)."""
    return source_sha256(EMBEDDING_CODE)


def source_sha256(modules: Sequence[str]) -> str:
    """sha256 over the source files of ``modules`` (dotted names; a package counts every
    ``.py`` file under it), each file named by its path inside its package, in sorted order.
    The modules are located, not imported (their parent packages are)."""
    digest = hashlib.sha256()
    for name in modules:
        spec = importlib.util.find_spec(name)
        if spec is None or spec.origin is None:
            raise ModuleNotFoundError(f"embedding code {name!r}: no such module")
        origin = Path(spec.origin)
        files = sorted(origin.parent.rglob("*.py")) if spec.submodule_search_locations else [origin]
        for path in files:
            relative = f"{name}/{path.relative_to(origin.parent).as_posix()}"
            source = path.read_bytes()
            digest.update(f"{relative}\0{len(source)}\0".encode() + source)
    return digest.hexdigest()
