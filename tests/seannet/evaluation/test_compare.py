"""seannet compare: lr chosen on val, seeds summarised with intervals, budget calibrated."""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import pytest
import torch

from seannet.errors import ModelError
from seannet.evaluation.compare import (
    calibrate_batches,
    compare_models,
    model_spec,
    paired_difference,
)
from seannet.model.backbones import LITE0_WEIGHTS
from seannet.training.config import TrainConfig
from seannet.training.runs import build_for_dataset as compare_build

TINY = TrainConfig().replace(
    depth=18,
    image_size=64,
    roi_size=4,
    visual_features="c5",
    embed_dim=64,
    epochs=1,
    batch_size=4,
    max_train_batches=1,
    num_workers=0,
)


def test_compare_sweeps_lr_and_summarises_seeds(tmp_path: Path, mini_dataset: Path) -> None:
    out = tmp_path / "cmp"
    result = compare_models(
        mini_dataset,
        out,
        ["resnet18", "seannet-graph"],
        preset=TINY,
        seeds=(0, 1),
        lrs=(0.01, 0.03),
    )
    saved = json.loads((out / "comparison.json").read_text())
    assert [e["model"] for e in saved["models"]] == ["resnet18", "seannet-graph"]
    for entry in result["models"]:
        assert entry["lr"] in (0.01, 0.03)
        assert set(entry["val_accuracy_by_lr"]) == {"0.01", "0.03"}
        summary = entry["summary"]
        assert summary["accuracy"]["n"] == 2 and summary["triplets"] == 10
        assert not math.isnan(summary["accuracy"]["ci95"])
        assert set(summary["by_moved"]) == {"0", "1-2", "3-5", "6+"}
        # the chosen lr's seed-0 run is the sweep's: seeds reuse it
        assert (out / entry["model"] / f"lr{entry['lr']:g}" / "seed1" / "best.pt").exists()
    table = (out / "comparison.md").read_text()
    assert "| resnet18 |" in table
    difference = saved["models"][1]["difference_to_first"]
    assert difference["low"] <= difference["mean"] <= difference["high"]
    assert f"- seannet-graph: {100 * difference['mean']:+.1f} points" in table


def test_paired_difference_weights_rooms_and_brackets_the_gap() -> None:
    def runs(*per_room: dict[str, float]) -> list[dict]:
        return [{"per_room": rooms} for rooms in per_room]

    counts = {"a": 10, "b": 30, "c": 20}
    better = runs({"a": 1.0, "b": 0.6, "c": 0.9}, {"a": 0.8, "b": 0.6, "c": 0.7})
    worse = runs({"a": 0.5, "b": 0.5, "c": 0.5})
    d = paired_difference(better, worse, counts)
    # seeds averaged per room (0.9, 0.6, 0.8), minus 0.5, weighted 10 / 30 / 20
    assert d["mean"] == pytest.approx((0.4 * 10 + 0.1 * 30 + 0.3 * 20) / 60)
    assert 0.0 < d["low"] < d["mean"] < d["high"] <= 0.4 and d["rooms"] == 3
    same = paired_difference(worse, worse, counts)
    assert same["mean"] == same["low"] == same["high"] == 0.0
    assert paired_difference(better, worse, counts) == d  # a fixed resampling seed


def test_budget_buys_batches(mini_dataset: Path) -> None:
    few = calibrate_batches(TINY.replace(model="resnet18", epochs=2), mini_dataset, 0.001)
    many = calibrate_batches(TINY.replace(model="resnet18", epochs=2), mini_dataset, 60.0)
    assert few == 1 and many > few


def test_model_specs_name_network_and_imagenet_init() -> None:
    config, weights = model_spec("seannet@lite0+imagenet", TINY)
    assert (config.model.name, config.model.backbone, weights) == (
        "seannet",
        "efficientnet_lite0",
        Path(LITE0_WEIGHTS),
    )
    config, weights = model_spec("seannet-graph@lite0", TINY)
    assert (config.model.name, config.model.backbone, weights) == (
        "seannet-graph",
        "efficientnet_lite0",
        None,
    )
    config, weights = model_spec("efficientnet_lite0+imagenet", TINY)
    assert (config.model.name, config.model.image_family, weights) == (
        "efficientnet_lite0",
        "efficientnet_lite0",
        Path(LITE0_WEIGHTS),
    )
    assert model_spec("resnet18", TINY)[0].model.backbone == "resnet"


@pytest.mark.parametrize(
    "spec", ["resnet18+imagenet", "seannet+imagenet", "resnet18@lite0", "seannet@vgg"]
)
def test_model_specs_refused_before_any_run(tmp_path: Path, mini_dataset: Path, spec: str) -> None:
    with pytest.raises(ModelError, match=re.escape(spec)):
        compare_models(mini_dataset, tmp_path / "cmp", ["resnet18", spec], preset=TINY)
    assert not (tmp_path / "cmp").exists()  # refused before the first (valid) model trained


def test_compare_trains_from_imagenet_weights(tmp_path: Path, mini_dataset: Path) -> None:
    out = tmp_path / "cmp"
    small = TINY.replace(image_size=64)
    result = compare_models(mini_dataset, out, ["efficientnet_lite0+imagenet"], preset=small)
    assert result["models"][0]["pretrained"] == LITE0_WEIGHTS
    # the run started from the ImageNet weights: its stem is not a fresh random init
    state = torch.load(
        out / "efficientnet_lite0+imagenet" / "lr0.01" / "seed0" / "best.pt", weights_only=False
    )
    stem = state["model"]["encoder.0.0.weight"]  # the stem convolution
    torch.manual_seed(0)
    fresh = compare_build(small.replace(model="efficientnet_lite0"), mini_dataset)
    fresh_stem = fresh.state_dict()["encoder.0.0.weight"]
    assert not torch.allclose(stem, fresh_stem, atol=1e-2)
