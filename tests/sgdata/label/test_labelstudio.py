"""Label Studio JSON: rectangles and relations in, and a dataset out and back in unchanged."""

from __future__ import annotations

import json
from pathlib import Path

import pyarrow.parquet as pq
import pytest

from sgdata.label.annotations import AnnotationFormatError
from sgdata.label.export import export_dataset
from sgdata.label.importers import UnknownLabelsError, import_labels
from sgdata.label.labelstudio import export_labelstudio
from sgdata.label.models import PhotoLabels
from sgdata.label.store import LabelStore
from sgdata.validate import validate_dataset

from ...cli_runner import run_cli
from .conftest import make_photo

ON, IN, PROXIMITY, DISJOINT = range(4)


def _rect(rid: str, label: str, x: float, y: float, w: float, h: float) -> dict:
    """A rectanglelabels result on a 320x240 photo; x, y, w, h in pixels."""
    return {
        "id": rid,
        "type": "rectanglelabels",
        "from_name": "label",
        "to_name": "image",
        "original_width": 320,
        "original_height": 240,
        "value": {
            "x": 100 * x / 320,
            "y": 100 * y / 240,
            "width": 100 * w / 320,
            "height": 100 * h / 240,
            "rotation": 0,
            "rectanglelabels": [label],
        },
    }


def _rel(src: str, dst: str, direction: str, *labels: str) -> dict:
    return {
        "type": "relation",
        "from_id": src,
        "to_id": dst,
        "direction": direction,
        "labels": list(labels),
    }


def _task(results: list[dict], image: str = "/data/upload/3/0a1b2c3d-a.png") -> list[dict]:
    return [
        {
            "id": 1,
            "data": {"image": image},
            "annotations": [
                {"result": [], "was_cancelled": True},
                {"result": results, "was_cancelled": False},
            ],
        }
    ]


RESULTS = [
    _rect("tbl", "DiningTable", 40, 100, 240, 130),
    _rect("mug", "coffee mug", 120, 60, 50, 45),
    _rect("bwl", "Bowl", 200, 110, 60, 40),
    _rect("apl", "Apple", 215, 120, 20, 20),
    _rect("chr", "Chair", 0, 120, 40, 110),
    _rect("pln", "HousePlant", 280, 10, 30, 60),
    _rel("mug", "tbl", "right", "on"),  # mug on table
    _rel("bwl", "apl", "left", "In"),  # left: to -> from, apple in bowl
    _rel("chr", "tbl", "bi", "next to"),  # mapped onto proximity
    _rel("pln", "bwl", "bi"),  # unlabeled bi: proximity
]


def test_relations_in_all_three_directions(photos_dir: Path, tmp_path: Path) -> None:
    path = tmp_path / "kitchen_ls.json"
    path.write_text(json.dumps(_task(RESULTS)))
    mapping = tmp_path / "map.toml"
    mapping.write_text('"coffee mug" = "Mug"\n\n[relations]\n"next to" = "proximity"\n')
    out = tmp_path / "ds"
    done = import_labels("labelstudio", path, photos_dir, out, class_map=mapping)
    assert (done.photos, done.boxes, done.relations) == (1, 6, 4)
    assert done.notes == []
    labels = LabelStore(out).load("a.png")  # the upload prefix 0a1b2c3d- is dropped
    assert {(r.src, r.dst, r.type) for r in labels.relations} == {
        (1, 0, "on"),
        (3, 2, "in"),
        (0, 4, "proximity"),
        (2, 5, "proximity"),
    }
    assert validate_dataset(out).ok
    row = pq.read_table(out / "observations/test/kitchen_ls.parquet").to_pylist()[0]
    assert row["objects"][1]["box2d"] == [120, 60, 170, 105]
    edges = {(r["src"], r["dst"], r["type"]) for r in row["relations"]}
    assert {(1, 0, ON), (3, 2, IN), (0, 4, PROXIMITY), (4, 0, PROXIMITY)} <= edges
    assert (0, 1, DISJOINT) not in edges and (1, 2, DISJOINT) in edges


def test_unknown_classes_and_relations_in_one_error(photos_dir: Path, tmp_path: Path) -> None:
    path = tmp_path / "kitchen_ls.json"
    path.write_text(json.dumps(_task(RESULTS)))
    with pytest.raises(UnknownLabelsError) as info:
        import_labels("labelstudio", path, photos_dir, tmp_path / "ds")
    message = str(info.value)
    assert "\n" not in message and "kitchen_ls.json" in message
    assert "class(es) 'coffee mug' and relation label(s) 'next to'" in message
    assert "[relations]" in message


