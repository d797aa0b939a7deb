"""The loaders' channels: depth, instance and class masks as tensors, resized like the image."""

from __future__ import annotations

import json
import pickle
from pathlib import Path

import numpy as np
import pytest
import torch
from PIL import Image
from torch.utils.data import DataLoader

from seannet.data.batch import SceneBatch
from seannet.data.datasets import (
    ImageTransform,
    ObservationDataset,
    TripletDataset,
    collate_triplets,
    collate_views,
)
from seannet.data.view_channels import nearest_rows
from seannet.errors import DataError
from sgdata.dataset import Dataset
from sgdata.dataset.channels import decode_channel
from sgdata.dataset.storage import image_bytes

SIZE = 64  # the tests' resize target (the mini dataset renders 96 x 96)
ALL = ("depth", "instances", "classes")


def _reference(root: Path, split: str, size: int) -> dict[str, dict[str, np.ndarray]]:
    """Every view's channels by plain means: the stored PNGs decoded, resized with Pillow's
    nearest filter, depth in metres, the class mask looked up per pixel."""
    table = Dataset.open(root).observations(
        split, columns=["obs_id", "depth", "instances", "objects"]
    )
    out = {}
    for row in table.to_pylist():
        resized = {}
        for name in ("depth", "instances"):
            values = decode_channel(image_bytes(row[name]))
            image = Image.fromarray(values).resize((size, size), Image.Resampling.NEAREST)
            resized[name] = np.asarray(image).astype(np.int64)
        classes = np.zeros_like(resized["instances"])
        for k, obj in enumerate(row["objects"], start=1):
            classes[resized["instances"] == k] = obj["class_id"] + 1
        out[row["obs_id"]] = {
            "depth": (resized["depth"] / 1000.0).astype(np.float32),
            "instances": resized["instances"],
            "classes": classes,
        }
    return out


def test_nearest_rows_match_pillow() -> None:
    for source, size in ((96, 64), (96, 224), (5, 3), (7, 7), (1, 4)):
        values = np.arange(source, dtype=np.uint16)[None, :].repeat(2, axis=0)
        image = Image.fromarray(values).resize((size, 2), Image.Resampling.NEAREST)
        assert np.asarray(image)[0].tolist() == nearest_rows(source, size).tolist()


def test_observation_channels_are_the_stored_pngs_resized(channels_dataset: Path) -> None:
    data = ObservationDataset(
        channels_dataset, "val", transform=ImageTransform(size=SIZE), channels=ALL
    )
    reference = _reference(channels_dataset, "val", SIZE)
    loader = DataLoader(data, batch_size=3, collate_fn=collate_views)
    seen = 0
    for batch, meta in loader:
        assert set(batch.channels) == set(ALL)
        b = batch.num_views
        assert batch.channels["depth"].shape == (b, SIZE, SIZE)
        assert batch.channels["depth"].dtype == torch.float32
        assert batch.channels["instances"].dtype == torch.int64
        assert batch.channels["classes"].dtype == torch.int64
        for k, obs in enumerate(meta["obs_id"]):
            for name in ALL:
                got = batch.channels[name][k].numpy()
                assert np.array_equal(got, reference[obs][name]), (obs, name)
            seen += 1
    assert seen == len(data) == len(reference)
    # the channels carry information: objects seen, depth where they are
    inst = torch.stack([data[i].view.channels["instances"] for i in range(len(data))])
    depth = torch.stack([data[i].view.channels["depth"] for i in range(len(data))])
    assert int(inst.max()) > 0 and bool((depth[inst > 0] > 0).all())


def test_channels_at_the_stored_size_are_not_resampled(channels_dataset: Path) -> None:
    data = ObservationDataset(
        channels_dataset, "test", transform=ImageTransform(size=96), channels=("instances",)
    )
    table = Dataset.open(channels_dataset).observations("test", columns=["obs_id", "instances"])
    stored = {r["obs_id"]: decode_channel(image_bytes(r["instances"])) for r in table.to_pylist()}
    for i in range(len(data)):
        item = data[i]
        assert list(item.view.channels) == ["instances"]
        assert np.array_equal(item.view.channels["instances"].numpy(), stored[item.obs_id])


