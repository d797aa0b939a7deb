"""Box noise: seeded per view, exact at zero, and each knob doing what it says."""

from __future__ import annotations

import numpy as np
import pytest

from seannet.data.box_noise import BoxNoise
from seannet.errors import DataError

SLOT_RUNS = np.array([[0, 2], [2, 3], [5, 1]], dtype=np.int64)  # 3 classes, 6 slots
HW = (100, 200)


def _view(k: int = 40) -> tuple[tuple, tuple]:
    rng = np.random.default_rng(0)
    lo = rng.uniform(0, 100, (k, 2))
    box = np.concatenate((lo, lo + rng.uniform(10, 50, (k, 2))), axis=1)
    objects = (np.arange(k), np.zeros(k, np.int64), np.arange(k), box.astype(np.float32))
    src, dst = np.arange(1, k), np.zeros(k - 1, np.int64)
    return objects, (src, dst, np.zeros(k - 1, np.int64))


def test_no_noise_is_the_identity() -> None:
    objects, relations = _view()
    out_objects, out_relations = BoxNoise().apply(
        "a", objects, relations, slot_runs=SLOT_RUNS, image_hw=HW
    )
    assert out_objects is objects and out_relations is relations


def test_each_view_draws_its_own_stream_whatever_the_order() -> None:
    objects, relations = _view()
    noise = BoxNoise(jitter=0.1, drop=0.2, seed=3)
    first = noise.apply("room/0/1/2/0", objects, relations, slot_runs=SLOT_RUNS, image_hw=HW)
    noise.apply("room/0/9/9/1", objects, relations, slot_runs=SLOT_RUNS, image_hw=HW)
    again = noise.apply("room/0/1/2/0", objects, relations, slot_runs=SLOT_RUNS, image_hw=HW)
    other = BoxNoise(jitter=0.1, drop=0.2, seed=4).apply(
        "room/0/1/2/0", objects, relations, slot_runs=SLOT_RUNS, image_hw=HW
    )
    assert np.array_equal(first[0][3], again[0][3])
    assert not np.array_equal(first[0][3], other[0][3])


def test_jitter_moves_corners_by_the_box_size_and_stays_in_the_image() -> None:
    objects, relations = _view(2000)
    (_, _, _, box), _ = BoxNoise(jitter=0.05).apply(
        "v", objects, relations, slot_runs=SLOT_RUNS, image_hw=(1000, 1000)
    )
    size = objects[3][:, 2:] - objects[3][:, :2]
    moved = (box[:, :2] - objects[3][:, :2]) / size
    assert np.std(moved) == pytest.approx(0.05, rel=0.1)
    assert (box[:, 2:] > box[:, :2]).all() and box.min() >= 0 and box.max() <= 1000


def test_dropped_objects_take_their_relations_with_them() -> None:
    objects, relations = _view(400)
    (instance, *_), (src, dst, _) = BoxNoise(drop=0.25).apply(
        "v", objects, relations, slot_runs=SLOT_RUNS, image_hw=HW
    )
    assert 0.65 < len(instance) / 400 < 0.85
    kept = set(instance.tolist())
    assert all(s in kept and d in kept for s, d in zip(src, dst, strict=True))


def test_false_objects_take_free_slots_of_their_class() -> None:
    objects = (np.array([7]), np.array([1]), np.array([2]), np.array([[10, 10, 30, 30]], float))
    relations = (np.zeros(0, np.int64),) * 3
    (instance, class_id, slot, box), _ = BoxNoise(spurious=5.0, seed=1).apply(
        "v", objects, relations, slot_runs=SLOT_RUNS, image_hw=HW
    )
    assert len(instance) > 1 and len(set(slot.tolist())) == len(slot)  # slots stay unique
    for c, s in zip(class_id.tolist(), slot.tolist(), strict=True):
        start, run = SLOT_RUNS[c]
        assert start <= s < start + run
    assert len(set(instance.tolist())) == len(instance)
    assert (box[:, 2:] <= [HW[1], HW[0]]).all()


@pytest.mark.parametrize(("field", "value"), [("jitter", -0.1), ("drop", 1.0), ("spurious", 9.0)])
def test_bad_noise_is_one_line(field: str, value: float) -> None:
    with pytest.raises(DataError, match=field):
        BoxNoise(**{field: value})
