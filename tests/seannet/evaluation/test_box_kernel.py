"""The learned box kernel: it learns which slots carry the pose, in the overlap's shape."""

from __future__ import annotations

import numpy as np
import pytest

from seannet.evaluation.box_kernel import BoxKernel, fit_box_kernel, slot_pairs
from seannet.evaluation.box_overlap import SlotBoxes

SLOTS = 8


def _triplets(rng: np.random.Generator, count: int, prefix: str):  # noqa: ANN202
    """Triplets where slot 0 (a fridge) stays put at the same pose and shifts at the next one,
    and slots 1-5 (chairs) move about their places in every view: only slot 0 tells the poses
    apart, and the chairs' chance overlaps drown it in a uniform mean."""
    views, triplets = {}, []

    def box(x: float, y: float) -> np.ndarray:
        return np.array([x, y, x + 40, y + 60], dtype=np.float32)

    for t in range(count):
        x, y = rng.uniform(0, 200, 2)
        step = rng.choice([-1, 1]) * rng.uniform(8, 15)
        places = rng.uniform(0, 200, (6, 2))
        ids = [f"{prefix}{t}{role}" for role in "apn"]
        for obs, fridge_x in zip(ids, (x, x, x + step), strict=True):
            chairs = {s: box(*(places[s] + rng.uniform(-30, 30, 2))) for s in range(1, 6)}
            views[obs] = {0: box(fridge_x, y), **chairs}
        triplets.append(tuple(ids))
    return views, triplets


def _table(views: dict[str, dict[int, np.ndarray]]) -> SlotBoxes:
    ids = list(views)
    offsets = np.concatenate(([0], np.cumsum([len(views[o]) for o in ids])))
    slots = np.array([s for o in ids for s in views[o]], dtype=np.int64)
    boxes = np.array([b for o in ids for b in views[o].values()], dtype=np.float32)
    return SlotBoxes(ids, offsets, slots, boxes, num_slots=SLOTS)


def _pairs(table: SlotBoxes, triplets: list[tuple[str, str, str]]):  # noqa: ANN202
    a, p, n = zip(*triplets, strict=True)
    return slot_pairs(table, a, p), slot_pairs(table, a, n)


def test_the_kernel_learns_the_slot_that_stays_and_beats_the_overlap_on_new_triplets() -> None:
    rng = np.random.default_rng(0)
    train_views, train = _triplets(rng, 200, "t")
    test_views, test = _triplets(rng, 200, "v")
    kernel, train_accuracy = fit_box_kernel(*_pairs(_table(train_views), train), SLOTS)
    table = _table(test_views)
    positive, negative = _pairs(table, test)
    learned = np.mean(kernel.score(positive) > kernel.score(negative))
    a, p, n = zip(*test, strict=True)
    overlap = np.mean(table.overlap(a, p) > table.overlap(a, n))
    assert train_accuracy > 0.95 and learned > 0.95
    assert learned > overlap + 0.1  # the chairs' chance overlaps mislead the uniform mean
    weights = kernel.slot_weight.detach()
    assert weights[0] > weights[1:6].max()  # the fridge counts most


def test_scores_are_a_weighted_mean_of_iou_in_0_1_and_the_same_each_fit() -> None:
    rng = np.random.default_rng(1)
    views, triplets = _triplets(rng, 40, "t")
    views["empty"] = {}
    table = _table(views)
    positive, negative = _pairs(table, triplets)
    kernel, _ = fit_box_kernel(positive, negative, SLOTS)
    again, _ = fit_box_kernel(positive, negative, SLOTS)
    scores = kernel.score(positive)
    assert np.array_equal(scores, again.score(positive))
    assert ((scores >= 0) & (scores <= 1)).all()
    anchor = triplets[0][0]
    assert kernel.score(slot_pairs(table, ["empty"], [anchor]))[0] == 0.0
    assert kernel.score(slot_pairs(table, [anchor], [anchor]))[0] == pytest.approx(1.0)
    # with every weight 1 the kernel is the hand-made overlap
    untrained = BoxKernel(SLOTS)
    a, p, _ = zip(*triplets, strict=True)
    assert untrained.score(slot_pairs(table, a, p)) == pytest.approx(table.overlap(a, p), abs=1e-6)
    # a slot in one view only counts against the pair: the same view plus an object scores lower
    views["plus"] = {**views[anchor], 7: np.array([0, 0, 30, 30], dtype=np.float32)}
    table = _table(views)
    assert kernel.score(slot_pairs(table, [anchor], ["plus"]))[0] < 1.0
