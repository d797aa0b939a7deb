"""``seannet eval`` on a real dataset: a run trained on synthetic views, evaluated on photos."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from sgdata.label.export import export_dataset
from sgdata.label.models import PhotoLabels
from sgdata.label.store import LabelStore

from .conftest import make_photo

torch = pytest.importorskip("torch")


def _real_dataset(tmp_path: Path) -> Path:
    """40 posed photos of one room (2 layouts x 5 cells x 4 headings), 80x60 PNG and JPEG,
    unlike the 96 px training views; a few boxes and an accepted relation each."""
    photos, out = tmp_path / "photos", tmp_path / "real"
    photos.mkdir()
    store = LabelStore(out)
    k = 0
    for layout in (0, 1):
        for i in range(5):
            for heading in range(4):
                name = f"p{k:03d}.{'jpg' if k % 3 == 0 else 'png'}"
                make_photo(photos / name, width=80, height=60, seed=k)
                objects = [
                    {"id": 0, "class_name": "Toilet", "box": [5, 20, 40, 58]},
                    {"id": 1, "class_name": "SoapBar", "box": [10 + i, 10, 20 + i, 22]},
                    {"id": 2, "class_name": "Towel", "box": [50, 5, 78, 40 - heading]},
                ]
                labels = {
                    "room_id": "bathroom_real",
                    "room_type": "bathroom",
                    "pose": {"layout": layout, "i": i, "j": 0, "heading": heading},
                    "objects": objects,
                    "relations": [{"src": 1, "dst": 0, "type": "on"}],
                }
                store.save(name, PhotoLabels.model_validate(labels))
                k += 1
    summary = export_dataset(photos, out)
    assert summary.triplets > 0
    return out


def test_eval_runs_on_a_real_dataset(tmp_path: Path, mini_dataset: Path) -> None:
    from seannet.evaluation.run_eval import evaluate_run
    from seannet.training.config import TrainConfig
    from seannet.training.train import train

    # tests/seannet/test_train.py's CPU settings, one epoch of 3 batches
    fast = TrainConfig().replace(
        model="seannet-fc512",
        depth=18,
        image_size=64,
        roi_size=4,
        embed_dim=256,
        epochs=1,
        batch_size=4,
        lr=0.05,
        max_train_batches=3,
        num_workers=0,
        decay_every=10,
    )
    train(fast, mini_dataset, tmp_path / "run")
    real = _real_dataset(tmp_path)
    result = evaluate_run(tmp_path / "run", real, split="test", out=tmp_path / "eval")
    triplets = json.loads((real / "dataset.json").read_text())["counts"]["triplets"]["test"]
    assert result["triplets"] == triplets and 0.0 <= result["accuracy"] <= 1.0
    assert set(result["per_room"]) == {"bathroom_real"}
    assert "no val split" in result["threshold"]["rule"]
    assert (tmp_path / "eval" / "eval_test.md").read_text().startswith("# seannet-fc512 on test")
    assert (tmp_path / "eval" / "heat_mean_test.png").read_bytes()[:4] == b"\x89PNG"
