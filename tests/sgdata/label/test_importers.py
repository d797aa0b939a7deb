"""``sgdata import coco|labelme``: boxes of foreign files become labels and a real dataset."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pyarrow.parquet as pq
import pytest

from sgdata.errors import ConfigError
from sgdata.label.annotations import AnnotationFormatError
from sgdata.label.importers import UnknownLabelsError, import_labels, load_import_map
from sgdata.label.store import LabelStore
from sgdata.validate import validate_dataset


def _coco(**changes) -> dict:
    coco = {
        "images": [
            {"id": 7, "file_name": "train/a.png", "width": 320, "height": 240},
            {"id": 9, "file_name": "c.jpg", "width": 200, "height": 100},
        ],
        "categories": [
            {"id": 1, "name": "dining table"},
            {"id": 2, "name": "Mug"},
            {"id": 3, "name": "coffee mug"},
        ],
        "annotations": [
            {"id": 100, "image_id": 7, "category_id": 1, "bbox": [40, 100, 240, 130]},
            {"id": 101, "image_id": 7, "category_id": 2, "bbox": [120.4, 59.6, 50, 45.2]},
            {"id": 102, "image_id": 9, "category_id": 3, "bbox": [10, 10, 140, 80]},
        ],
    }
    coco.update(changes)
    return coco


def _write(path: Path, data) -> Path:
    path.write_text(json.dumps(data))
    return path


def _rows(out: Path, room: str) -> dict[str, dict]:
    table = pq.read_table(out / f"observations/test/{room}.parquet")
    return {r["obs_id"]: r for r in table.to_pylist()}


def test_coco_becomes_a_valid_real_dataset(photos_dir: Path, tmp_path: Path) -> None:
    classes = tmp_path / "map.toml"
    classes.write_text('"coffee mug" = "Cup"\n')
    coco = _write(tmp_path / "kitchen_scan.json", _coco())
    out = tmp_path / "ds"
    done = import_labels("coco", coco, photos_dir, out, class_map=classes)
    assert (done.photos, done.boxes, done.relations) == (2, 3, 0)
    assert done.export.observations == 2 and done.export.rooms == 1
    assert validate_dataset(out).ok
    rows = _rows(out, "kitchen_scan")  # room id from the file name, type from its prefix
    a = rows["kitchen_scan/a"]
    assert a["room_type"] == "kitchen" and a["domain"] == "real"
    assert [(o["class_name"], o["box2d"]) for o in a["objects"]] == [
        ("DiningTable", [40, 100, 280, 230]),  # "dining table" matches the catalog loosely
        ("Mug", [120, 60, 170, 105]),  # float pixels rounded
    ]
    assert [o["class_name"] for o in rows["kitchen_scan/c"]["objects"]] == ["Cup"]
    # the labels are in the store, as `sgdata label` saves them, and re-importing replaces them
    assert LabelStore(out).load("a.png").objects[1].box == [120, 60, 170, 105]
    again = import_labels("coco", coco, photos_dir, out, class_map=classes, room="kitchen_2")
    assert again.export.rooms == 1 and LabelStore(out).load("a.png").revision == 2


def test_labelme_file_and_folder(photos_dir: Path, tmp_path: Path) -> None:
    folder = tmp_path / "labelme"
    folder.mkdir()
    shapes = [
        {"label": "Chair", "shape_type": "rectangle", "points": [[150, 90], [10, 10]]},
        {"label": "Sofa", "shape_type": "polygon", "points": [[1, 1], [5, 1], [5, 5]]},
    ]
    page = {"imagePath": "../photos/c.jpg", "imageWidth": 200, "imageHeight": 100}
    _write(folder / "c.json", {**page, "shapes": shapes})
    a = {"imagePath": "a.png", "imageWidth": 320, "imageHeight": 240, "shapes": []}
    _write(folder / "a.json", a)
    out = tmp_path / "ds"
    done = import_labels("labelme", folder, photos_dir, out, room="den", room_type="living_room")
    assert (done.photos, done.boxes) == (2, 1)
    assert done.notes == ["skipped 1 LabelMe shape(s) that are not rectangles"]
    assert validate_dataset(out).ok
    rows = _rows(out, "den")
    assert rows["den/c"]["objects"][0]["box2d"] == [10, 10, 150, 90]
    assert rows["den/a"]["objects"] == [] and rows["den/a"]["room_type"] == "living_room"
    one = import_labels(
        "labelme",
        folder / "c.json",
        photos_dir,
        tmp_path / "one",
        room="den",
        room_type="living_room",
    )
    assert one.photos == 1


def test_unknown_names_are_listed_together(photos_dir: Path, tmp_path: Path) -> None:
    coco = _coco()
    coco["categories"] += [{"id": 4, "name": "gizmo"}, {"id": 5, "name": "doohickey"}]
    coco["annotations"] += [
        {"id": 103, "image_id": 7, "category_id": 4, "bbox": [1, 1, 5, 5]},
        {"id": 104, "image_id": 9, "category_id": 5, "bbox": [1, 1, 5, 5]},
    ]
    path = _write(tmp_path / "kitchen.json", coco)
    with pytest.raises(UnknownLabelsError) as info:
        import_labels("coco", path, photos_dir, tmp_path / "ds")
    message = str(info.value)
    assert "\n" not in message
    assert "class(es) 'coffee mug', 'doohickey', 'gizmo'" in message and "--classes" in message
    assert not (tmp_path / "ds" / "labels").exists() or not list(
        (tmp_path / "ds" / "labels").iterdir()
    )  # nothing written


@pytest.mark.parametrize(
    ("change", "expected"),
    [
        ({"annotations": [{"id": 1, "image_id": 7, "category_id": 1}]}, r"annotations\[0\]\.bbox"),
        ({"annotations": [{"image_id": 7, "category_id": 1, "bbox": [1, 2]}]}, "bbox"),
        ({"annotations": [{"image_id": 3, "category_id": 1, "bbox": [1, 1, 2, 2]}]}, "image_id"),
        ({"images": [{"id": 7, "file_name": 5}]}, r"images\[0\]\.file_name"),
        ({"images": "nope"}, "top level.images"),
        (
            {
                "images": [{"id": 7, "file_name": "a.png", "width": 640, "height": 480}],
                "annotations": [],
            },
            "is 320x240",
        ),
        ({"images": [{"id": 7, "file_name": "zzz.png"}], "annotations": []}, "not in .*zzz.png"),
    ],
)
def test_malformed_coco_names_file_and_field(
    photos_dir: Path, tmp_path: Path, change: dict, expected: str
) -> None:
    path = _write(tmp_path / "kitchen.json", _coco(**change))
    with pytest.raises(AnnotationFormatError, match=expected) as info:
        import_labels("coco", path, photos_dir, tmp_path / "ds")
    assert "kitchen.json" in str(info.value) and "\n" not in str(info.value)


@pytest.mark.parametrize("value", [2**63, -(10**400)], ids=["2^63", "400-digits"])
def test_an_id_past_int64_is_one_line(photos_dir: Path, tmp_path: Path, value: int) -> None:
    coco = _coco()
    coco["images"][0]["id"] = coco["annotations"][0]["image_id"] = value
    path = _write(tmp_path / "kitchen.json", coco)
    with pytest.raises(AnnotationFormatError, match=r"images\[0\]\.id: expected an integer wi"):
        import_labels("coco", path, photos_dir, tmp_path / "ds")
    assert not (tmp_path / "ds").exists()


def test_bad_files_and_maps(photos_dir: Path, tmp_path: Path) -> None:
    (tmp_path / "kitchen.json").write_text("{not json")
    with pytest.raises(AnnotationFormatError, match=r"kitchen.json: not JSON \(line 1"):
        import_labels("coco", tmp_path / "kitchen.json", photos_dir, tmp_path / "ds")
    with pytest.raises(ConfigError, match="expected one of coco, labelme, labelstudio"):
        import_labels("yolo", tmp_path / "kitchen.json", photos_dir, tmp_path / "ds")
    bad = tmp_path / "map.toml"
    bad.write_text('mug = "Mug"\n[relations]\nnear = "beside"\n')
    with pytest.raises(ConfigError, match="'near' maps to 'beside'"):
        load_import_map(bad)
    bad.write_text('mug = "Unicorn"\n[relations]\nnear = "proximity"\n')
    with pytest.raises(ConfigError, match="'mug' = 'Unicorn'"):
        load_import_map(bad)
    path = _write(tmp_path / "attic.json", _coco(annotations=[]))
    with pytest.raises(ConfigError, match="room 'attic': no room type; give --room-type"):
        import_labels("coco", path, photos_dir, tmp_path / "ds")


def test_cli_import_errors_are_one_line(photos_dir: Path, tmp_path: Path) -> None:
    coco = _coco()
    coco["categories"][0]["name"] = "gizmo"
    path = _write(tmp_path / "kitchen.json", coco)
    result = subprocess.run(
        [
            sys.executable,
            "-m",
            "sgdata_cli.sgdata_app",
            "import",
            "coco",
            str(path),
            "--images",
            str(photos_dir),
            "--out",
            str(tmp_path / "ds"),
        ],
        capture_output=True,
        text=True,
        timeout=120,
        env={**os.environ, "COLUMNS": "200"},
    )
    assert result.returncode == 2, result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and "'gizmo'" in lines[0] and "'coffee mug'" in lines[0]
    assert "Traceback" not in result.stderr


def test_a_file_with_no_photos_labels_is_refused_and_writes_nothing(
    photos_dir: Path, tmp_path: Path
) -> None:
    empty = tmp_path / "kitchen.json"
    empty.write_text("[]", encoding="utf-8")  # a Label Studio export of no task
    with pytest.raises(ConfigError, match="holds no photo's labels; nothing to import"):
        import_labels("labelstudio", empty, photos_dir, tmp_path / "out")
    assert not (tmp_path / "out").exists()
