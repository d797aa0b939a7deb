"""The view pipeline on the tiny room: record contents, relations, slots, overlay."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from sgdata.annotate.annotator import ViewAnnotator
from sgdata.annotate.records import ViewPose, ViewRecord
from sgdata.annotate.relations import RelationType
from sgdata.annotate.slots import SlotTable
from sgdata.pictures.overlay import draw_overlay

SLOTS = SlotTable.from_counts(
    [("DiningTable", 2), ("Mug", 4), ("ShelvingUnit", 2), ("Book", 4), ("Shelf", 4),
     ("Chair", 1), ("Box", 2)]
)  # fmt: skip


@pytest.fixture
def record(tiny_renderer: Any, tiny_room: Any, tiny_view: Any) -> ViewRecord:
    va = ViewAnnotator(tiny_renderer, SLOTS)
    va.set_layout(tiny_room.room, tiny_room.geometry, 0)
    return va.view(ViewPose(*tiny_view, grid_i=10, grid_j=2, heading=1), seed=5)


def test_record_fields(record: ViewRecord, tiny_room: Any) -> None:
    ids = tiny_room.ids
    assert record.room_id == "tiny_000" and record.layout == 0 and record.seed == 5
    assert record.rgb.shape == (224, 224, 3) and record.rgb.dtype == np.uint8
    # one chair slot: chair_b (the higher id) is dropped and counted
    assert record.dropped_objects == 1
    want = sorted(v for k, v in ids.items() if k not in ("crate", "chair_b"))
    assert record.obj_instance.tolist() == want
    k = {v: n for n, v in enumerate(record.obj_instance.tolist())}
    assert record.obj_slot[k[ids["mug"]]] == 2 and record.obj_slot[k[ids["chair_a"]]] == 16
    assert record.obj_support[k[ids["mug"]]] == ids["table"]
    assert record.obj_box2d.shape == (len(want), 4) and record.obj_obb.shape == (len(want), 7)
    n = len(want)
    assert len(record.obj_class) == len(record.obj_dynamics) == n
    assert len(record.rel_src) == n * (n - 1) - 4  # 2 on + 2 in pairs give one edge each


def test_relations_in_the_scene(tiny_renderer: Any, tiny_room: Any, tiny_view: Any) -> None:
    ids = tiny_room.ids
    va = ViewAnnotator(tiny_renderer, SlotTable.from_counts(
        [(c, 4) for c in ("DiningTable", "Mug", "ShelvingUnit", "Book", "Shelf", "Chair", "Box")]
    ))  # fmt: skip
    va.set_layout(tiny_room.room, tiny_room.geometry, 0)
    rec = va.view(ViewPose(*tiny_view, 0, 0, 1))
    edges = {
        (s, d): RelationType(t)
        for s, d, t in zip(
            rec.rel_src.tolist(), rec.rel_dst.tolist(), rec.rel_type.tolist(), strict=True
        )
    }
    assert edges[ids["mug"], ids["table"]] == RelationType.ON
    assert (ids["table"], ids["mug"]) not in edges
    assert edges[ids["book"], ids["board"]] == RelationType.ON
    assert edges[ids["book"], ids["unit"]] == RelationType.IN
    assert edges[ids["board"], ids["unit"]] == RelationType.IN
    assert edges[ids["chair_a"], ids["chair_b"]] == RelationType.PROXIMITY
    assert edges[ids["chair_b"], ids["chair_a"]] == RelationType.PROXIMITY
    assert edges[ids["mug"], ids["chair_b"]] == RelationType.DISJOINT
    assert all(ids["crate"] not in e for e in edges)


def test_same_pose_same_record(tiny_renderer: Any, tiny_room: Any, tiny_view: Any) -> None:
    va = ViewAnnotator(tiny_renderer, SLOTS)
    va.set_layout(tiny_room.room, tiny_room.geometry, 0)
    pose = ViewPose(*tiny_view, 0, 0, 1)
    a, b = va.view(pose, seed=3, jitter_lights=True), va.view(pose, seed=3, jitter_lights=True)
    assert a.rgb.tobytes() == b.rgb.tobytes()
    assert np.array_equal(a.rel_type, b.rel_type) and np.array_equal(a.obj_box2d, b.obj_box2d)


def test_record_converts_to_arrow(record: ViewRecord) -> None:
    pa = pytest.importorskip("pyarrow")
    from dataclasses import fields

    row = {}
    for f in fields(record):
        v = getattr(record, f.name)
        row[f.name] = v.tolist() if isinstance(v, np.ndarray) else v
    table = pa.Table.from_pylist([row])
    assert table.num_rows == 1 and table.column("obj_class").to_pylist()[0] == record.obj_class


def test_overlay_draws(record: ViewRecord) -> None:
    img = draw_overlay(record)
    assert img.size == (672, 672 + 22)
    px = np.asarray(img)
    assert (px[:672] != np.repeat(np.repeat(record.rgb, 3, axis=0), 3, axis=1)).any()


def test_depth_and_instance_channels(tiny_renderer: Any, tiny_room: Any, tiny_view: Any) -> None:
    """The instance mask numbers the listed objects 1..k: each one's extent is its stored box
    and its pixel count its visible pixels; a dropped object (chair_b) leaves no pixel; depth
    is metric and hits wherever an object is seen."""
    va = ViewAnnotator(tiny_renderer, SLOTS, keep_depth=True, keep_instances=True)
    va.set_layout(tiny_room.room, tiny_room.geometry, 0)
    rec = va.view(ViewPose(*tiny_view, grid_i=10, grid_j=2, heading=1), seed=5)
    mask, depth = rec.instances, rec.depth
    assert mask is not None and depth is not None
    assert mask.dtype == np.uint16 and mask.shape == rec.rgb.shape[:2]
    assert int(mask.max()) == rec.num_objects
    for k in range(rec.num_objects):
        v, u = np.nonzero(mask == k + 1)
        assert [u.min(), v.min(), u.max() + 1, v.max() + 1] == rec.obj_box2d[k].tolist()
        assert len(u) == rec.obj_visible_pixels[k]
    ids = tiny_renderer.render_ids(*tiny_view)
    assert not mask[ids == tiny_room.ids["chair_b"]].any()
    assert (depth[mask > 0] > 0).all() and float(depth.max()) < np.hypot(5.0, 4.0)
    plain = ViewAnnotator(tiny_renderer, SLOTS)
    plain.set_layout(tiny_room.room, tiny_room.geometry, 0)
    again = plain.view(ViewPose(*tiny_view, grid_i=10, grid_j=2, heading=1), seed=5)
    assert again.instances is None and again.depth is None
    assert np.array_equal(again.rgb, rec.rgb)  # reading depth back leaves the pixels as they are
