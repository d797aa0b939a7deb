"""``sgdata label --export``: saved labels become real observation rows that validate."""

from __future__ import annotations

from pathlib import Path

import pyarrow.parquet as pq
import pytest
from fastapi.testclient import TestClient

from sgdata.dataset import Dataset
from sgdata.errors import ConfigError, DatasetError
from sgdata.label.export import export_dataset
from sgdata.label.models import PhotoLabels
from sgdata.label.server import create_app
from sgdata.label.store import LabelStore
from sgdata.validate import validate_dataset

from ...cli_runner import run_cli
from .conftest import make_photo


def _labels(**fields) -> PhotoLabels:
    return PhotoLabels.model_validate({"room_id": "kitchen_real", "room_type": "kitchen", **fields})


def test_export_writes_real_rows_that_validate(photos_dir: Path, tmp_path: Path) -> None:
    out = tmp_path / "ds"
    store = LabelStore(out)
    objects = [
        {"id": 0, "class_name": "DiningTable", "box": [40, 100, 280, 230]},
        {"id": 1, "class_name": "Mug", "box": [120, 60, 170, 105]},
        {"id": 2, "class_name": "Apple", "box": [200, 20, 230, 50]},
    ]
    relations = [{"src": 1, "dst": 0, "type": "on"}]
    store.save("a.png", _labels(objects=objects, relations=relations))
    store.save(
        "c.jpg", _labels(objects=[{"id": 4, "class_name": "Chair", "box": [10, 10, 150, 90]}])
    )
    store.save("b.png", PhotoLabels())  # no room id: left out

    summary = export_dataset(photos_dir, out)
    assert (summary.rooms, summary.observations, summary.triplets) == (1, 2, 0)
    assert summary.unlabeled == ["b.png"]
    report = validate_dataset(out)
    assert report.ok, report.problems

    table = pq.read_table(out / "observations/test/kitchen_real.parquet")
    rows = {r["obs_id"]: r for r in table.to_pylist()}
    assert set(rows) == {"kitchen_real/a", "kitchen_real/c"}
    a = rows["kitchen_real/a"]
    assert a["domain"] == "real" and a["image_format"] == "png"
    assert a["image"]["bytes"] == (photos_dir / "a.png").read_bytes()  # the photo's own bytes
    assert a["grid_i"] is None and a["camera"]["width"] == 320
    assert [o["class_name"] for o in a["objects"]] == ["DiningTable", "Mug", "Apple"]
    assert all(o["box3d_min"] is None and o["obb"] is None for o in a["objects"])
    assert a["objects"][1]["box2d"] == [120, 60, 170, 105]
    edges = {(r["src"], r["dst"], r["type"]) for r in a["relations"]}
    # 1 on 0 as accepted; every other pair disjoint (3) both ways, as the generator stores it
    assert edges == {(1, 0, 0), (0, 2, 3), (2, 0, 3), (1, 2, 3), (2, 1, 3)}
    c = rows["kitchen_real/c"]
    assert c["image_format"] == "jpeg" and c["camera"]["height"] == 100
    ds = Dataset.open(out)
    assert ds.splits == ("test",) or list(ds.splits) == ["test"]


def test_export_with_nothing_labeled_names_the_waiting_photos_and_writes_nothing(
    photos_dir: Path, tmp_path: Path
) -> None:
    out = tmp_path / "ds"
    LabelStore(out).save("b.png", PhotoLabels())  # labels, but no room id
    with pytest.raises(
        ConfigError, match=r"nothing to export: .*\(3 waiting: b.png, a.png, c.jpg\)"
    ):
        export_dataset(photos_dir, out)
    assert not (out / "dataset.json").exists()
    done = run_cli("sgdata", "label", str(photos_dir), "--out", str(out), "--export")
    assert done.returncode != 0 and "nothing to export" in done.stderr


