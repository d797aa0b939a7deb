"""seannet compare: every choice on val, selection written before test is read, intervals over
rooms and seeds, budget calibrated."""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import pytest
import torch

from seannet.errors import ModelError
from seannet.evaluation.compare import (
    CALIBRATIONS,
    SELECTION,
    compare_models,
    model_spec,
)
from seannet.training.config import TrainConfig
from seannet.training.runs import build_for_dataset as compare_build
from seannet.weights import LITE0_WEIGHTS
from sgdata.dataset import Dataset

TINY = TrainConfig().replace(
    graph_hidden=512,  # the cpu preset's GCN fc width, for the SeanNets compared
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


@pytest.mark.slow  # a whole comparison trained, selected on val, then read on test
def test_compare_selects_on_val_before_reading_test(tmp_path: Path, mini_dataset: Path) -> None:
    # the test split is not there until the selection is written: a read of it before then
    # fails the whole comparison
    data = tmp_path / "data"
    shutil.copytree(mini_dataset, data)
    hidden = tmp_path / "hidden"
    hidden.mkdir()
    test_files = [data / "triplets" / "test.parquet", data / "observations" / "test"]
    for path in test_files:
        path.rename(hidden / path.name)
    seen: dict = {}

    def reveal_test(selection: Path) -> None:
        seen.update(json.loads(selection.read_text()))
        for path in test_files:
            (hidden / path.name).rename(path)

    out = tmp_path / "cmp"
    result = compare_models(
        data,
        out,
        ["resnet18", "resnet18+boxes", "seannet-graph"],
        preset=TINY,
        seeds=(0, 1),
        lrs=(0.01, 0.03),
        budget_s=0.001,  # one batch an epoch: what TINY trains anyway
        on_selected=reveal_test,
    )
    assert [m["model"] for m in seen["models"]] == ["resnet18", "resnet18+boxes", "seannet-graph"]
    assert json.loads((out / SELECTION).read_text()) == seen
    for choice, entry in zip(seen["models"], result["models"], strict=True):
        # the chosen lr is the one with the best accuracy on the *whole* val split
        by_lr = choice["val_accuracy_by_lr"]
        best = max(by_lr.values())
        assert choice["lr"] == min(float(k) for k, v in by_lr.items() if v == best)
        tag = "+boxes" if choice["model"].endswith("+boxes") else ""
        val = json.loads((Path(choice["runs"][0]) / f"eval_val{tag}.json").read_text())
        # every val triplet of the dataset, not a subset
        assert val["triplets"] == Dataset.open(data).triplets("val").num_rows
        assert by_lr[f"{choice['lr']:g}"] == val["accuracy"]
        summary = entry["summary"]
        assert summary["accuracy"]["n"] == 2 and summary["triplets"] == 10
        # the rooms x seeds interval is about the seeds' mean, and never narrower than the
        # seeds' own t-interval (2 seeds: t on 1 dof) where an accuracy's [0, 1] leaves room
        two, seeds = summary["two_level"], summary["accuracy"]
        assert two["mean"] == pytest.approx(seeds["mean"])
        assert 0.0 <= two["low"] <= two["high"] <= 1.0
        assert two["high"] >= min(1.0, seeds["mean"] + seeds["ci95"]) - 1e-9
        assert two["low"] <= max(0.0, seeds["mean"] - seeds["ci95"]) + 1e-9
        # what the budget bought, and the timing it rests on, recorded with the choice
        budget = choice["budget"]
        assert budget["source"] == "calibrated" and budget["budget_s"] == 0.001
        assert budget["batches"] == choice["batches_per_epoch"] == 1
        assert choice["examples"] == budget["examples"] == TINY.batch_size * TINY.epochs
        assert budget["step_s"] > 0 and budget["spread"] >= 0
    # +boxes shares the network's runs, and chose its lambda on val
    plain, boxes = seen["models"][0], seen["models"][1]
    assert all(Path(r).parent.parent.name == "resnet18" for r in plain["runs"] + boxes["runs"])
    assert "box_weight" in result["models"][1]["runs"][0]
    difference = result["models"][2]["difference_to_first"]
    first, third = (result["models"][k]["summary"]["accuracy"]["mean"] for k in (0, 2))
    assert difference["mean"] == pytest.approx(first - third)
    # never narrower than Welch's interval over the seeds
    welch = difference["seeds_t"]
    assert welch["mean"] == pytest.approx(difference["mean"])
    assert difference["high"] >= welch["high"] - 1e-9 and difference["low"] <= welch["low"] + 1e-9
    table = (out / "comparison.md").read_text()
    assert "| resnet18+boxes |" in table and "| seannet-graph |" in table


def test_a_resumed_comparison_trains_the_batches_its_calibration_kept(
    tmp_path: Path, mini_dataset: Path
) -> None:
    # stopped before its selection was written and started again (maybe on another machine):
    # the calibration kept in calibrations.json sets the batches, not a second timing
    out = tmp_path / "cmp"
    ask = {"preset": TINY, "seeds": (0,), "lrs": (0.01,), "budget_s": 0.001}
    first = compare_models(mini_dataset, out, ["resnet18"], **ask)["models"][0]
    kept = json.loads((out / CALIBRATIONS).read_text())
    assert [r["key"]["trained"] for r in kept] == ["resnet18"]
    # the selection holds the record and the comparison it was timed for (untagged: "")
    assert kept[0]["comparison"] == ""
    assert {**kept[0]["calibration"], "source": "calibrated", "timed_for": ""} == first["budget"]
    (out / SELECTION).unlink()
    again = compare_models(mini_dataset, out, ["resnet18"], **ask)["models"][0]
    assert again["budget"] == first["budget"]  # the same timing, not a new one
    assert json.loads((out / CALIBRATIONS).read_text()) == kept
    # the kept record is what sets the batches: one that says 2 trains 2 a epoch
    other = tmp_path / "other"
    other.mkdir()
    record = json.loads(json.dumps(kept[0]))
    record["calibration"] |= {"batches": 2, "examples": 2 * TINY.batch_size * TINY.epochs}
    (other / CALIBRATIONS).write_text(json.dumps([record]))
    two = compare_models(mini_dataset, other, ["resnet18"], **ask)["models"][0]
    assert two["batches_per_epoch"] == two["budget"]["batches"] == 2
    trained = torch.load(Path(two["runs"][0]["run"]) / "last.pt", weights_only=False)
    assert trained["config"]["max_train_batches"] == 2
    # another budget is a calibration of its own, kept beside the first
    compare_models(mini_dataset, out, ["resnet18"], **{**ask, "budget_s": 0.002})
    assert [r["key"]["budget_s"] for r in json.loads((out / CALIBRATIONS).read_text())] == [
        0.001,
        0.002,
    ]


def test_a_network_timed_on_a_later_machine_gets_the_first_machines_seconds(
    tmp_path: Path, mini_dataset: Path
) -> None:
    # the runs' first calibration was taken by another process on a machine where resnet18
    # took 100 s a step (far slower than here): seannet-graph, first timed now, is put in that
    # machine's seconds by resnet18's step there and here, not given this machine's
    out = tmp_path / "cmp"
    out.mkdir()
    shape = {"budget_s": 1000.0, "batch_size": 4, "epochs": 1, "image_size": 64, "device": "cpu"}
    then = {"budget_s": 1000.0, "batches": 1, "examples": 4, "step_s": 100.0, "steps_s": [100.0]}
    record = {
        "key": {"trained": "resnet18", **shape},
        "taken": {"pid": -1, "code_loaded": "2026-12-01 00:00:00 UTC", "started": "then"},
        "calibration": then | {"spread": 0.0, "busy": 0.0, "clock": "thread-cpu, 1 torch thread"},
    }
    (out / CALIBRATIONS).write_text(json.dumps([record]))
    ask = {"preset": TINY, "seeds": (0,), "lrs": (0.01,), "budget_s": 1000.0}
    models = compare_models(mini_dataset, out, ["resnet18", "seannet-graph"], **ask)["models"]
    assert models[0]["budget"]["step_s"] == 100.0 and models[0]["batches_per_epoch"] == 1
    graph = models[1]["budget"]
    by = graph["converted_by"]
    assert by["reference"] == "resnet18" and by["reference_then_s"] == 100.0
    assert 0 < by["reference_now_s"] < 10 and 0 < by["timed_s"] < 10  # timed here, far faster
    assert graph["step_s"] == pytest.approx(by["timed_s"] * 100.0 / by["reference_now_s"])
    assert graph["batches"] == models[1]["batches_per_epoch"] == max(1, int(1000 / graph["step_s"]))
    kept = json.loads((out / CALIBRATIONS).read_text())
    assert [r["key"]["trained"] for r in kept] == ["resnet18", "seannet-graph"]
    assert {**kept[1]["calibration"], "source": "calibrated", "timed_for": ""} == graph


@pytest.mark.parametrize("text", ["{not json", "[1, 2]", '[{"key": {}}]'])
def test_a_damaged_calibrations_file_is_one_clear_error(
    tmp_path: Path, mini_dataset: Path, text: str
) -> None:
    out = tmp_path / "cmp"
    out.mkdir()
    (out / CALIBRATIONS).write_text(text)
    with pytest.raises(ModelError, match=r"calibrations.json: not a list of calibration"):
        compare_models(mini_dataset, out, ["resnet18"], preset=TINY, budget_s=0.001)
    assert not (out / "resnet18").exists()  # refused before any run trained


def test_model_specs_name_network_and_imagenet_init() -> None:
    spec = model_spec("seannet@lite0+imagenet", TINY)
    assert (spec.config.model.name, spec.config.model.backbone, spec.pretrained) == (
        "seannet",
        "efficientnet_lite0",
        Path(LITE0_WEIGHTS),
    )
    spec = model_spec("seannet-graph@lite0", TINY)
    assert (spec.config.model.name, spec.config.model.backbone, spec.pretrained) == (
        "seannet-graph",
        "efficientnet_lite0",
        None,
    )
    spec = model_spec("efficientnet_lite0+imagenet", TINY)
    assert (spec.config.model.name, spec.config.model.image_family, spec.pretrained) == (
        "efficientnet_lite0",
        "efficientnet_lite0",
        Path(LITE0_WEIGHTS),
    )
    assert model_spec("resnet18", TINY).config.model.backbone == "resnet"
    for term in ("+boxes", "+box-kernel"):
        boxes = model_spec(f"seannet@lite0{term}", TINY)
        assert (boxes.trained, boxes.boxes, boxes.config) == (
            "seannet@lite0",
            term,
            model_spec("seannet@lite0", TINY).config,
        )


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