def test_triplet_channels_with_the_image_cache(channels_dataset: Path, tmp_path: Path) -> None:
    transform = ImageTransform(size=SIZE)
    views = ObservationDataset(channels_dataset, "val", transform=transform, channels=ALL)
    by_id = {views[i].obs_id: views[i].view.channels for i in range(len(views))}
    triplets = TripletDataset(
        channels_dataset, "val", transform=transform, cache=tmp_path / "cache", channels=ALL
    )
    anchors, positives, negatives, meta = collate_triplets(triplets.__getitems__([0, 1, 2]))
    for batch, role in ((anchors, "anchor"), (positives, "positive"), (negatives, "negative")):
        assert set(batch.channels) == set(ALL)
        for k, obs in enumerate(meta[role]):
            for name in ALL:
                assert torch.equal(batch.channels[name][k], by_id[obs][name])
    # single items collate to the same channels
    again = collate_triplets([triplets[0], triplets[1], triplets[2]])
    for name in ALL:
        assert torch.equal(again[0].channels[name], anchors.channels[name])
    # channels travel with the batch: moved, pickled (DataLoader workers), prepared
    moved = pickle.loads(pickle.dumps(anchors.to("cpu")))
    assert all(torch.equal(moved.channels[n], anchors.channels[n]) for n in ALL)
    assert set(anchors.prepare().channels) == set(ALL)


def test_no_channels_by_default(channels_dataset: Path) -> None:
    data = ObservationDataset(channels_dataset, "test", transform=ImageTransform(size=SIZE))
    batch, _ = collate_views([data[0], data[1]])
    assert batch.channels == {} and data[0].view.channels == {}


def test_scene_batch_checks_channel_shapes(channels_dataset: Path) -> None:
    data = ObservationDataset(
        channels_dataset, "test", transform=ImageTransform(size=SIZE), channels=("depth",)
    )
    batch, _ = collate_views([data[0], data[1]])
    with pytest.raises(DataError, match=r"channel depth: shape \(2, 32, 32\)"):
        SceneBatch(**{**vars(batch), "channels": {"depth": torch.zeros(2, 32, 32)}})


def _one_line(exc: pytest.ExceptionInfo) -> str:
    message = str(exc.value)
    assert "\n" not in message
    return message


def test_a_channel_the_dataset_lacks_is_refused(mini_dataset: Path) -> None:
    with pytest.raises(DataError) as exc:
        ObservationDataset(mini_dataset, "val", channels=("depth",))
    message = _one_line(exc)
    assert str(mini_dataset) in message and "(mini)" in message
    assert "no depth channel" in message and "[outputs] depth = true" in message
    with pytest.raises(DataError) as exc:
        TripletDataset(mini_dataset, "val", channels=("classes",))
    assert "no classes channel" in _one_line(exc) and "[outputs] instances" in str(exc.value)
    with pytest.raises(DataError, match="expected distinct names among depth, instances"):
        ObservationDataset(mini_dataset, "val", channels=("normals",))
    with pytest.raises(DataError, match="expected distinct names"):
        ObservationDataset(mini_dataset, "val", channels=("depth", "depth"))


def test_a_real_dataset_has_no_depth(tmp_path: Path) -> None:
    from sgdata.label.importers import import_labels

    photos = tmp_path / "photos"
    photos.mkdir()
    Image.fromarray(np.full((60, 80, 3), 128, dtype=np.uint8)).save(photos / "a.png")
    coco = {
        "images": [{"id": 1, "file_name": "a.png", "width": 80, "height": 60}],
        "categories": [{"id": 1, "name": "Mug"}],
        "annotations": [{"id": 1, "image_id": 1, "category_id": 1, "bbox": [10, 10, 20, 20]}],
    }
    (tmp_path / "kitchen_1.json").write_text(json.dumps(coco))
    root = tmp_path / "real"
    import_labels("coco", tmp_path / "kitchen_1.json", photos, root)
    assert len(ObservationDataset(root, "test")) == 1  # readable without channels
    with pytest.raises(DataError) as exc:
        ObservationDataset(root, "test", channels=("instances", "depth"))
    message = _one_line(exc)
    assert str(root) in message and "no instances channel" in message and "real" in message
