"""The detector in the loop on the mini dataset with depth: trained on its COCO export, scored
by pycocotools, its graphs fed to a localizer's evaluation in place of the generator's."""

from __future__ import annotations

import hashlib
import json
import shutil
from pathlib import Path

import pytest

from tests.bench_scripts import load_script
from tests.cli_runner import run_cli


@pytest.fixture(scope="module")
def detector_run(detector_copy: Path) -> Path:
    """This module's evaluations write into the run: its own copy."""
    return detector_copy


def test_a_trained_detector_records_its_curve_and_is_scored_by_pycocotools(
    detector_run: Path, channels_dataset: Path
) -> None:
    record = json.loads((detector_run / "detector.json").read_text())
    assert [e["epoch"] for e in record["epochs"]] == [1, 2]
    assert record["best_epoch"] in (1, 2)
    assert record["config"]["pretrained"] == "imagenet-lite0"
    assert (detector_run / "coco" / "annotations" / "instances_train.json").is_file()
    # the export belongs to the dataset it was made of: another dataset's would be replaced
    manifest = (channels_dataset / "dataset.json").read_bytes()
    marker = (detector_run / "coco.manifest_sha256").read_text().strip()
    assert marker == hashlib.sha256(manifest).hexdigest()
    done = run_cli("seannet", "detector", "eval", detector_run, "--data", channels_dataset)
    assert done.returncode == 0, done.stderr
    score = json.loads((detector_run / "eval_test.json").read_text())
    truth = json.loads((detector_run / "coco/annotations/instances_test.json").read_text())
    assert score["views"] == len(truth["images"])
    assert 0.0 <= score["ap"] <= score["ap50"] <= 1.0
    # every class with a true box in the test views has its AP50, and only those
    names = {c["id"]: c["name"] for c in truth["categories"]}
    assert set(score["ap50_per_class"]) == {names[a["category_id"]] for a in truth["annotations"]}


def test_a_hand_edited_coco_file_of_a_run_is_one_line_naming_the_entry(
    tmp_path: Path, detector_run: Path, channels_dataset: Path
) -> None:
    run = tmp_path / "run"
    shutil.copytree(detector_run, run)
    (run / "eval_test.json").unlink(missing_ok=True)  # another test's eval of the module's run
    path = run / "coco" / "annotations" / "instances_test.json"
    document = json.loads(path.read_text())
    document["annotations"][1]["bbox"][0] = "12"  # a number typed as text
    path.write_text(json.dumps(document))
    done = run_cli("seannet", "detector", "eval", run, "--data", channels_dataset)
    assert done.returncode == 2 and len(done.stderr.strip().splitlines()) == 1, done.stderr
    assert f"{path}: annotations[1].bbox: expected [x, y, width, height] numbers" in done.stderr
    assert not (run / "eval_test.json").exists()


def test_a_coco_file_nested_too_deeply_is_one_line(tmp_path: Path) -> None:
    from seannet.detection.coco_views import CocoViews
    from seannet.errors import DataError

    path = tmp_path / "annotations" / "instances_test.json"
    path.parent.mkdir()
    path.write_text("[" * 100_000 + "]" * 100_000)  # valid JSON, deeper than the parser recurses
    with pytest.raises(DataError, match="not a readable COCO file") as caught:
        CocoViews(tmp_path, "test")
    assert str(path) in str(caught.value) and "\n" not in str(caught.value)


def test_eval_with_detected_graphs_is_its_own_file_and_reuses_the_detections(
    tmp_path: Path, detector_run: Path, channels_dataset: Path, localizer_run: Path
) -> None:
    run = tmp_path / "run"
    shutil.copytree(localizer_run, run)
    args = ("eval", run, "--data", channels_dataset, "--graphs", "detected", "--detector")
    done = run_cli("seannet", *args, detector_run)
    assert done.returncode == 0, done.stderr
    written = sorted(p.name for p in run.glob("eval_test_detected-*.json"))
    assert len(written) == 1, sorted(p.name for p in run.iterdir())
    chosen = json.loads(next((detector_run / "graphs").glob("*/threshold.json")).read_text())
    assert written[0].endswith(f"-t{chosen['threshold']:g}.json")
    assert f"detected-{chosen['detector'][:8]}-" in written[0]
    assert max(chosen["val_f1"].values()) == chosen["val_f1"][f"{chosen['threshold']:g}"]
    cached = sorted((detector_run / "graphs").glob("*/*.parquet"))
    assert [p.name for p in cached] == ["test.parquet", "val.parquet"]
    stamps = [p.stat().st_mtime_ns for p in cached]
    again = run_cli("seannet", *args, detector_run)
    assert again.returncode == 0, again.stderr
    assert [p.stat().st_mtime_ns for p in cached] == stamps  # read from the cache


