"""seannet compare: lr chosen on val, seeds summarised with intervals, budget calibrated."""

from __future__ import annotations

import json
import math
from pathlib import Path

from seannet.compare import calibrate_batches, compare_models
from seannet.config import TrainConfig

TINY = TrainConfig(
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
    assert "| resnet18 |" in (out / "comparison.md").read_text()


def test_budget_buys_batches(mini_dataset: Path) -> None:
    few = calibrate_batches(TINY.replace(model="resnet18", epochs=2), mini_dataset, 0.001)
    many = calibrate_batches(TINY.replace(model="resnet18", epochs=2), mini_dataset, 60.0)
    assert few == 1 and many > few
