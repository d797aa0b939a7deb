"""What a detector's scene graphs lose (``seannet detector graphs``): detections made from a
real view's truth lose nothing; dropping a class's detections loses exactly its objects and
their relations' ends."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from seannet.detection.fidelity import ViewTally, summary, tally_view
from seannet.detection.graphs import ViewDetections
from sgdata.dataset import Dataset, observations_schema, read_table


def _views(channels_dataset: Path) -> tuple[np.ndarray, list[dict]]:
    ds = Dataset.open(channels_dataset)
    slot_runs = np.array([(c.slot_start, c.slot_count) for c in ds.manifest.classes], np.int64)
    rows = read_table(ds.observation_files("test")[0], observations_schema(),
                      columns=["obs_id", "objects", "relations"]).to_pylist()  # fmt: skip
    return slot_runs, [r for r in rows if len(r["objects"]) >= 3][:5]


def _as_detected(objects: list[dict], keep: set[int] | None = None) -> ViewDetections:
    """The truth as a detector that saw it exactly (boxes, classes, 3D boxes), best first."""
    chosen = [o for o in objects if keep is None or o["class_id"] in keep]
    n = len(chosen)
    return ViewDetections(
        np.array([o["box2d"] for o in chosen], np.float32).reshape(n, 4),
        np.array([o["class_id"] for o in chosen], np.int64),
        np.linspace(0.99, 0.6, n),
        np.array([o["box3d_min"] for o in chosen], np.float64).reshape(n, 3),
        np.array([o["box3d_max"] for o in chosen], np.float64).reshape(n, 3),
        np.ones(n, bool),
    )


def test_the_truth_detected_exactly_loses_no_object_and_no_relations_end(
    channels_dataset: Path,
) -> None:
    slot_runs, views = _views(channels_dataset)
    assert views, "no test view with three objects: the test compares nothing"
    tally = ViewTally()
    for view in views:
        tally_view(tally, _as_detected(view["objects"]), 0.5, slot_runs, view["objects"],
                   view["relations"])  # fmt: skip
    found = summary(tally)
    assert found["objects"]["recall"] == 1.0 and found["objects"]["precision"] == 1.0
    assert found["objects"]["true"] == sum(len(v["objects"]) for v in views)
    assert found["lifting"]["centre_error_m"]["median"] == 0.0
    assert found["lifting"]["size_error_m"]["p90"] == 0.0
    assert found["relations"]["true"] == sum(len(v["relations"]) for v in views)
    assert found["relations"]["with_both_ends"] == 1.0
    # the relations of the same boxes by the generator's rules: the pairwise ones all agree
    assert found["relations"]["by_type"]["disjoint"]["kept_of_those"] > 0.9


def test_a_class_never_detected_loses_its_objects_and_their_relations(
    channels_dataset: Path,
) -> None:
    slot_runs, views = _views(channels_dataset)
    view = views[0]
    classes = sorted({o["class_id"] for o in view["objects"]})
    missed = classes[0]
    tally = ViewTally()
    tally_view(tally, _as_detected(view["objects"], set(classes[1:])), 0.5, slot_runs,
               view["objects"], view["relations"])  # fmt: skip
    found = summary(tally)
    gone = {o["instance"] for o in view["objects"] if o["class_id"] == missed}
    n = len(view["objects"])
    assert found["objects"]["recall"] == (n - len(gone)) / n
    assert found["objects"]["precision"] == 1.0
    ends = [r for r in view["relations"] if r["src"] not in gone and r["dst"] not in gone]
    assert found["relations"]["with_both_ends"] == len(ends) / len(view["relations"])
    # nothing detected at all: every share that has a whole is 0, the rest say so
    tally = ViewTally()
    tally_view(tally, ViewDetections.none(), 0.5, slot_runs, view["objects"], view["relations"])
    nothing = summary(tally)
    assert nothing["objects"]["recall"] == 0.0 and nothing["objects"]["precision"] is None
    assert nothing["lifting"]["centre_error_m"]["median"] is None
    assert nothing["relations"]["with_both_ends"] == 0.0
    assert nothing["relations"]["kept_of_those"] is None
