"""seannet.data.batch: the two forms of SceneBatch, prepare(), to() and the pixel normalisation."""

from __future__ import annotations

import pickle

import numpy as np
import pytest
import torch

from seannet.data.batch import SceneBatch, normalise_pixels
from seannet.errors import DataError
from seannet.weights import IMAGENET_MEAN, IMAGENET_STD, LITE0, NETWORKS

LITE0_MEAN, LITE0_STD = NETWORKS[LITE0].mean, NETWORKS[LITE0].std

M = 16


def reference_normalise(rgb: np.ndarray, mean: tuple, std: tuple) -> np.ndarray:
    """The loaders' float path before SceneBatch.prepare existed (ImageTransform, numpy)."""
    std64 = np.asarray(std, dtype=np.float64)
    scale = (1.0 / (255.0 * std64)).astype(np.float32)[:, None, None]
    offset = (-np.asarray(mean, dtype=np.float64) / std64).astype(np.float32)[:, None, None]
    x = np.ascontiguousarray(rgb.transpose(2, 0, 1)).astype(np.float32)
    x *= scale
    x += offset
    return x


def compact_batch(*, edges: bool = True) -> SceneBatch:
    """Two 8 x 8 views: uint8 pixels (a channels-last view) and a sparse adjacency."""
    g = np.random.default_rng(0)
    pixels = g.integers(0, 256, (2, 8, 8, 3), dtype=np.uint8)
    index = torch.tensor([[0, 0, 1, 1], [0, 2, 1, 2], [3, 3, 5, 5], [3, 4, 5, 5]])
    weight = torch.tensor([0.5, 1.0, 1.0, 1.0])
    if not edges:
        index, weight = index[:, :0], weight[:0]
    return SceneBatch(
        images=torch.from_numpy(pixels).permute(0, 3, 1, 2),
        boxes=torch.tensor([[0.0, 0.0, 4.0, 4.0], [1.0, 1.0, 8.0, 8.0]]),
        box_view=torch.tensor([0, 1]),
        class_ids=torch.tensor([2, 7]),
        slots=torch.tensor([3, 5]),
        adjacency=torch.sparse_coo_tensor(index, weight, (2, 3, M, M), check_invariants=True),
        mean=IMAGENET_MEAN,
        std=IMAGENET_STD,
    )


@pytest.mark.parametrize("family", [(IMAGENET_MEAN, IMAGENET_STD), (LITE0_MEAN, LITE0_STD)])
def test_normalise_pixels_gives_the_old_float_path_bit_for_bit(family: tuple) -> None:
    mean, std = family
    rgb = np.random.default_rng(1).integers(0, 256, (2, 17, 13, 3), dtype=np.uint8)
    got = normalise_pixels(torch.from_numpy(rgb).permute(0, 3, 1, 2), mean, std)
    assert got.dtype == torch.float32 and got.is_contiguous() and got.shape == (2, 3, 17, 13)
    for k in range(2):
        assert np.array_equal(got[k].numpy(), reference_normalise(rgb[k], mean, std))


def test_prepare_normalises_and_densifies() -> None:
    batch = compact_batch()
    assert not batch.prepared and batch.num_views == 2 and batch.num_slots == M
    ready = batch.prepare()
    assert ready.prepared and ready.mean is None and ready.std is None
    hwc = batch.images.permute(0, 2, 3, 1).numpy()
    want = np.stack([reference_normalise(p, IMAGENET_MEAN, IMAGENET_STD) for p in hwc])
    assert np.array_equal(ready.images.numpy(), want)
    dense = torch.zeros(2, 3, M, M)
    dense[0, 0, 3, 3], dense[0, 2, 3, 4], dense[1, 1, 5, 5], dense[1, 2, 5, 5] = 0.5, 1, 1, 1
    assert torch.equal(ready.adjacency, dense)
    for name in ("boxes", "box_view", "class_ids", "slots"):
        assert getattr(ready, name) is getattr(batch, name)
    assert ready.prepare() is ready  # a prepared batch is returned as it is
    ready.validate(num_classes=8)


def test_a_batch_without_edges() -> None:
    batch = compact_batch(edges=False)
    assert batch.adjacency._nnz() == 0
    ready = batch.prepare()
    assert ready.adjacency.shape == (2, 3, M, M) and float(ready.adjacency.abs().sum()) == 0.0


def test_to_keeps_the_compact_form_and_pickles() -> None:
    batch = compact_batch()
    moved = batch.to("cpu")
    assert moved.images.dtype == torch.uint8 and moved.adjacency.is_sparse
    assert moved.mean == IMAGENET_MEAN and moved.std == IMAGENET_STD
    assert torch.equal(moved.prepare().images, batch.prepare().images)
    again = pickle.loads(pickle.dumps(batch))
    assert again.adjacency.is_sparse
    assert torch.equal(again.prepare().adjacency, batch.prepare().adjacency)
    assert torch.equal(again.images, batch.images)


def test_constructor_checks_the_forms() -> None:
    batch = compact_batch()
    fields = dict(vars(batch))
    with pytest.raises(DataError, match="without mean / std"):
        SceneBatch(**{**fields, "mean": None})
    with pytest.raises(DataError, match="normalised already"):
        SceneBatch(**{**fields, "images": batch.prepare().images})
    with pytest.raises(DataError, match="dtype torch.int32"):
        SceneBatch(**{**fields, "images": batch.images.to(torch.int32)})
    with pytest.raises(DataError, match="expected \\(2, 3, M, M\\)"):
        SceneBatch(**{**fields, "adjacency": torch.zeros(2, 2, M, M)})
