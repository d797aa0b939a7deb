"""The hand-made box overlap: vectorised as the plain per-pair definition, lambda on val."""

from __future__ import annotations

import numpy as np
import pytest

from seannet.evaluation.box_overlap import BOX_WEIGHTS, SlotBoxes, choose_box_weight


def _iou(a: np.ndarray, b: np.ndarray) -> float:
    w = max(0.0, min(a[2], b[2]) - max(a[0], b[0]))
    h = max(0.0, min(a[3], b[3]) - max(a[1], b[1]))
    union = (a[2] - a[0]) * (a[3] - a[1]) + (b[2] - b[0]) * (b[3] - b[1]) - w * h
    return w * h / union if union > 0 else 0.0


def _reference(a: dict[int, np.ndarray], b: dict[int, np.ndarray]) -> float:
    both = a.keys() | b.keys()
    return sum(_iou(a[s], b[s]) for s in a.keys() & b.keys()) / len(both) if both else 0.0


def test_vectorised_overlap_equals_the_definition() -> None:
    rng = np.random.default_rng(0)
    views = []
    for _ in range(30):
        slots = rng.choice(16, size=rng.integers(0, 8), replace=False)
        lo = rng.uniform(0, 50, (len(slots), 2))
        views.append(
            {
                int(s): np.array([*p, *(p + rng.uniform(1, 30, 2))])
                for s, p in zip(slots, lo, strict=True)
            }
        )
    offsets = np.concatenate(([0], np.cumsum([len(v) for v in views])))
    slots = np.array([s for v in views for s in v], dtype=np.int64)
    boxes = np.array([b for v in views for b in v.values()], dtype=np.float32).reshape(-1, 4)
    ids = [f"v{k}" for k in range(len(views))]
    table = SlotBoxes(ids, offsets, slots, boxes, num_slots=16)
    first, second = rng.integers(0, 30, 200), rng.integers(0, 30, 200)
    got = table.overlap([ids[k] for k in first], [ids[k] for k in second])
    want = [_reference(views[a], views[b]) for a, b in zip(first, second, strict=True)]
    assert got == pytest.approx(want, abs=1e-5)
    assert table.overlap(["v0"], ["v0"])[0] == pytest.approx(1.0 if views[0] else 0.0)


def test_lambda_is_read_off_validation_triplets() -> None:
    # the image similarity gets half right; the boxes get the rest right with a big lambda
    s_ap, s_an = np.array([0.9, 0.2]), np.array([0.1, 0.8])
    box_ap, box_an = np.array([0.5, 0.5]), np.array([0.5, 0.4])
    weight, by_weight = choose_box_weight(s_ap, s_an, box_ap, box_an)
    assert by_weight["0"] == 0.5 and by_weight[f"{weight:g}"] == 1.0
    assert weight == min(w for w in BOX_WEIGHTS if by_weight[f"{w:g}"] == 1.0)
