"""seannet eval under box noise and with the box overlap: choices on val, files by option."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from seannet.data.box_noise import BoxNoise
from seannet.errors import DataError
from seannet.evaluation.run_eval import eval_file, evaluate_run
from seannet.training.config import TrainConfig
from seannet.training.train import train

NOISE = BoxNoise(jitter=0.1, drop=0.25, spurious=0.5, seed=2)


def test_box_noise_reaches_the_scene_graph_not_the_image(
    tmp_path: Path, mini_dataset: Path, localizer_run: Path, tiny_seannet: TrainConfig
) -> None:
    run = tmp_path / "seannet"
    train(tiny_seannet, mini_dataset, run)
    clean = evaluate_run(run, mini_dataset, split="test", out=tmp_path / "a")
    noisy = evaluate_run(run, mini_dataset, split="test", out=tmp_path / "a", noise=NOISE)
    assert noisy["noise"] == {"jitter": 0.1, "drop": 0.25, "spurious": 0.5, "seed": 2}
    assert (tmp_path / "a" / f"eval_test_{NOISE.label()}.json").exists()
    # SeanNet reads the boxes: its similarities move; epsilon is re-read on noisy val
    assert noisy["mean_gap"] != clean["mean_gap"]
    # an image encoder does not
    image = evaluate_run(localizer_run, mini_dataset, split="test", out=tmp_path / "b")
    image_noisy = evaluate_run(
        localizer_run, mini_dataset, split="test", out=tmp_path / "b", noise=NOISE
    )
    assert image_noisy["mean_gap"] == pytest.approx(image["mean_gap"])


def test_boxes_choose_lambda_on_val_and_write_their_own_file(
    tmp_path: Path, mini_dataset: Path, localizer_run: Path
) -> None:
    out = tmp_path / "eval"
    plain = evaluate_run(localizer_run, mini_dataset, split="test", out=out)
    boxed = evaluate_run(localizer_run, mini_dataset, split="test", out=out, boxes="+boxes")
    assert boxed["model"] == "resnet18+boxes" and plain["model"] == "resnet18"
    saved = json.loads(eval_file(out, "test", boxes="+boxes").read_text())
    weight = saved["box_weight"]
    val = evaluate_run(
        localizer_run, mini_dataset, split="val", out=tmp_path / "val", boxes="+boxes"
    )
    # lambda is what the val triplets chose, whichever split is evaluated
    assert weight == val["box_weight"]
    by = weight["val_accuracy_by_lambda"]
    assert by[f"{weight['lambda']:g}"] == max(by.values()) == val["accuracy"]
    assert json.loads(eval_file(out, "test").read_text())["accuracy"] == plain["accuracy"]


@pytest.mark.parametrize(("term", "split"), [("+boxes", "val"), ("+box-kernel", "train")])
def test_boxes_need_the_split_they_learn_on(
    tmp_path: Path, mini_dataset: Path, localizer_run: Path, term: str, split: str
) -> None:
    import shutil

    data = tmp_path / "data"
    shutil.copytree(mini_dataset, data)
    manifest = json.loads((data / "dataset.json").read_text())
    rooms = manifest["splits"].pop(split)
    counts = manifest["counts"]
    counts["rooms"] -= len(rooms)
    for key in ("observations", "triplets", "tiers"):
        del counts[key][split]
    (data / "dataset.json").write_text(json.dumps(manifest))
    with pytest.raises(DataError, match=f"{re.escape(term)} .* the {split} split"):
        evaluate_run(localizer_run, data, split="test", out=tmp_path / "x", boxes=term)
