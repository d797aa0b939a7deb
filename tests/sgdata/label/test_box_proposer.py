"""``sgdata label --detector RUN``: a run names the function that opens it; what its detector
returns is checked, kept above the score floor, clipped to the photo and shown as proposed."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from fastapi.testclient import TestClient

from sgdata.errors import ConfigError
from sgdata.label.box_proposer import ProposedBox, open_proposer
from sgdata.label.export import export_dataset
from sgdata.label.server import create_app
from tests.cli_runner import run_cli

from .file_proposer import file_run

KNOWN = ("Mug", "Chair", "Table")
PIXELS = np.zeros((240, 320, 3), np.uint8)


@pytest.mark.parametrize(
    ("setup", "said"),
    [
        (lambda run: None, "no detector.json; expected a detector run"),
        (lambda run: (run / "detector.json").write_text("{"), "detector.json: not readable JSON"),
        (  # valid JSON nested deeper than Python's parser recurses
            lambda run: (run / "detector.json").write_text("[" * 100_000 + "]" * 100_000),
            "detector.json: not readable JSON",
        ),
        (
            lambda run: (run / "detector.json").write_text('{"classes": []}'),
            "detector.json: proposer: expected an import path 'package.module:function'",
        ),
        (
            lambda run: file_run(run, [], "tests.sgdata.label.nowhere:open"),
            "proposer 'tests.sgdata.label.nowhere:open' failed: ModuleNotFoundError",
        ),
        (
            lambda run: file_run(run, [], "tests.sgdata.label.file_proposer:nothing"),
            "failed: AttributeError",
        ),
        (lambda run: file_run(run, "fail to open"), "failed: FileNotFoundError: weights.pt"),
    ],
)
def test_a_run_that_does_not_open_is_one_line_naming_it(tmp_path: Path, setup, said) -> None:  # noqa: ANN001
    run = tmp_path / "run"
    run.mkdir()
    setup(run)
    with pytest.raises(ConfigError) as caught:
        open_proposer(run, min_score=0.5, known=KNOWN)
    assert said in str(caught.value) and str(run) in str(caught.value)
    assert "\n" not in str(caught.value)


def test_boxes_are_checked_kept_above_the_floor_clipped_and_best_first(tmp_path: Path) -> None:
    rows = [
        ["Mug", [10.4, 20.6, 50.2, 60.0], 0.6],
        ["Chair", [-30, -5, 100, 300], 0.9],  # reaches outside the 320 x 240 photo: clipped
        ["Table", [0, 0, 10, 10], 0.49],  # under the floor
        ["Sofa", [0, 0, 10, 10], 0.99],  # a class the labeler does not know
        ["Mug", [400, 10, 500, 40], 0.8],  # wholly outside: nothing left of it
        ["Mug", [0, 0, 10, 10], float("nan")],
    ]
    proposer = open_proposer(file_run(tmp_path / "run", rows), min_score=0.5, known=KNOWN)
    assert proposer(PIXELS) == [
        ProposedBox("Chair", (0, 0, 100, 240), 0.9),
        ProposedBox("Mug", (10, 21, 50, 60), 0.6),
    ]
    assert open_proposer(tmp_path / "run", min_score=0.0, known=KNOWN)(PIXELS)[-1].score == 0.49
    with pytest.raises(ConfigError, match=r"--min-score 1.5: expected a score in \[0, 1\]"):
        open_proposer(tmp_path / "run", min_score=1.5, known=KNOWN)
    wrong = open_proposer(file_run(tmp_path / "wrong", [{"box": [1, 2, 3, 4]}]), min_score=0,
                          known=KNOWN)  # fmt: skip
    with pytest.raises(ConfigError, match="result 0 is dict; expected a sgdata.label.box_prop"):
        wrong(PIXELS)
    # a corner at NaN or infinity is a slip, left out; a corner that is not a number, a class
    # name that is not a string, or a box of three values is a broken detector, refused
    slips = [["Mug", [float("nan"), 0, 10, 10], 0.9], ["Mug", [0, 0, float("inf"), 10], 0.9],
             ["Mug", [1, 1, 9, 9], 0.7]]  # fmt: skip
    assert open_proposer(file_run(tmp_path / "slips", slips), min_score=0, known=KNOWN)(PIXELS) == [
        ProposedBox("Mug", (1, 1, 9, 9), 0.7)
    ]
    for k, (row, problem) in enumerate(
        [
            (["Mug", ["1", 0, 10, 10], 0.9], "has a box corner of type str"),
            ([["Mug"], [0, 0, 10, 10], 0.9], "has a class_name of type list"),
            (["Mug", [0, 0, 10], 0.9], "has a box of 3 values"),
            (["Mug", [0, 0, 10, 10], "0.9"], "has a score of type str"),
        ]
    ):
        broken = open_proposer(file_run(tmp_path / f"broken{k}", [row]), min_score=0,
                               known=KNOWN)  # fmt: skip
        with pytest.raises(ConfigError, match=f"result 0 {problem}; expected"):
            broken(PIXELS)
    failing = open_proposer(file_run(tmp_path / "fails", "fail to detect"), min_score=0,
                            known=KNOWN)  # fmt: skip
    with pytest.raises(ConfigError, match="detection failed: ValueError: a bad image"):
        failing(PIXELS)


def _client(photos: Path, out: Path, run: Path) -> TestClient:
    app = create_app(photos, out, detector=run, min_score=0.5)
    return TestClient(app, base_url="http://127.0.0.1")


def test_a_never_saved_photo_opens_with_the_proposals_and_export_leaves_the_unaccepted_out(
    photos_dir: Path, tmp_path: Path
) -> None:
    run = file_run(
        tmp_path / "run", [["Mug", [10, 10, 60, 50], 0.8], ["DiningTable", [0, 100, 300, 230], 0.7]]
    )
    out = tmp_path / "ds"
    client = _client(photos_dir, out, run)
    # b.png is saved first with ids up to 7: a.png's proposals take ids no photo uses
    saved_b = {"revision": 0, "room_id": "k1", "room_type": "kitchen",
               "objects": [{"id": 7, "class_name": "Chair", "box": [1, 1, 30, 30]}]}  # fmt: skip
    assert client.put("/api/labels/b.png", json=saved_b).status_code == 200
    got = client.get("/api/labels/a.png").json()
    assert got["labels"]["revision"] == 0
    assert got["labels"]["objects"] == [
        {"id": 8, "class_name": "Mug", "box": [10, 10, 60, 50], "proposed": 0.8},
        {"id": 9, "class_name": "DiningTable", "box": [0, 100, 300, 230], "proposed": 0.7},
    ]
    assert got["detector"] == {"run": str(run), "min_score": 0.5}
    assert "2 proposed box(es) to accept (Enter) or delete" in got["problems"]
    assert any(p["src"] == 8 and p["dst"] == 9 for p in got["proposals"])  # the mug on the table
    # the labeler accepts the table (its score goes), keeps the mug proposed, sets the room
    labels = {**got["labels"], "room_id": "k1", "room_type": "kitchen"}
    labels["objects"] = [labels["objects"][0], {**labels["objects"][1], "proposed": None}]
    stored = client.put("/api/labels/a.png", json=labels).json()
    assert stored["labels"]["revision"] == 1
    assert "1 proposed box(es) to accept (Enter) or delete" in stored["problems"]
    # saved labels are the labeler's: the detector does not run again on a saved photo
    (run / "boxes.json").write_text(json.dumps([["Chair", [0, 0, 9, 9], 0.99]]))
    again = client.get("/api/labels/a.png").json()["labels"]["objects"]
    assert [(o["id"], o.get("proposed")) for o in again] == [(8, 0.8), (9, None)]
    done = export_dataset(photos_dir, out)
    assert done.guessed == {"a.png": 1}
    import pyarrow.parquet as pq

    rows = pq.read_table(next(out.glob("observations/*/k1.parquet"))).to_pylist()
    kept = {r["obs_id"]: [o["instance"] for o in r["objects"]] for r in rows}
    assert kept == {"k1/a": [9], "k1/b": [7]}  # the mug never accepted is no label


def test_a_detector_that_fails_on_a_photo_is_said_in_the_page(
    photos_dir: Path, tmp_path: Path
) -> None:
    client = _client(photos_dir, tmp_path / "ds", file_run(tmp_path / "run", "fail to detect"))
    got = client.get("/api/labels/a.png")
    assert got.status_code == 500
    assert got.json()["detail"].endswith("detection failed: ValueError: a bad image")


def test_the_command_refuses_a_bad_detector_in_one_line(photos_dir: Path, tmp_path: Path) -> None:
    done = run_cli("sgdata", "label", photos_dir, "--out", tmp_path / "ds", "--detector",
                   tmp_path / "none")  # fmt: skip
    assert done.returncode == 2 and "Traceback" not in done.stderr
    assert done.stderr.strip() == (
        f"sgdata: error: --detector {tmp_path / 'none'}: no detector.json; expected a detector "
        "run (seannet detector train --out RUN)"
    )
    both = run_cli("sgdata", "label", photos_dir, "--out", tmp_path / "ds", "--export",
                   "--detector", tmp_path / "none")  # fmt: skip
    assert both.returncode == 2 and "give one" in both.stderr
    assert not (tmp_path / "ds" / "dataset.json").exists()