@pytest.mark.parametrize(
    ("results", "expected"),
    [
        ([_rel("a", "b", "right", "on")], r"result\[0\]\.from_id: expected the id of a rectangle"),
        (
            [
                _rect("a", "Mug", 1, 1, 5, 5),
                _rect("b", "Cup", 9, 9, 5, 5),
                _rel("a", "b", "up", "on"),
            ],
            r"result\[2\]\.direction: expected one of right, left, bi",
        ),
        (
            [
                _rect("a", "Mug", 1, 1, 5, 5),
                _rect("b", "Cup", 9, 9, 5, 5),
                _rel("a", "b", "bi", "on"),
            ],
            "a 'bi' relation typed 'on'",
        ),
        ([{**_rect("a", "Mug", 1, 1, 5, 5), "original_width": None}], "original_width"),
        ([{**_rect("a", "Mug", 1, 1, 5, 5), "value": {"x": 1}}], r"value\.y: expected a number"),
        (  # an integer of 400 digits is valid JSON, but no float holds it
            [{**_rect("a", "Mug", 1, 1, 5, 5), "value": {"x": 10**400, "y": 1}}],
            r"value\.x: expected a number, not 1000",
        ),
        ([{**_rect("a", "Mug", 1, 1, 5, 5), "original_width": 640}], "is 320x240"),
    ],
)
def test_malformed_labelstudio(
    photos_dir: Path, tmp_path: Path, results: list, expected: str
) -> None:
    path = tmp_path / "kitchen_ls.json"
    path.write_text(json.dumps(_task(results)))
    with pytest.raises(AnnotationFormatError, match=expected) as info:
        import_labels("labelstudio", path, photos_dir, tmp_path / "ds")
    assert "kitchen_ls.json" in str(info.value) and "\n" not in str(info.value)


@pytest.mark.parametrize(
    ("value", "expected"),
    [
        ("9" * 5000, "a number too long to read"),  # Python converts at most 4,300 digits
        ("[" * 100_000 + "]" * 100_000, "nested too deeply"),
    ],
    ids=["5000-digits", "nested"],
)
def test_valid_json_python_cannot_hold_is_one_line(
    photos_dir: Path, tmp_path: Path, value: str, expected: str
) -> None:
    path = tmp_path / "kitchen_ls.json"
    text = json.dumps(_task([_rect("a", "Mug", 1, 1, 5, 5)]))
    path.write_text(text.replace('"original_width": 320', f'"original_width": {value}', 1))
    with pytest.raises(AnnotationFormatError, match=expected) as info:
        import_labels("labelstudio", path, photos_dir, tmp_path / "ds")
    assert "kitchen_ls.json" in str(info.value) and "\n" not in str(info.value)


def _labeled_dataset(tmp_path: Path) -> Path:
    """A label export: unposed PNG/JPEG photos with on / in / proximity, and posed photos."""
    photos, out = tmp_path / "photos", tmp_path / "ds"
    photos.mkdir()
    store = LabelStore(out)
    make_photo(photos / "a.png", seed=1)
    make_photo(photos / "c.jpg", width=200, height=100, seed=3)
    objects = [
        {"id": 0, "class_name": "DiningTable", "box": [40, 100, 280, 230]},
        {"id": 3, "class_name": "Mug", "box": [121, 61, 170, 105]},
        {"id": 5, "class_name": "Bowl", "box": [200, 110, 260, 150]},
        {"id": 7, "class_name": "Apple", "box": [215, 120, 236, 139]},
        {"id": 9, "class_name": "Chair", "box": [0, 120, 40, 239]},
    ]
    relations = [
        {"src": 3, "dst": 0, "type": "on"},
        {"src": 7, "dst": 5, "type": "in"},
        {"src": 0, "dst": 9, "type": "proximity"},
        {"src": 3, "dst": 5, "type": "disjoint"},
    ]
    base = {"room_id": "kitchen_real", "room_type": "kitchen"}
    store.save(
        "a.png", PhotoLabels.model_validate({**base, "objects": objects, "relations": relations})
    )
    chair = {"id": 9, "class_name": "Chair", "box": [0, 20, 40, 99]}
    store.save("c.jpg", PhotoLabels.model_validate({**base, "objects": [chair]}))
    for heading in range(4):
        name = f"p{heading}.png"
        make_photo(photos / name, width=97, height=61, seed=heading)
        pose = {"layout": 1, "i": 2, "j": -3, "heading": heading}
        box = {"id": 2, "class_name": "Sofa", "box": [heading, 3, 97, 61]}
        store.save(
            name,
            PhotoLabels.model_validate(
                {"room_id": "den", "room_type": "living_room", "pose": pose, "objects": [box]}
            ),
        )
    export_dataset(photos, out)
    return out


