"""Navigation on a detector's scene graphs (``seannet navigate --graphs detected``): every
rendered view gets the graph the detector gives it, the graph its stored view gets, and the
maps, parts and results of such a run are its own."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from seannet.data.live_views import LiveRooms
from seannet.detection.graphs import detected_graphs
from seannet.detection.live_graphs import live_graphs
from seannet.detection.train import load_detector
from seannet.navigation.benchmark import run_navigation
from seannet.navigation.config import NavigationTestConfig
from sgdata.dataset import Dataset, observations_schema, read_table
from tests.cli_runner import run_cli

# one spawned worker for the module's one-worker navigations (conftest.one_pool)
pytestmark = pytest.mark.usefixtures("one_pool")


def test_a_rendered_view_gets_the_graph_its_stored_view_gets(
    detector_copy: Path, channels_dataset: Path
) -> None:
    ds = Dataset.open(channels_dataset)
    graphs = live_graphs(detector_copy, ds)
    stored = detected_graphs(load_detector(detector_copy, ds), ds, ["test"])
    assert graphs.threshold == stored.threshold and graphs.label == stored.label()
    shard = ds.observation_files("test")[0]
    columns = ["obs_id", "room_id", "layout", "grid_i", "grid_j", "heading"]
    rows = read_table(shard, observations_schema(), columns=columns).to_pylist()[:4]
    names = [c.name for c in ds.manifest.classes]
    compared = 0
    with LiveRooms(ds, regraph=graphs.regraph(ds)) as live:
        for row in rows:
            live.load(row["room_id"], row["layout"])
            record = live.view(row["grid_i"], row["grid_j"], row["heading"])
            (instance, class_id, slot, box2d), relations = stored.views[row["obs_id"]]
            assert record.obj_instance.tolist() == instance.tolist()
            assert record.obj_class == [names[c] for c in class_id.tolist()]
            assert record.obj_slot.tolist() == slot.tolist()
            # the same pixels, the same boxes (but for float sums: one view, not a batch of 16)
            assert np.allclose(record.obj_box2d, box2d, atol=1e-3)
            # relations from the rendered depth, the stored one a quantisation of it
            live_pairs = set(zip(record.rel_src.tolist(), record.rel_dst.tolist(),
                                 record.rel_type.tolist(), strict=True))  # fmt: skip
            stored_pairs = set(zip(*(r.tolist() for r in relations), strict=True))
            assert live_pairs == stored_pairs
            compared += len(instance)
    assert compared > 0, "the detector found nothing on four views: the test compares nothing"


def test_navigate_with_detected_graphs_keeps_its_maps_parts_and_label_apart(
    detector_copy: Path, channels_dataset: Path, tmp_path: Path
) -> None:
    config = NavigationTestConfig(episodes=1)
    truth = run_navigation(["boxes-overlap"], None, channels_dataset, config, epsilon=0.5,
                           out=tmp_path, maps=tmp_path / "maps")  # fmt: skip
    done = run_cli("seannet", "navigate", "boxes-overlap", "--data", channels_dataset,
                   "--oracle", "--episodes", "1", "--epsilon", "0.5",
                   "--out", tmp_path / "detected", "--maps", tmp_path / "maps",
                   "--graphs", "detected", "--detector", detector_copy)  # fmt: skip
    assert done.returncode == 0, done.stderr
    graphs = live_graphs(detector_copy, channels_dataset)  # the val detections are cached now
    assert f"detected graphs: score >= {graphs.threshold:g}" in done.stdout
    found = json.loads((tmp_path / "detected" / "navigate_test.json").read_text())
    (run,) = found["runs"]
    assert run["label"] == f"boxes-overlap@{graphs.label}"
    assert found["graphs"] == {"run": str(detector_copy), "detector": graphs.detector,
                               "threshold": graphs.threshold}  # fmt: skip
    assert "graphs" not in truth
    maps = sorted(p.name for p in (tmp_path / "maps").iterdir())
    assert maps == ["boxes-overlap", run["label"]]
    # the same episodes (drawn from the maps' structure), seen through other graphs
    paths = [[e["path"] for e in r["episodes"]] for r in (truth["runs"][0], run)]
    assert paths[0] == paths[1]


def test_navigate_wants_graphs_and_detector_together(
    channels_dataset: Path, tmp_path: Path
) -> None:
    done = run_cli("seannet", "navigate", "boxes-overlap", "--data", channels_dataset,
                   "--oracle", "--out", tmp_path, "--graphs", "detected")  # fmt: skip
    assert done.returncode == 2 and "--graphs detected and --detector RUN go together" in (
        done.stderr
    )
    assert not list(tmp_path.iterdir())