def test_detected_graphs_need_depth_and_a_detector_run(
    tmp_path: Path, detector_run: Path, mini_dataset: Path, localizer_run: Path
) -> None:
    run = tmp_path / "run"
    shutil.copytree(localizer_run, run)
    alone = run_cli("seannet", "eval", run, "--data", mini_dataset, "--graphs", "detected")
    assert alone.returncode == 2 and "--detector RUN" in alone.stderr
    no_depth = run_cli(
        "seannet",
        "eval",
        run,
        "--data",
        mini_dataset,
        "--graphs",
        "detected",
        "--detector",
        detector_run,
    )
    assert no_depth.returncode == 2
    assert "no depth" in no_depth.stderr and "[outputs] depth = true" in no_depth.stderr
    assert len(no_depth.stderr.strip().splitlines()) == 1, no_depth.stderr
    assert not list(run.glob("eval_test_detected*"))


def test_the_benchmark_sweep_gains_a_detected_graphs_row(
    tmp_path: Path, detector_run: Path, channels_dataset: Path
) -> None:
    done = run_cli(
        "seannet",
        "benchmark",
        "--data",
        channels_dataset,
        "--methods",
        "boxes-overlap",
        "--out",
        tmp_path / "cards",
        "--seeds",
        "0",
        "--detector",
        detector_run,
    )
    assert done.returncode == 0, done.stderr
    card = json.loads(next((tmp_path / "cards").rglob("card.json")).read_text())
    labels = [n["label"] for n in card["summary"]["box_noise"]]
    assert labels[-1].startswith("detected-") and len(labels) == 6, labels
    assert 0.0 <= card["summary"]["box_noise"][-1]["accuracy"] <= 1.0
    assert (
        0.0 <= card["summary"]["box_noise"][-1]["recall1"] <= 1.0
    )  # the map's graphs detected too
    assert labels[-1] in (tmp_path / "cards" / "boxes-overlap" / "card.md").read_text()
    # the doc's figures come from evidence copied out of the runs, not from the runs
    scored = run_cli("seannet", "detector", "eval", detector_run, "--data", channels_dataset)
    assert scored.returncode == 0, scored.stderr
    # what the detected graphs lose, on the test views the sweep's graphs came from
    lost = run_cli("seannet", "detector", "graphs", detector_run, "--data", channels_dataset)
    assert lost.returncode == 0, lost.stderr
    fidelity = json.loads((detector_run / "graphs_test.json").read_text())
    assert fidelity["objects"]["true"] > 0 and 0.0 <= fidelity["objects"]["recall"] <= 1.0
    recall = f"{100 * fidelity['objects']['recall']:.1f}"
    assert "true objects found" in lost.stdout and recall in lost.stdout
    figures = load_script("detector_figures")
    figures.RECORDS = tmp_path / "records"
    folder = figures.record(detector_run, tmp_path / "cards", channels_dataset)
    shutil.rmtree(tmp_path / "cards")
    text = figures.doc()
    assert folder.name in text
    assert "*Made by " in text and "manifest sha256" in text  # the stamp of the commands
    accuracy = card["summary"]["accuracy"]["mean"]
    assert f"| `boxes-overlap` | {100 * accuracy:.1f} |" in text
    # the recall@1 columns, true then detected, from the card
    recall = (card["summary"]["recall1"]["mean"], card["summary"]["box_noise"][-1]["recall1"])
    assert " | {:.1f} | {:.1f} | ".format(*(100 * r for r in recall)) in text
    assert (folder / "graphs_test.json").read_text() == json.dumps(fidelity, indent=1) + "\n"
    assert "**What the detected graphs lose** on the" in text
