"""The datasets on a real generated dataset: transforms, graph tensors, datasets, collation."""

from __future__ import annotations

import pickle
import shutil
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
import torch
from torch.utils.data import DataLoader

from seannet.data.batch import SceneBatch
from seannet.data.datasets import (
    ImageTransform,
    ObservationDataset,
    TripletDataset,
    collate_triplets,
    collate_views,
    dataset_identity,
    graph_tensors,
)
from seannet.errors import DataError
from seannet.weights import IMAGENET_MEAN, IMAGENET_STD
from sgdata.dataset import Dataset

SIZE = 64  # the tests' resize target (the mini dataset renders 96 x 96)


def reference_graph(objects: list[dict], relations: list[dict], num_slots: int) -> np.ndarray:
    """The plain per-edge version of graph_tensors' adjacency: on / in transposed (the
    support's row holds what rests on it, paper §IV-A), A + I for present objects."""
    slot_of = {o["instance"]: o["slot"] for o in objects}
    a = np.zeros((3, num_slots, num_slots), dtype=np.float64)
    for e in relations:
        if e["type"] in (0, 1):
            a[e["type"], slot_of[e["dst"]], slot_of[e["src"]]] = 1.0
        elif e["type"] == 2:
            a[e["type"], slot_of[e["src"]], slot_of[e["dst"]]] = 1.0
    for o in objects:
        a[:, o["slot"], o["slot"]] = 1.0
    for r in range(3):
        for i in range(num_slots):
            total = sum(a[r, i])
            if total > 0:
                for j in range(num_slots):
                    a[r, i, j] /= total
    return a


# ---------------------------------------------------------------------------------- graphs


def test_graph_tensors_equal_the_reference_on_real_rows(mini_dataset: Path) -> None:
    ds = Dataset.open(mini_dataset)
    m = ds.manifest.num_slots
    fed = 0
    for split in ("train", "test"):
        table = ds.observations(split, columns=["objects", "relations"])
        objects, relations = table.column("objects"), table.column("relations")
        for i in range(table.num_rows):
            objs, rels = objects[i].as_py(), relations[i].as_py()
            expected = reference_graph(objs, rels, m)
            # the Arrow cells and their Python lists give the same tensors
            for form in ((objects[i], relations[i]), (objs, rels)):
                slots, class_ids, boxes, adj = graph_tensors(*form, num_slots=m)
                assert adj.dtype == torch.float32 and adj.shape == (3, m, m)
                np.testing.assert_allclose(adj.numpy(), expected, atol=1e-6)
                assert slots.tolist() == [o["slot"] for o in objs]
                assert class_ids.tolist() == [o["class_id"] for o in objs]
                assert boxes.tolist() == [list(map(float, o["box2d"])) for o in objs]
                assert slots.dtype == class_ids.dtype == torch.long
            fed += sum(e["type"] < 3 for e in rels)
    assert fed > 0  # the rows do exercise the adjacency


def test_graph_tensors_drop_disjoint_and_normalise_rows() -> None:
    objects = [
        {"instance": 7, "class_id": 1, "slot": 4, "box2d": [0, 0, 5, 5]},
        {"instance": 3, "class_id": 2, "slot": 9, "box2d": [1, 1, 2, 2]},
        {"instance": 5, "class_id": 2, "slot": 10, "box2d": [2, 2, 3, 3]},
    ]
    relations = [
        {"src": 3, "dst": 7, "type": 0},  # on
        {"src": 3, "dst": 5, "type": 2},  # proximity, both ways
        {"src": 5, "dst": 3, "type": 2},
        {"src": 3, "dst": 7, "type": 2},
        {"src": 7, "dst": 5, "type": 3},  # disjoint: not fed
        {"src": 5, "dst": 3, "type": 2},  # a repeated edge counts once
    ]
    slots, class_ids, boxes, adj = graph_tensors(objects, relations, num_slots=16)
    assert slots.tolist() == [4, 9, 10] and class_ids.tolist() == [1, 2, 2]
    # on: 3 rests on 7, so the support's row (slot 4) holds slot 9, beside its self-loop
    assert adj[0, 4, 9] == adj[0, 4, 4] == 0.5 and adj[0, 9, 4] == 0.0 and adj[0, 9, 9] == 1.0
    assert torch.equal(adj[1], torch.diag(adj[1].diagonal()))  # in: self-loops only
    assert adj[1].diagonal()[[4, 9, 10]].tolist() == [1.0, 1.0, 1.0]
    assert adj[2, 9, 10] == adj[2, 9, 4] == adj[2, 9, 9] == pytest.approx(1 / 3)
    assert adj[2, 10, 9] == adj[2, 10, 10] == 0.5
    assert adj[2, 4, 4] == 1.0  # node 4 has no proximity edge of its own: its self-loop
    assert torch.allclose(adj.sum(dim=2)[:, [4, 9, 10]], torch.ones(3, 3))  # rows sum to 1
    assert adj.sum() == 9.0  # absent slots stay zero
    empty = graph_tensors([], [], num_slots=16)
    assert empty[0].shape == (0,) and empty[2].shape == (0, 4) and empty[3].sum() == 0


