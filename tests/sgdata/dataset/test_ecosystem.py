"""The generated dataset as the ML ecosystem opens it: Hugging Face ``datasets`` from the card,
MLCommons ``mlcroissant`` from croissant.json, and the card's YAML against the manifest."""

from __future__ import annotations

import io
import json
import logging
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest
import yaml
from PIL import Image

from sgdata.dataset import Dataset, read_manifest
from sgdata.dataset.card import read_front_matter

OFFLINE = {"HF_HUB_OFFLINE": "1", "HF_DATASETS_OFFLINE": "1"}

# Runs in a fresh interpreter that imports no sgdata: `datasets`, pyarrow and PIL only.
HF_SCRIPT = r"""
import io, sys
import numpy as np, pyarrow.dataset as pads, pyarrow.parquet as pq
from PIL import Image
import datasets

root, cache = sys.argv[1], sys.argv[2]
assert "sgdata" not in sys.modules
views = datasets.load_dataset(root, "observations", cache_dir=cache)
classes = views["train"].features["objects"].feature["class_id"].names
print("classes", ",".join(classes))
assert any(row["objects"] for row in views["train"])
for split, table in views.items():
    want = pads.dataset(f"{root}/observations/{split}", format="parquet").to_table()
    by_id = {r["obs_id"]: r for r in want.to_pylist()}
    assert table.num_rows == len(by_id) > 0, split
    for row in table:
        stored = by_id[row["obs_id"]]
        assert isinstance(row["image"], Image.Image)
        png = Image.open(io.BytesIO(stored["image"]["bytes"])).convert("RGB")
        assert np.array_equal(np.asarray(row["image"].convert("RGB")), np.asarray(png))
        assert row["objects"] == stored["objects"]
        assert all(isinstance(o, dict) for o in row["objects"])
        assert row["relations"] == stored["relations"]
        assert row["camera"] == stored["camera"] and row["seed"] == stored["seed"]
triplets = datasets.load_dataset(root, "triplets", cache_dir=cache)
for split, table in triplets.items():
    assert table.to_list() == pq.read_table(f"{root}/triplets/{split}.parquet").to_pylist()
plain = datasets.load_dataset(
    "parquet", data_files={"train": f"{root}/observations/train/*.parquet"}, cache_dir=cache
)
assert isinstance(plain["train"][0]["image"], Image.Image)
print("splits", ",".join(views), ",".join(triplets))
"""


def test_load_dataset_from_the_card_alone(mini_dataset: Path, tmp_path: Path) -> None:
    pytest.importorskip("datasets")
    env = {**os.environ, **OFFLINE, "HF_HOME": str(tmp_path / "hf")}
    done = subprocess.run(
        [sys.executable, "-c", HF_SCRIPT, str(mini_dataset), str(tmp_path / "cache")],
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    lines = dict(line.split(" ", 1) for line in done.stdout.splitlines() if " " in line)
    manifest = read_manifest(mini_dataset)
    assert lines["classes"].split(",") == [c.name for c in manifest.classes]
    splits = ",".join(manifest.splits)
    assert lines["splits"] == f"{splits} {splits}"


def _strip(record: dict, prefix: str) -> dict:
    """mlcroissant's record with its ``set/field`` keys as plain names, text decoded."""
    out = {}
    for key, value in record.items():
        name = key.rsplit("/", 1)[-1]
        if isinstance(value, dict):
            value = _strip(value, prefix)
        elif isinstance(value, list):
            value = [_strip(v, prefix) if isinstance(v, dict) else v for v in value]
        elif isinstance(value, bytes):
            value = value.decode()
        out[name] = value
    return out


def _close(a: object, b: object) -> bool:
    """Equal, floats to float32 precision (pandas hands float32 columns back as float64)."""
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(_close(a[k], b[k]) for k in a)
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(_close(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, float) or isinstance(b, float):
        return a is not None and b is not None and np.float32(a) == np.float32(b)
    return a == b


def test_croissant_validates_and_reads_the_parquet_rows(
    mini_dataset: Path, caplog: pytest.LogCaptureFixture
) -> None:
    mlc = pytest.importorskip("mlcroissant")
    with caplog.at_level(logging.WARNING):
        ds = mlc.Dataset(jsonld=str(mini_dataset / "croissant.json"))
    issues = ds.metadata.ctx.issues
    assert not issues.errors and not issues.warnings, issues.report()
    assert [r.getMessage() for r in caplog.records if r.levelno >= logging.WARNING] == []

    data = Dataset.open(mini_dataset)
    views = {
        r["obs_id"]: r
        for s in data.splits
        for r in pq.read_table(data.observation_files(s)[0]).to_pylist()
    }
    records = [_strip(r, "observations") for r in ds.records("observations")]
    assert sorted(r["obs_id"] for r in records) == sorted(views)
    for record in records:
        stored = dict(views[record["obs_id"]])
        png = stored.pop("image")["bytes"]
        image = record.pop("image")
        assert np.array_equal(
            np.asarray(image.convert("RGB")), np.asarray(Image.open(io.BytesIO(png)).convert("RGB"))
        )
        for name in ("objects", "relations"):
            stored.pop(name)
        assert _close(record, stored), record["obs_id"]
    for name in ("objects", "relations"):
        for record in map(lambda r: _strip(r, name), ds.records(name)):
            assert _close(record[name], views[record["obs_id"]][name]), record["obs_id"]
    triplets = [_strip(r, "triplets") for r in ds.records("triplets")]
    stored = [r for s in data.splits for r in data.triplets(s).to_pylist()]
    key = lambda r: (r["split"], r["triplet_id"])  # noqa: E731
    assert sorted(triplets, key=key) == sorted(stored, key=key)
    splits = [_strip(r, "splits")["name"] for r in ds.records("splits")]
    assert splits == data.splits


def test_card_yaml_parses_and_matches_the_manifest(mini_dataset: Path) -> None:
    manifest = read_manifest(mini_dataset)
    meta = yaml.safe_load(read_front_matter(mini_dataset / "README.md").strip("-\n"))
    configs = {c["config_name"]: c for c in meta["configs"]}
    assert configs["observations"]["default"] is True
    assert [f["split"] for f in configs["observations"]["data_files"]] == list(manifest.splits)
    assert {f["path"] for f in configs["triplets"]["data_files"]} <= {
        f.path for f in manifest.files
    }
    info = {i["config_name"]: i for i in meta["dataset_info"]}
    sizes = {s["name"]: s["num_examples"] for s in info["observations"]["splits"]}
    assert sizes == manifest.counts.observations
    sizes = {s["name"]: s["num_examples"] for s in info["triplets"]["splits"]}
    assert sizes == manifest.counts.triplets
    assert meta["license"] == "cc-by-4.0"
    datasets = pytest.importorskip("datasets")
    features = datasets.Features._from_yaml_list(info["observations"]["features"])
    assert isinstance(features["image"], datasets.Image)
    assert features["objects"].feature["class_id"].names == [c.name for c in manifest.classes]
    assert features["relations"].feature["type"].names == list(manifest.relation_types)
    body = (mini_dataset / "README.md").read_text()
    for needle in (
        "load_dataset",
        "pyarrow",
        "SELECT",
        "seannet",
        "@misc",
        manifest.generator.version,
    ):
        assert needle in body
    assert json.loads((mini_dataset / "croissant.json").read_text())["name"] == manifest.name