def test_export_makes_triplets_from_full_poses(tmp_path: Path) -> None:
    photos = tmp_path / "photos"
    photos.mkdir()
    store = LabelStore(tmp_path / "ds")
    objects = [{"id": 0, "class_name": "Chair", "box": [10, 10, 50, 60]}]
    k = 0
    # two layouts x a row of 5 cells x 4 headings: every tier can be filled
    for layout in (0, 1):
        for i in range(5):
            for heading in range(4):
                name = f"p{k:03d}.png"
                make_photo(photos / name, width=64, height=64, seed=k)
                pose = {"layout": layout, "i": i, "j": 0, "heading": heading}
                store.save(name, _labels(objects=objects, pose=pose))
                k += 1
    summary = export_dataset(photos, tmp_path / "ds")
    assert summary.observations == 40 and summary.triplets > 0
    report = validate_dataset(tmp_path / "ds")
    assert report.ok, report.problems
    tri = pq.read_table(tmp_path / "ds/triplets/test.parquet")
    assert tri.num_rows == summary.triplets
    assert "kitchen_real/0/0/0/0" in set(
        pq.read_table(tmp_path / "ds/observations/test/kitchen_real.parquet")["obs_id"].to_pylist()
    )


def test_export_refuses_unknown_classes_and_foreign_datasets(
    photos_dir: Path, tmp_path: Path
) -> None:
    out = tmp_path / "ds"
    store = LabelStore(out)
    store.save("a.png", _labels(objects=[{"id": 0, "class_name": "", "box": [1, 1, 5, 5]}]))
    with pytest.raises(DatasetError, match="object 0 has no class"):
        export_dataset(photos_dir, out)
    (out / "dataset.json").write_text('{"config": {}}')
    store.save("a.png", _labels(revision=1))
    with pytest.raises(ConfigError, match="not a `sgdata label` export"):
        export_dataset(photos_dir, out)


def test_validate_wants_one_class_per_instance_in_a_room(photos_dir: Path, tmp_path: Path) -> None:
    out = tmp_path / "ds"
    store = LabelStore(out)
    store.save("a.png", _labels(objects=[{"id": 3, "class_name": "Cup", "box": [1, 1, 9, 9]}]))
    store.save("b.png", _labels(objects=[{"id": 3, "class_name": "Mug", "box": [1, 1, 9, 9]}]))
    export_dataset(photos_dir, out)
    report = validate_dataset(out)
    (problem,) = report.problems
    assert problem.check == "objects.instance" and problem.field == "objects[0].class_name"
    assert "instance 3 is 'Mug' here but 'Cup' in kitchen_real/a" in problem.message
    # another room may use the id for another class
    store.save(
        "b.png",
        _labels(
            revision=1, room_id="den", objects=[{"id": 3, "class_name": "Mug", "box": [1, 1, 9, 9]}]
        ),
    )
    export_dataset(photos_dir, out)
    assert validate_dataset(out).ok


def test_undecided_proposals_are_named_by_photo(photos_dir: Path, tmp_path: Path) -> None:
    out = tmp_path / "ds"
    store = LabelStore(out)
    table = {"id": 0, "class_name": "DiningTable", "box": [40, 100, 280, 230]}
    mug = {"id": 1, "class_name": "Mug", "box": [120, 60, 170, 105]}
    store.save("a.png", _labels(objects=[table, mug]))
    store.save("c.jpg", _labels(objects=[{"id": 2, "class_name": "Chair", "box": [1, 1, 9, 9]}]))
    assert export_dataset(photos_dir, out).pending == {"a.png": 1}
    done = run_cli("sgdata", "label", photos_dir, "--out", out, "--export", columns=300)
    assert done.returncode == 0, done.stderr
    assert "1 undecided proposal(s) stored as disjoint: a.png (1)" in done.stdout


def test_a_class_map_given_to_label_is_used_by_export(photos_dir: Path, tmp_path: Path) -> None:
    out, names = tmp_path / "ds", tmp_path / "names.toml"
    names.write_text('Saucer = "Plate"\n')
    client = TestClient(create_app(photos_dir, out, class_map=names), base_url="http://127.0.0.1")
    body = {"room_id": "k1", "room_type": "kitchen"}
    body["objects"] = [{"id": 0, "class_name": "Saucer", "box": [1, 1, 9, 9]}]
    assert client.put("/api/labels/a.png", json=body).status_code == 200
    names.unlink()  # the export is not given --classes, and the file is gone
    export_dataset(photos_dir, out)
    (row,) = pq.read_table(out / "observations/test/k1.parquet").to_pylist()
    assert row["objects"][0]["class_name"] == "Plate"
    # and a later `sgdata label` without --classes still offers the name
    again = TestClient(create_app(photos_dir, out), base_url="http://127.0.0.1")
    assert again.get("/api/classes").json()["mapped"] == {"Saucer": "Plate"}
