"""The image cache: same tensors as decoding PNG, rebuilt when stale, refused when foreign."""

from __future__ import annotations

import json
import pickle
import shutil
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
import torch
from torch.utils.data import DataLoader

from seannet.data.datasets import (
    ImageTransform,
    ObservationDataset,
    TripletDataset,
    collate_triplets,
)
from seannet.data.image_cache import default_cache_dir, open_image_cache, resize_like_transform
from seannet.errors import DataError
from sgdata.dataset import Dataset, decode_image, write_parquet
from sgdata.fileio import TEMP_GLOB

SIZE = 64  # the tests' resize target (the mini dataset renders 96 x 96)
SHARD = "observations/train/bathroom_000.parquet"  # the mini dataset's train room


@pytest.fixture
def copy(mini_dataset: Path, tmp_path: Path) -> Path:
    target = tmp_path / "copy"
    shutil.copytree(mini_dataset, target)
    return target


def edit_manifest(root: Path, change: Callable[[dict], None]) -> None:
    raw = json.loads((root / "dataset.json").read_text())
    change(raw)
    (root / "dataset.json").write_text(json.dumps(raw, indent=2))


def rewrite(root: Path, rel: str, table: pa.Table) -> None:
    """Write ``table`` over ``rel`` and fix its rows / sha256 / bytes in the manifest."""
    info = write_parquet(table, root / rel)

    def fix(raw: dict) -> None:
        for entry in raw["files"]:
            if entry["path"] == rel:
                entry.update(rows=info.rows, sha256=info.sha256, bytes=info.bytes)

    edit_manifest(root, fix)


def assert_same_views(a: object, b: object) -> None:
    for name in ("image", "boxes", "class_ids", "slots", "edge_index", "edge_weight"):
        assert torch.equal(getattr(a, name), getattr(b, name)), name


# ---------------------------------------------------------------------------------- tensors


@pytest.mark.parametrize("size", [SIZE, 96, 77])  # shrink, as stored, odd enlarge-free size
def test_cached_tensors_equal_png_tensors(mini_dataset: Path, tmp_path: Path, size: int) -> None:
    transform = ImageTransform(size=size)
    png = TripletDataset(mini_dataset, "train", transform=transform)
    cached = TripletDataset(mini_dataset, "train", transform=transform, cache=tmp_path / "c")
    assert len(png) == len(cached)
    for i in range(len(png)):
        a, b = png[i], cached[i]
        for role in ("anchor", "positive", "negative"):
            assert_same_views(getattr(a, role), getattr(b, role))
        assert a.ids == b.ids and a.tier == b.tier
    views = ObservationDataset(mini_dataset, "test", transform=transform)
    cached_views = ObservationDataset(
        mini_dataset, "test", transform=transform, cache=tmp_path / "c"
    )
    assert cached_views.obs_ids == views.obs_ids
    for i in range(len(views)):
        assert_same_views(views[i].view, cached_views[i].view)


def test_cache_holds_the_transforms_pixels(mini_dataset: Path, tmp_path: Path) -> None:
    ds = Dataset.open(mini_dataset)
    transform = ImageTransform(size=SIZE)
    images = open_image_cache(ds, "train", transform, cache_dir=tmp_path)
    first = pq.read_table(ds.observation_files("train")[0], columns=["obs_id", "image"])
    rgb = decode_image(first.column("image")[0].as_py())
    assert images.obs_ids[0] == first.column("obs_id")[0].as_py()
    assert images.array.shape == (len(images), SIZE, SIZE, 3)
    assert images.array.dtype == np.uint8 and not images.array.flags.writeable
    np.testing.assert_array_equal(images.image(0), resize_like_transform(rgb, transform))
    # normalising the cached pixels gives what the transform gives from the decoded ones
    want, _ = transform(rgb, np.zeros((0, 4)))
    got, _ = transform(np.asarray(images.image(0)), np.zeros((0, 4)))
    assert torch.equal(want, got)
    assert images.source_hw.tolist() == [[96, 96]] * len(images)


def test_workers_get_the_same_tensors(mini_dataset: Path, tmp_path: Path) -> None:
    transform = ImageTransform(size=SIZE)
    png = TripletDataset(mini_dataset, "train", transform=transform)
    data = TripletDataset(mini_dataset, "train", transform=transform, cache=tmp_path)
    kwargs = dict(batch_size=5, shuffle=False, collate_fn=collate_triplets)
    serial = list(DataLoader(png, num_workers=0, **kwargs))
    data[0]  # the parent has mapped the cache: workers map it themselves
    assert data._store.cached._array is not None
    parallel = list(DataLoader(data, num_workers=2, **kwargs))
    assert len(serial) == len(parallel)
    for a, b in zip(serial, parallel, strict=True):
        for x, y in zip(a[:3], b[:3], strict=True):
            x, y = x.prepare(), y.prepare()
            for name in ("images", "boxes", "box_view", "class_ids", "slots", "adjacency"):
                assert torch.equal(getattr(x, name), getattr(y, name)), name
        assert a[3]["anchor"] == b[3]["anchor"]
    restored = pickle.loads(pickle.dumps(data))
    assert restored._store.cached._array is None and restored._store._shards == {}
    assert torch.equal(restored[3].anchor.image, png[3].anchor.image)


