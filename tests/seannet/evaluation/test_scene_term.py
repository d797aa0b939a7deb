"""The scene term: one object for ``+boxes`` / ``+box-kernel``, and ``seannet eval`` and the
method benchmark, which both use it, choose the same lambda and score the same accuracy."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import torch

from seannet.evaluation.box_overlap import SlotBoxes
from seannet.evaluation.run_eval import evaluate_run
from seannet.evaluation.scene_term import SceneTerm
from seannet.methods import BenchmarkConfig, benchmark_method
from seannet.methods.boxes import box_scores, box_vectors, row_triplets, vector_boxes

SLOTS = 6


def _boxes(rng: np.random.Generator, views: int) -> tuple[SlotBoxes, torch.Tensor]:
    """Random views' boxes as SlotBoxes (ids "0", "1", ...) and as (N, M, 4) NaN-padded."""
    dense = torch.full((views, SLOTS, 4), float("nan"))
    for v in range(views):
        for s in rng.choice(SLOTS, size=rng.integers(0, SLOTS), replace=False):
            lo = rng.uniform(0, 0.6, 2)
            dense[v, s] = torch.tensor([*lo, *(lo + rng.uniform(0.05, 0.4, 2))])
    present = ~torch.isnan(dense[..., 0])
    view, slot = torch.nonzero(present, as_tuple=True)
    offsets = np.concatenate([[0], np.cumsum(present.sum(1).numpy())])
    table = SlotBoxes(
        [str(k) for k in range(views)], offsets, slot.numpy(), dense[view, slot].numpy(), SLOTS
    )
    return table, dense


def test_a_scene_term_is_named_by_the_spec() -> None:
    assert SceneTerm.from_spec("+boxes").term == "+boxes" and not SceneTerm().learned
    assert SceneTerm.from_spec("+box-kernel").learned
    with pytest.raises(ValueError, match=r"scene term '\+box': expected one of \+boxes"):
        SceneTerm.from_spec("+box")
    with pytest.raises(ValueError, match="box-kernel: fit the kernel"):
        SceneTerm.from_spec("+box-kernel").scores(_boxes(np.random.default_rng(0), 2)[0], [], [])


def test_the_scores_are_the_overlap_or_the_kernel_fit_on_train() -> None:
    rng = np.random.default_rng(1)
    table, dense = _boxes(rng, 40)
    first, second = [str(k) for k in range(20)], [str(k) for k in range(20, 40)]
    assert np.array_equal(SceneTerm.from_spec("+boxes").scores(table, first, second),
                          table.overlap(first, second))  # fmt: skip
    assert not SceneTerm().scores(table, first, second).any()  # no term: no score
    # a method's box vectors are the same boxes: the same scores, row pair by row pair
    vectors = box_vectors(dense)
    rows = box_scores(vectors[:20], vectors[20:], SceneTerm.from_spec("+boxes"))
    assert rows.numpy() == pytest.approx(table.overlap(first, second), abs=1e-6)
    triplets = np.array([[3 * k, 3 * k + 1, 3 * k + 2] for k in range(13)])
    kernel = SceneTerm.from_spec("+box-kernel")
    kernel.fit(vector_boxes(vectors), row_triplets(triplets))
    fit = kernel.choices["box_kernel"]
    assert fit["train_triplets"] == 13 and 0.0 <= fit["train_accuracy"] <= 1.0
    b_ap, b_an = kernel.triplet_scores(table, row_triplets(triplets))
    assert fit["train_accuracy"] == pytest.approx(np.mean(b_ap > b_an))
    assert ((b_ap >= 0) & (b_ap <= 1)).all()
    again = SceneTerm.from_spec("+box-kernel")
    again.fit(table, row_triplets(triplets))  # the same boxes give the same kernel
    assert np.array_equal(again.triplet_scores(table, row_triplets(triplets))[0], b_ap)


def test_lambda_is_chosen_on_val_and_combines_one_way() -> None:
    scene = SceneTerm.from_spec("+boxes")
    s_ap, s_an = np.array([0.9, 0.2, 0.3]), np.array([0.1, 0.8, 0.4])
    b_ap, b_an = np.array([0.5, 0.9, 0.5]), np.array([0.5, 0.1, 0.2])
    weight, by_weight = scene.choose_weight(s_ap, s_an, b_ap, b_an)
    assert scene.weight == weight == 1.0  # the smallest that ranks all three right
    assert scene.choices["box_weight"] == {"lambda": 1.0, "val_accuracy_by_lambda": by_weight}
    assert [by_weight[k] for k in ("0", "0.5", "1", "50")] == pytest.approx([1 / 3, 2 / 3, 1, 1])
    combined = scene.combine(s_ap, b_ap)
    assert combined == pytest.approx(s_ap + b_ap)
    unit = scene.combine(s_ap, b_ap, unit=True)  # a method's similarity: a cosine's range
    assert unit == pytest.approx(combined / 2) and (np.abs(unit) <= 1).all()
    assert np.array_equal(np.argsort(unit), np.argsort(combined))
    assert np.array_equal(SceneTerm().combine(s_ap, b_an), s_ap)  # lambda 0: S alone


def test_eval_and_the_benchmark_choose_the_same_lambda_and_accuracy(
    tmp_path: Path, mini_dataset: Path
) -> None:
    config = BenchmarkConfig(
        seeds=(0,), preset="smoke", batch_size=16, batches=1, epochs=1, noise=()
    )
    for term in ("+boxes", "+box-kernel"):
        card = json.loads(
            benchmark_method(f"resnet18{term}", mini_dataset, tmp_path, config).read_text()
        )
        (method,) = card["runs"]
        run = Path(method["choices"]["run"])  # the network NetworkMethod trained and kept
        evaluated = evaluate_run(run, mini_dataset, split="test", out=tmp_path / term, boxes=term)
        assert evaluated["box_weight"] == method["choices"]["box_weight"]
        assert evaluated["accuracy"] == method["accuracy"]
        assert evaluated["per_tier"] == pytest.approx(
            {int(k): v for k, v in method["per_tier"].items()}
        )
        if term == "+box-kernel":  # the same kernel fit on the same train triplets
            assert evaluated["box_kernel"] == method["choices"]["box_kernel"]
