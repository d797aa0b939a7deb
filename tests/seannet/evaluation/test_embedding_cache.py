"""Embeddings kept beside a run: read back equal, never stale, rewritten when unreadable."""

from __future__ import annotations

import io
import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from seannet.data.box_noise import BoxNoise
from seannet.evaluation import run_eval as evaluation
from seannet.evaluation.embedding_cache import (
    CACHE_DIR,
    EMBEDDING_CODE,
    cached_embeddings,
    embedding_code_sha256,
    source_sha256,
)
from seannet.evaluation.metrics import Embeddings
from seannet.evaluation.run_eval import evaluate_run


def _embeddings(seed: int) -> Embeddings:
    rng = np.random.default_rng(seed)
    return Embeddings(
        obs_ids=["kitchen_1/a", "kitchen_1/b", "bath_2/c"],
        vectors=rng.normal(size=(3, 4)).astype(np.float32),
        room=np.array(["kitchen_1", "kitchen_1", "bath_2"]),
        layout=np.array([0, 1, 0]),
        grid_i=np.array([1, 1, 2]),
        grid_j=np.array([0, 0, -1]),
        heading=np.array([3, 3, 0]),
        slot_boxes=(np.array([0, 1, 3, 3]), np.array([4, 4, 7]), rng.uniform(size=(3, 4))),
        num_slots=8,
    )


def _rekey(path: Path, **changes: str) -> None:
    """Rewrite a cache file's key with some of its parts changed (as older code wrote it)."""
    with np.load(path, allow_pickle=False) as stored:
        arrays = dict(stored)
    key = json.loads(str(arrays["key"]))
    assert set(changes) <= set(key)
    arrays["key"] = np.array(json.dumps({**key, **changes}, sort_keys=True))
    buffer = io.BytesIO()
    np.savez(buffer, **arrays)
    path.write_bytes(buffer.getvalue())


def _fail() -> Embeddings:
    raise AssertionError("embedded again although the cache holds these embeddings")


def test_read_back_equal_and_embedded_again_when_anything_in_the_key_changes(
    tmp_path: Path,
) -> None:
    run, data = tmp_path / "run", tmp_path / "data"
    run.mkdir()
    data.mkdir()
    (run / "best.pt").write_bytes(b"checkpoint 1")
    (data / "dataset.json").write_text("{}")
    first = cached_embeddings(run, data, "val", None, lambda: _embeddings(0))
    again = cached_embeddings(run, data, "val", None, _fail)
    for name in ("vectors", "room", "layout", "grid_i", "grid_j", "heading"):
        assert np.array_equal(getattr(again, name), getattr(first, name))
    assert again.obs_ids == first.obs_ids and again.num_slots == 8
    assert all(
        np.array_equal(a, b) for a, b in zip(again.slot_boxes, first.slot_boxes, strict=True)
    )
    # the split and the noise name the file too: the val file copied under the other name
    # must be refused by its key alone
    cache = run / CACHE_DIR
    noise = BoxNoise(jitter=0.05)
    shutil.copy(cache / "val.npz", cache / "test.npz")
    assert np.array_equal(
        cached_embeddings(run, data, "test", None, lambda: _embeddings(1)).vectors,
        _embeddings(1).vectors,
    )
    shutil.copy(cache / "val.npz", cache / f"val_{noise.label()}.npz")
    assert np.array_equal(
        cached_embeddings(run, data, "val", noise, lambda: _embeddings(2)).vectors,
        _embeddings(2).vectors,
    )
    # embeddings of other code (a forward or a transform changed since): embedded again
    _rekey(cache / "val.npz", code_sha256="0" * 64)
    assert np.array_equal(
        cached_embeddings(run, data, "val", None, lambda: _embeddings(6)).vectors,
        _embeddings(6).vectors,
    )
    again = cached_embeddings(run, data, "val", None, _fail)  # and kept under the right key
    assert np.array_equal(again.vectors, _embeddings(6).vectors)
    (run / "best.pt").write_bytes(b"checkpoint 2")  # retrained
    assert np.array_equal(
        cached_embeddings(run, data, "val", None, lambda: _embeddings(3)).vectors,
        _embeddings(3).vectors,
    )
    (data / "dataset.json").write_text('{"another": 1}')  # another dataset
    assert np.array_equal(
        cached_embeddings(run, data, "val", None, lambda: _embeddings(4)).vectors,
        _embeddings(4).vectors,
    )
    (run / CACHE_DIR / "val.npz").write_bytes(b"not a zip")  # unreadable: embedded again
    assert np.array_equal(
        cached_embeddings(run, data, "val", None, lambda: _embeddings(5)).vectors,
        _embeddings(5).vectors,
    )
    assert not list((run / CACHE_DIR).glob(".*.tmp"))


def test_an_evaluation_embeds_each_split_once(
    tmp_path: Path, mini_dataset: Path, localizer_run: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    plain = evaluate_run(localizer_run, mini_dataset, split="test", out=tmp_path / "a")
    monkeypatch.setattr(evaluation, "embed_split", lambda *_a, **_k: _fail())
    boxed = evaluate_run(localizer_run, mini_dataset, split="test", out=tmp_path / "b")
    assert boxed["accuracy"] == plain["accuracy"] and boxed["mean_gap"] == plain["mean_gap"]
    evaluate_run(localizer_run, mini_dataset, split="test", out=tmp_path / "c", boxes="+boxes")


def test_the_code_version_is_the_embedding_codes_source(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    package = tmp_path / "fake_embedder"
    (package / "nets").mkdir(parents=True)
    (package / "__init__.py").write_text("")
    (package / "nets" / "forward.py").write_text("def forward(x):\n    return x\n")
    (tmp_path / "transform.py").write_text("SIZE = 112\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    modules = ("fake_embedder", "transform")
    before = source_sha256(modules)
    assert source_sha256(modules) == before
    (package / "nets" / "forward.py").write_text("def forward(x):\n    return 2 * x\n")
    edited = source_sha256(modules)
    assert edited != before  # a file inside the package
    (tmp_path / "transform.py").write_text("SIZE = 224\n")
    assert source_sha256(modules) not in (before, edited)  # a single module
    # the real key covers the networks and the data pipeline, and is stable in a process
    assert {"seannet.model", "seannet.data"} <= set(EMBEDDING_CODE)
    assert embedding_code_sha256() == source_sha256(EMBEDDING_CODE)
