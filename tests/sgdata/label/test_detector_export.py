"""``sgdata export coco`` and ``export yolo`` on the mini dataset with masks: pycocotools reads
the files, COCOeval of the ground truth against itself is perfect, ``sgdata import coco`` gives
the boxes back, YOLO labels are the stored boxes; bad input is one line and writes nothing."""

from __future__ import annotations

import json
from collections import Counter
from pathlib import Path

import numpy as np
import pytest

from sgdata.dataset import Dataset
from sgdata.dataset.channels import decode_channel
from sgdata.label.coco_export import export_coco
from sgdata.label.importers import import_labels
from sgdata.label.yolo_export import export_yolo

from ...cli_runner import Done, run_cli

pytest.importorskip("pycocotools")


def _boxes(root: Path, split: str) -> Counter:
    """(image file stem, class, box) of every object of a split."""
    rows = Dataset.open(root).observations(split).to_pylist()
    return Counter(
        (row["obs_id"].replace("/", "__"), o["class_name"], tuple(o["box2d"]))
        for row in rows
        for o in row["objects"]
    )


@pytest.fixture(scope="module")
def coco(channels_dataset: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("coco") / "coco"
    done = export_coco(channels_dataset, out, masks=True)
    assert done.masks and done.images > 0 and done.annotations > 0
    return out


def test_coco_loads_and_scores_itself_perfectly(coco: Path, channels_dataset: Path) -> None:
    from pycocotools.coco import COCO
    from pycocotools.cocoeval import COCOeval

    ds = Dataset.open(channels_dataset)
    for split in ds.splits:
        gt = COCO(str(coco / "annotations" / f"instances_{split}.json"))
        rows = ds.observations(split).to_pylist()
        assert len(gt.getImgIds()) == len(rows)
        assert len(gt.getAnnIds()) == sum(len(r["objects"]) for r in rows)
        for image in gt.loadImgs(gt.getImgIds()):
            assert (coco / "images" / split / image["file_name"]).is_file()
        # the RLE of each object is its pixels of the instance mask
        row = max(rows, key=lambda r: len(r["objects"]))
        image_id = next(i["id"] for i in gt.dataset["images"] if i["obs_id"] == row["obs_id"])
        mask = decode_channel(row["instances"])
        for k, ann in enumerate(gt.loadAnns(gt.getAnnIds(imgIds=[image_id]))):
            assert np.array_equal(gt.annToMask(ann), (mask == k + 1).astype(np.uint8))
            assert ann["area"] == row["objects"][k]["visible_pixels"]
        for kind in ("bbox", "segm"):
            results = [{**a, "score": 1.0} for a in gt.dataset["annotations"]]
            evaluation = COCOeval(gt, gt.loadRes(results), kind)
            evaluation.evaluate()
            evaluation.accumulate()
            evaluation.summarize()
            assert evaluation.stats[0] == pytest.approx(1.0)  # AP@[.5:.95]


def test_import_coco_of_the_export_gives_the_boxes_back(
    coco: Path, channels_dataset: Path, tmp_path: Path
) -> None:
    done = import_labels(
        "coco",
        coco / "annotations" / "instances_val.json",
        coco / "images" / "val",
        tmp_path / "real",
        room="imported",
        room_type="bathroom",
    )
    assert done.boxes > 0
    back = _boxes(tmp_path / "real", "test")
    back = Counter({(stem.split("__", 1)[1], c, b): n for (stem, c, b), n in back.items()})
    assert back == _boxes(channels_dataset, "val")
    # a real dataset has no masks: --masks says so in one line and writes nothing
    out = tmp_path / "masks"
    run = run_cli("sgdata", "export", "coco", tmp_path / "real", "-o", out, "--masks")
    assert run.returncode != 0 and "real" in run.stderr and "no instance masks" in run.stderr
    assert len(run.stderr.strip().splitlines()) == 1 and not out.exists()


def test_yolo_labels_are_the_stored_boxes(channels_dataset: Path, tmp_path: Path) -> None:
    out = tmp_path / "yolo"
    done = export_yolo(channels_dataset, out, split="train")
    assert done.images > 0
    text = (out / "data.yaml").read_text()
    assert "train: images/train" in text and "val:" not in text
    names = dict(line.strip().split(": ", 1) for line in text.split("names:\n")[1].splitlines())
    ds = Dataset.open(channels_dataset)
    assert [json.loads(v) for v in names.values()] == ds.class_names
    for row in ds.observations("train").to_pylist():
        stem = row["obs_id"].replace("/", "__")
        assert (out / "images" / "train" / f"{stem}.png").is_file()
        lines = (out / "labels" / "train" / f"{stem}.txt").read_text().splitlines()
        w, h = row["camera"]["width"], row["camera"]["height"]
        for line, obj in zip(lines, row["objects"], strict=True):
            c, cx, cy, bw, bh = line.split()
            box = [(float(cx) - float(bw) / 2) * w, (float(cy) - float(bh) / 2) * h]
            box += [box[0] + float(bw) * w, box[1] + float(bh) * h]
            assert int(c) == obj["class_id"]
            assert np.allclose(box, obj["box2d"], atol=1e-3)


def test_bad_exports_are_one_line_and_write_nothing(
    channels_dataset: Path, mini_dataset: Path, tmp_path: Path
) -> None:
    def run(*args: str) -> Done:
        return run_cli("sgdata", "export", *args)

    out = tmp_path / "out"
    done = run("coco", str(mini_dataset), "-o", str(out), "--masks")  # mini: no masks
    assert done.returncode != 0 and "no instance masks" in done.stderr and not out.exists()
    done = run("pascal", str(channels_dataset), "-o", str(out))
    assert done.returncode != 0 and "coco, labelstudio, yolo" in done.stderr
    assert not out.exists()
    out.mkdir()
    (out / "keep.txt").write_text("mine\n")
    done = run("yolo", str(channels_dataset), "-o", str(out))
    assert done.returncode != 0 and "not empty" in done.stderr
    assert [p.name for p in out.iterdir()] == ["keep.txt"]
    for result in (done,):
        assert len(result.stderr.strip().splitlines()) == 1
    done = run("yolo", str(channels_dataset), "-o", str(out), "--force", "--split", "val")
    assert done.returncode == 0, done.stderr
    assert sorted(p.name for p in out.iterdir()) == ["data.yaml", "images", "labels"]
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no stage left
