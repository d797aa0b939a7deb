"""The structure mask a generated dataset stores with its instance masks (format 2.3.0): the
room's parts where no object is, the door's opening only where nothing is drawn, and the
class mask that names both objects and parts."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from sgdata.dataset import Dataset
from sgdata.dataset.channels import class_mask, decode_channel, stored_channels
from sgdata.room_parts import DOOR, FLOOR, WALL


def test_generated_views_name_the_rooms_parts(channels_dataset: Path) -> None:
    ds = Dataset.open(channels_dataset)
    m = ds.manifest
    assert stored_channels(m.config, m.format_version) == ("depth", "instances", "structure")
    assert stored_channels(m.config, "2.2.0") == ("depth", "instances")
    n_classes = len(m.classes)
    seen: set[int] = set()
    for split in ds.splits:
        columns = ["depth", "instances", "structure", "objects"]
        for row in ds.observations(split, columns=columns).to_pylist():
            depth, mask, parts = (decode_channel(row[c]) for c in columns[:3])
            assert not np.any((mask > 0) & (parts > 0))  # objects keep their pixels
            door = parts == DOOR
            assert np.all(depth[door] == 0)  # the opening has no surface to draw
            assert np.all(depth[(parts > 0) & ~door] > 0)  # walls, floor, ceiling have
            # what neither mask names is an object too small to be listed: it has depth
            assert np.all(depth[(mask == 0) & (parts == 0)] > 0)
            ids = np.array([o["class_id"] for o in row["objects"]], np.int64)
            classes = class_mask(mask, ids, parts, n_classes=n_classes)
            assert np.array_equal(classes[mask > 0], class_mask(mask, ids)[mask > 0])
            assert np.array_equal(classes[parts > 0], n_classes + parts[parts > 0])
            seen |= set(np.unique(parts).tolist())
    assert {WALL, FLOOR} <= seen