def _content(root: Path) -> dict:
    """Per image (its bytes): room, type, pose, objects and relations."""
    out = {}
    for shard in sorted((root / "observations/test").glob("*.parquet")):
        for r in pq.read_table(shard).to_pylist():
            key = (
                r["image"]["bytes"],  # format 2.x: the Hugging Face Image struct
                r["room_id"],
                r["room_type"],
                r["layout"],
                r["grid_i"],
                r["grid_j"],
                r["heading"],
                r["camera"]["width"],
                r["camera"]["height"],
            )
            objects = [(o["instance"], o["class_name"], tuple(o["box2d"])) for o in r["objects"]]
            relations = sorted((x["src"], x["dst"], x["type"]) for x in r["relations"])
            out[key] = (objects, relations)
    return out


def test_round_trip_keeps_boxes_and_relations(tmp_path: Path) -> None:
    first = _labeled_dataset(tmp_path)
    summary = export_labelstudio(first, tmp_path / "ls.json")
    assert (summary.tasks, summary.boxes, summary.relations) == (6, 10, 3)
    tasks = json.loads((tmp_path / "ls.json").read_text())
    posed = [t for t in tasks if t["data"]["room_id"] == "den"]
    assert posed[0]["data"]["image"] == "den__1__2__-3__0.png"
    assert (tmp_path / "ls_images" / "den__1__2__-3__0.png").is_file()
    second = tmp_path / "again"
    done = import_labels("labelstudio", tmp_path / "ls.json", tmp_path / "ls_images", second)
    assert done.export.triplets == 0 and done.export.rooms == 2
    assert validate_dataset(second).ok
    assert _content(second) == _content(first)
    obs = set(pq.read_table(second / "observations/test/den.parquet")["obs_id"].to_pylist())
    assert "den/1/2/-3/0" in obs  # posed photos keep their ids


def test_cli_export_then_import(tmp_path: Path) -> None:
    first = _labeled_dataset(tmp_path)
    out = tmp_path / "ls.json"
    exported = run_cli(
        "sgdata", "export", "labelstudio", first, "-o", out, "--images", tmp_path / "img"
    )
    assert exported.returncode == 0, exported.stderr
    assert "wrote 6 task(s), 10 box(es) and 3 relation(s)" in exported.stdout
    imported = run_cli(
        "sgdata", "import", "labelstudio", out, "--images", tmp_path / "img",
        "--out", tmp_path / "again",
    )  # fmt: skip
    assert imported.returncode == 0, imported.stderr
    assert "imported 10 box(es) and 3 relation(s) of 6 photo(s)" in imported.stdout
    assert _content(tmp_path / "again") == _content(first)
    bad = run_cli("sgdata", "export", "bogus", first, "-o", out)
    assert bad.returncode == 2 and "expected one of coco, labelstudio, yolo" in bad.stderr


ODD_NAMES = ["my cup #1.png", "what?.jpg", "100% tea.png", "tasse à café.jpg", "a b%20c.png"]


def test_round_trip_is_byte_exact_for_odd_names(tmp_path: Path) -> None:
    photos, first = tmp_path / "photos", tmp_path / "ds"
    photos.mkdir()
    store = LabelStore(first)
    for k, name in enumerate(ODD_NAMES):
        make_photo(photos / name, seed=k)
        objects = [{"id": 10 + k, "class_name": "Cup", "box": [10 + k, 20, 90, 100]}]
        labels = {"room_id": "kitchen_real", "room_type": "kitchen", "objects": objects}
        store.save(name, PhotoLabels.model_validate(labels))
    export_dataset(photos, first)
    previous = None
    source = first
    for turn in range(2):  # dataset -> Label Studio -> dataset, twice
        ls = tmp_path / f"ls{turn}.json"
        export_labelstudio(source, ls, images_dir=tmp_path / f"img{turn}")
        refs = [t["data"]["image"] for t in json.loads(ls.read_text())]
        assert "kitchen_real__my%20cup%20%231.png" in refs and "kitchen_real__what%3F.jpg" in refs
        if previous is not None:
            assert ls.read_bytes() == previous  # same tasks, same image names, same ids
        previous = ls.read_bytes()
        source = tmp_path / f"again{turn}"
        import_labels("labelstudio", ls, tmp_path / f"img{turn}", source)
        assert validate_dataset(source).ok
        assert _content(source) == _content(first)
        obs = pq.read_table(source / "observations/test/kitchen_real.parquet")["obs_id"]
        assert sorted(obs.to_pylist()) == sorted(
            f"kitchen_real/{Path(n).stem}" for n in ODD_NAMES
        )  # no second room prefix: kitchen_real/kitchen_real__...