# ---------------------------------------------------------------------------------- building


def test_default_location_and_reuse(copy: Path) -> None:
    TripletDataset(copy, "train", transform=ImageTransform(size=SIZE), cache=True)
    directory = default_cache_dir(copy, SIZE)
    assert directory == copy / ".cache" / f"images-{SIZE}"
    npy, meta = directory / "train.npy", directory / "train.json"
    assert npy.is_file() and meta.is_file()
    assert not list(directory.glob(TEMP_GLOB))  # the temporary files were renamed away
    stamp = (npy.stat().st_mtime_ns, meta.stat().st_mtime_ns)
    TripletDataset(copy, "train", transform=ImageTransform(size=SIZE), cache=True)
    assert (npy.stat().st_mtime_ns, meta.stat().st_mtime_ns) == stamp  # fresh: not rebuilt
    recorded = json.loads(meta.read_text())
    assert recorded["files"] == [
        {"path": SHARD, "sha256": Dataset.open(copy).manifest.file(SHARD).sha256}
    ]
    assert recorded["dataset"]["name"] == Dataset.open(copy).manifest.name


def test_bytes_do_not_depend_on_build_order(mini_dataset: Path, tmp_path: Path) -> None:
    ds = Dataset.open(mini_dataset)
    transform = ImageTransform(size=SIZE)
    for split in ("train", "test"):
        open_image_cache(ds, split, transform, cache_dir=tmp_path / "a")
    for split in ("test", "train"):
        open_image_cache(ds, split, transform, cache_dir=tmp_path / "b")
    (tmp_path / "b" / "train.json").unlink()  # a forced rebuild writes the same bytes again
    open_image_cache(ds, "train", transform, cache_dir=tmp_path / "b")
    for name in ("train.npy", "train.json", "test.npy", "test.json"):
        assert (tmp_path / "a" / name).read_bytes() == (tmp_path / "b" / name).read_bytes()


def test_rebuilt_when_an_observation_file_changes(copy: Path) -> None:
    transform = ImageTransform(size=SIZE)
    before = TripletDataset(copy, "train", transform=transform, cache=True)
    obs = before._store.obs_ids
    old = np.array(before._store.cached.image(0))
    # rewrite the shard with its first two images swapped, and fix the manifest
    table = pq.read_table(copy / SHARD)
    images = table.column("image").to_pylist()
    images[0], images[1] = images[1], images[0]
    at = table.schema.get_field_index("image")
    table = table.set_column(
        at, table.schema.field(at), pa.array(images, type=table.schema.field(at).type)
    )
    rewrite(copy, SHARD, table)
    after = TripletDataset(copy, "train", transform=transform, cache=True)
    assert after._store.obs_ids == obs
    new = np.array(after._store.cached.image(0))
    assert not np.array_equal(old, new)
    np.testing.assert_array_equal(new, np.array(after._store.cached.image(0)))
    png = TripletDataset(copy, "train", transform=transform)
    for i in range(len(png)):
        assert torch.equal(png[i].anchor.image, after[i].anchor.image)
    meta = json.loads((default_cache_dir(copy, SIZE) / "train.json").read_text())
    assert meta["files"][0]["sha256"] == Dataset.open(copy).manifest.file(SHARD).sha256


def test_rebuilt_when_the_array_is_damaged(copy: Path) -> None:
    transform = ImageTransform(size=SIZE)
    TripletDataset(copy, "train", transform=transform, cache=True)
    npy = default_cache_dir(copy, SIZE) / "train.npy"
    npy.write_bytes(npy.read_bytes()[:1000])  # truncated, as by a full disk
    data = TripletDataset(copy, "train", transform=transform, cache=True)
    png = TripletDataset(copy, "train", transform=transform)
    assert torch.equal(data[0].anchor.image, png[0].anchor.image)


def test_another_datasets_cache_is_refused(copy: Path, tmp_path: Path) -> None:
    shared = tmp_path / "shared"
    transform = ImageTransform(size=SIZE)
    for cache in (shared, True):
        TripletDataset(copy, "train", transform=transform, cache=cache)
    name = Dataset.open(copy).manifest.name
    edit_manifest(copy, lambda raw: raw.update(name="another"))
    with pytest.raises(DataError) as info:
        TripletDataset(copy, "train", transform=transform, cache=shared)
    message = str(info.value)
    assert "\n" not in message and str(shared) in message
    assert f"{name!r}" in message and "'another'" in message
    # under the dataset's own root, the renamed dataset's cache is rebuilt instead
    data = TripletDataset(copy, "train", transform=transform, cache=True)
    meta = json.loads((default_cache_dir(copy, SIZE) / "train.json").read_text())
    assert meta["dataset"]["name"] == "another"
    assert torch.equal(
        data[0].anchor.image, TripletDataset(copy, "train", transform=transform)[0].anchor.image
    )


def test_cache_dir_that_is_a_file(mini_dataset: Path, tmp_path: Path) -> None:
    path = tmp_path / "file"
    path.write_text("not a directory")
    with pytest.raises(DataError, match="is a file"):
        ObservationDataset(mini_dataset, "test", cache=path)