def test_graph_tensors_reject_bad_rows() -> None:
    obj = [{"instance": 1, "class_id": 0, "slot": 2, "box2d": [0, 0, 1, 1]}]
    with pytest.raises(DataError, match="instance 9"):
        graph_tensors(obj, [{"src": 1, "dst": 9, "type": 0}], num_slots=4)
    with pytest.raises(DataError, match="slot 5 out of range"):
        graph_tensors([{**obj[0], "slot": 5}], [], num_slots=4)
    with pytest.raises(DataError, match="share a GCN slot"):
        graph_tensors([obj[0], {**obj[0], "instance": 2}], [], num_slots=4)


# ---------------------------------------------------------------------------------- images


def test_image_transform_resizes_scales_boxes_and_normalises() -> None:
    rgb = np.full((96, 48, 3), 128, dtype=np.uint8)
    image, boxes = ImageTransform(size=32)(rgb, np.array([[0, 0, 48, 96], [12, 24, 36, 48]]))
    assert image.shape == (3, 32, 32) and image.dtype == torch.float32
    expected = (128 / 255 - np.asarray(IMAGENET_MEAN)) / np.asarray(IMAGENET_STD)
    np.testing.assert_allclose(image.mean(dim=(1, 2)).numpy(), expected, atol=1e-5)
    assert boxes.tolist() == [[0, 0, 32, 32], [8, 8, 24, 16]]
    with pytest.raises(DataError, match="size=0"):
        ImageTransform(size=0)


# ---------------------------------------------------------------------------------- datasets


def _check_batch(batch: SceneBatch, n: int, m: int) -> None:
    # the loaders' compact form: uint8 pixels and a sparse adjacency, prepared by the model
    assert batch.images.shape == (n, 3, SIZE, SIZE) and batch.images.dtype == torch.uint8
    assert batch.adjacency.shape == (n, 3, m, m) and batch.adjacency.is_sparse
    assert not batch.prepared
    batch = batch.prepare()
    assert batch.images.dtype == torch.float32 and batch.images.is_contiguous()
    assert batch.adjacency.layout == torch.strided and batch.mean is None
    batch.validate()
    assert bool((batch.boxes >= 0).all()) and bool((batch.boxes <= SIZE).all())
    assert bool((batch.boxes[:, 2:] > batch.boxes[:, :2]).all())
    rows = batch.adjacency.sum(dim=-1)  # (n, 3, M): 1 where a node has edges, else 0
    assert torch.allclose(rows[rows > 0], torch.ones(1))
    present = torch.zeros(n, m, dtype=torch.bool)
    present[batch.box_view, batch.slots] = True
    assert float(rows.sum(dim=1)[~present].abs().sum()) == 0.0  # absent nodes: zero rows


def test_triplet_batch_shapes_boxes_and_adjacency(
    mini_triplets: dict[str, int], mini_dataset: Path
) -> None:
    data = TripletDataset(mini_dataset, "train", transform=ImageTransform(size=SIZE))
    assert len(data) == mini_triplets["train"]
    items = [data[i] for i in range(4)]
    anchors, positives, negatives, meta = collate_triplets(items)
    for batch in (anchors, positives, negatives):
        _check_batch(batch, 4, 256)
    assert meta["tier"].tolist() == [t.tier for t in items]
    assert meta["triplet_id"].tolist() == [0, 1, 2, 3]
    assert len(set(zip(meta["anchor"], meta["positive"], meta["negative"], strict=True))) == 4
    # boxes are the row's boxes scaled by SIZE / 96, in object order
    ds = Dataset.open(mini_dataset)
    rows = ds.observations("train", columns=["obs_id", "objects", "relations"]).to_pylist()
    objects = {r["obs_id"]: r["objects"] for r in rows}
    relations = {r["obs_id"]: r["relations"] for r in rows}
    dense = positives.prepare().adjacency
    for b, obs in enumerate(meta["positive"]):  # the batch's dense adjacency is the row's
        expected = reference_graph(objects[obs], relations[obs], 256)
        np.testing.assert_allclose(dense[b].numpy(), expected, atol=1e-6)
        assert torch.equal(items[b].positive.adjacency, dense[b])
    first = objects[meta["negative"][0]]
    got = negatives.boxes[negatives.box_view == 0]
    want = torch.tensor([o["box2d"] for o in first], dtype=torch.float32) * (SIZE / 96)
    assert torch.allclose(got, want)


