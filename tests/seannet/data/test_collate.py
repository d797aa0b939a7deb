"""The collate functions: gathered batches equal the old dense float path (data and model)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import torch
from torch.utils.data import DataLoader

from seannet.data.batch import SceneBatch
from seannet.data.collate import TripletItems, ViewTensors
from seannet.data.datasets import (
    ImageTransform,
    ObservationDataset,
    TripletDataset,
    collate_triplets,
    collate_views,
)
from seannet.errors import DataError
from seannet.model.factory import build_model

SIZE = 64  # the tests' resize target (the mini dataset renders 96 x 96)
ROLES = ("anchor", "positive", "negative")


def old_batch(views: list[ViewTensors], transform: ImageTransform) -> SceneBatch:
    """What collation gave before the compact form: the views' float images from
    ``ImageTransform.__call__`` and the dense adjacency scattered per view, on the CPU."""
    adjacency = torch.zeros(len(views), 3, views[0].num_slots, views[0].num_slots)
    images = []
    for b, v in enumerate(views):
        image, _ = transform(v.image.permute(1, 2, 0).numpy(), np.zeros((0, 4)))
        images.append(image)
        adjacency[b, v.edge_index[0], v.edge_index[1], v.edge_index[2]] = v.edge_weight
    counts = torch.tensor([v.boxes.shape[0] for v in views])
    return SceneBatch(
        images=torch.stack(images),
        boxes=torch.cat([v.boxes for v in views]),
        box_view=torch.repeat_interleave(torch.arange(len(views)), counts),
        class_ids=torch.cat([v.class_ids for v in views]),
        slots=torch.cat([v.slots for v in views]),
        adjacency=adjacency,
    )


def assert_same(new: SceneBatch, old: SceneBatch) -> None:
    new = new.prepare()
    for name in ("images", "boxes", "box_view", "class_ids", "slots", "adjacency"):
        assert torch.equal(getattr(new, name), getattr(old, name)), name


@pytest.mark.parametrize("cache", [False, True])
def test_gathered_batches_equal_the_old_dense_float_batches(
    mini_dataset: Path, tmp_path: Path, cache: bool
) -> None:
    transform = ImageTransform(size=SIZE)
    data = TripletDataset(mini_dataset, "train", transform=transform, cache=cache and tmp_path)
    gathered = data.__getitems__([4, 0, 3, -1])
    assert isinstance(gathered, TripletItems) and len(gathered) == 4
    singles = [data[i] for i in (4, 0, 3, len(data) - 1)]
    new = collate_triplets(gathered)
    from_list = collate_triplets(singles)
    for k, role in enumerate(ROLES):
        old = old_batch([getattr(t, role) for t in singles], transform)
        assert_same(new[k], old)
        assert_same(from_list[k], old)
    assert new[3]["anchor"] == from_list[3]["anchor"] == [t.ids[0] for t in singles]
    assert torch.equal(new[3]["tier"], from_list[3]["tier"])
    # the gathered items are the single items, too
    for a, b in zip(gathered, singles, strict=True):
        for role in ROLES:
            x, y = getattr(a, role), getattr(b, role)
            for name in ("image", "boxes", "class_ids", "slots", "edge_index", "edge_weight"):
                assert torch.equal(getattr(x, name), getattr(y, name)), name
        assert a.ids == b.ids and a.triplet_id == b.triplet_id


def test_observation_batches_equal_the_old_ones(mini_dataset: Path) -> None:
    transform = ImageTransform.for_model(SIZE, "efficientnet_lite0")  # not ImageNet's
    data = ObservationDataset(mini_dataset, "test", transform=transform)
    batch, meta = next(iter(DataLoader(data, batch_size=5, collate_fn=collate_views)))
    old = old_batch([data[i].view for i in range(5)], transform)
    assert_same(batch, old)
    assert meta["obs_id"] == data.obs_ids[:5]
    single, _ = collate_views([data[i].view for i in range(5)])
    assert_same(single, old)


def test_the_model_embeds_the_compact_batch_as_the_old_one(mini_dataset: Path) -> None:
    transform = ImageTransform(size=SIZE)
    data = TripletDataset(mini_dataset, "train", transform=transform)
    anchors, _, _, _ = collate_triplets(data.__getitems__([0, 1, 2]))
    old = old_batch([data[i].anchor for i in range(3)], transform)
    torch.manual_seed(0)
    seannet = build_model("seannet", depth=18, num_slots=256, roi_size=7).eval()
    torch.manual_seed(0)
    baseline = build_model("resnet18", embed_dim=64).eval()
    with torch.no_grad():
        for model in (seannet, baseline):
            torch.testing.assert_close(model.embed(anchors), model.embed(old), rtol=0, atol=0)


def test_views_without_objects_or_edges(mini_dataset: Path) -> None:
    transform = ImageTransform(size=SIZE)
    view = ObservationDataset(mini_dataset, "test", transform=transform)[0].view
    empty = ViewTensors(
        image=view.image.clone(),
        boxes=torch.zeros(0, 4),
        class_ids=torch.zeros(0, dtype=torch.long),
        slots=torch.zeros(0, dtype=torch.long),
        edge_index=torch.zeros(3, 0, dtype=torch.long),
        edge_weight=torch.zeros(0),
        num_slots=view.num_slots,
        mean=view.mean,
        std=view.std,
    )
    for views in ([empty, view, empty], [empty]):
        batch, meta = collate_views(views)
        assert meta == {} and batch.num_views == len(views)
        assert batch.adjacency._nnz() == sum(v.edge_weight.numel() for v in views)
        assert_same(batch, old_batch(views, transform))
        ready = batch.prepare()
        assert float(ready.adjacency[0].abs().sum()) == 0.0
        owners = [b for b, v in enumerate(views) for _ in range(v.boxes.shape[0])]
        assert batch.box_view.tolist() == owners
    torch.manual_seed(0)
    model = build_model("seannet", depth=18, num_slots=256, roi_size=7).eval()
    with torch.no_grad():
        out = model.embed(collate_views([empty, empty])[0])  # no box in the whole batch
    assert out.shape == (2, model.out_dim) and bool(torch.isfinite(out).all())


def test_mixed_views_are_refused(mini_dataset: Path) -> None:
    a = ObservationDataset(mini_dataset, "test", transform=ImageTransform(size=SIZE))[0].view
    b = ObservationDataset(mini_dataset, "test", transform=ImageTransform(size=32))[0].view
    with pytest.raises(DataError, match="expected one"):
        collate_views([a, b])
    lite = ImageTransform.for_model(SIZE, "efficientnet_lite0")
    c = ObservationDataset(mini_dataset, "test", transform=lite)[0].view
    with pytest.raises(DataError, match="views with mean"):
        collate_views([a, c])


def test_batches_kept_are_never_overwritten(mini_dataset: Path, tmp_path: Path) -> None:
    """The pixel buffers are reused only once nothing refers to them any more."""
    transform = ImageTransform(size=SIZE)
    data = TripletDataset(mini_dataset, "train", transform=transform, cache=tmp_path)
    kept = collate_triplets(data.__getitems__([0, 1]))
    item = data[2]
    want = [b.images.clone() for b in kept[:3]], item.anchor.image.clone()
    for _ in range(10):  # read and drop: the dropped batches' buffers are reused
        collate_triplets(data.__getitems__([3, 4]))
    assert all(torch.equal(b.images, w) for b, w in zip(kept[:3], want[0], strict=True))
    assert torch.equal(item.anchor.image, want[1])
    held = list(DataLoader(data, batch_size=2, collate_fn=collate_triplets))
    again = list(DataLoader(data, batch_size=2, collate_fn=collate_triplets))
    for x, y in zip(held, again, strict=True):
        assert all(torch.equal(p.images, q.images) for p, q in zip(x[:3], y[:3], strict=True))
    store = data._store
    first = store._buffers.take((2, SIZE, SIZE, 3))
    address = first.ctypes.data
    del first
    assert store._buffers.take((2, SIZE, SIZE, 3)).ctypes.data == address  # reused
    held_one = store._buffers.take((2, SIZE, SIZE, 3))
    assert store._buffers.take((2, SIZE, SIZE, 3)).ctypes.data != held_one.ctypes.data