def test_workers_yield_the_same_tensors(mini_dataset: Path) -> None:
    data = TripletDataset(mini_dataset, "train", transform=ImageTransform(size=SIZE))
    kwargs = dict(batch_size=5, shuffle=False, collate_fn=collate_triplets)
    serial = list(DataLoader(data, num_workers=0, **kwargs))
    data[0]  # the parent has read shards: workers must not inherit its cache
    parallel = list(DataLoader(data, num_workers=2, **kwargs))
    assert len(serial) == len(parallel) == -(-len(data) // 5)
    for a, b in zip(serial, parallel, strict=True):
        for x, y in zip(a[:3], b[:3], strict=True):
            x, y = x.prepare(), y.prepare()
            for name in ("images", "boxes", "box_view", "class_ids", "slots", "adjacency"):
                assert torch.equal(getattr(x, name), getattr(y, name)), name
        assert a[3]["anchor"] == b[3]["anchor"]
        assert torch.equal(a[3]["tier"], b[3]["tier"])
    restored = pickle.loads(pickle.dumps(data))
    assert restored._store._shards == {}
    assert torch.equal(restored[3].anchor.image, data[3].anchor.image)


def test_observation_dataset_covers_every_view(mini_dataset: Path) -> None:
    ds = Dataset.open(mini_dataset)
    table = ds.observations("test", columns=["obs_id", "grid_i", "heading"]).to_pylist()
    data = ObservationDataset(mini_dataset, "test", transform=ImageTransform(size=SIZE))
    assert len(data) == len(table) > 0
    loader = DataLoader(data, batch_size=8, num_workers=0, collate_fn=collate_views)
    seen, grid_i = [], []
    for batch, meta in loader:
        _check_batch(batch, len(meta["obs_id"]), 256)
        seen += meta["obs_id"]
        grid_i += meta["grid_i"].tolist()
    assert seen == data.obs_ids == [r["obs_id"] for r in table]
    assert grid_i == [r["grid_i"] for r in table]
    item = data[-1]
    assert item.obs_id == table[-1]["obs_id"] and item.heading == table[-1]["heading"]


# ---------------------------------------------------------------------------------- identity


def test_dataset_identity(mini_dataset: Path) -> None:
    ident = dataset_identity(mini_dataset)
    m = Dataset.open(mini_dataset).manifest
    assert ident["name"] == m.name and ident["version"] == m.version
    assert ident["format_version"] == m.format_version and ident["num_slots"] == 256
    assert len(ident["vocabulary_sha256"]) == 64
    assert dataset_identity(Dataset.open(mini_dataset)) == ident
    assert TripletDataset(mini_dataset, "test").identity == ident


# ---------------------------------------------------------------------------------- errors


def test_not_a_dataset_is_a_data_error(tmp_path: Path) -> None:
    for root in (tmp_path, tmp_path / "absent"):
        with pytest.raises(DataError) as info:
            TripletDataset(root, "train")
        assert "\n" not in str(info.value) and str(root) in str(info.value)
    with pytest.raises(DataError):
        dataset_identity(tmp_path)


def test_missing_split_is_a_data_error(mini_dataset: Path) -> None:
    with pytest.raises(DataError, match="split 'holdout'"):
        ObservationDataset(mini_dataset, "holdout")


def test_triplet_naming_a_missing_observation(mini_dataset: Path, tmp_path: Path) -> None:
    root = tmp_path / "copy"
    shutil.copytree(mini_dataset, root)
    path = root / "triplets" / "train.parquet"
    table = pq.read_table(path)
    anchors = table.column("anchor").to_pylist()
    anchors[5] = "bathroom_000/9/99/99/0"
    column = table.schema.get_field_index("anchor")
    table = table.set_column(
        column, table.schema.field(column), pa.array(anchors, type=pa.string())
    )
    pq.write_table(table, path)
    with pytest.raises(DataError, match=r"triplet 5 .*'bathroom_000/9/99/99/0'"):
        TripletDataset(root, "train")
