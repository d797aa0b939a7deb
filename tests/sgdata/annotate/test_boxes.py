"""Annotation on real renders: visible set, pixel boxes against projected geometry, 3D boxes."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from sgdata.annotate.boxes import ObjectTable, annotate
from sgdata.errors import RenderError
from sgdata.render.renderer import RenderedView


@pytest.fixture
def table(tiny_room: Any) -> ObjectTable:
    return ObjectTable.from_scene(tiny_room.geometry, tiny_room.room)


def test_visible_set_is_exact(
    tiny_renderer: Any, tiny_room: Any, tiny_view: Any, table: ObjectTable
) -> None:
    ann = annotate(tiny_renderer.render(*tiny_view), table)
    want = sorted(v for k, v in tiny_room.ids.items() if k != "crate")
    assert ann.instance.tolist() == want
    assert (ann.visible_pixels >= 20).all()


def test_min_visible_pixels_filters(
    tiny_renderer: Any, tiny_view: Any, table: ObjectTable, tiny_room: Any
) -> None:
    view = tiny_renderer.render(*tiny_view)
    full = annotate(view, table, min_visible_pixels=1)
    mug_px = int(full.visible_pixels[full.instance.tolist().index(tiny_room.ids["mug"])])
    ann = annotate(view, table, min_visible_pixels=mug_px + 1)
    assert tiny_room.ids["mug"] not in ann.instance.tolist()


def test_boxes_match_projected_geometry(
    tiny_renderer: Any, tiny_room: Any, tiny_view: Any, table: ObjectTable
) -> None:
    cam = tiny_renderer.camera
    ann = annotate(tiny_renderer.render(*tiny_view), table)
    geom = {o.instance: o for o in tiny_room.geometry.objects}
    # unoccluded objects: their pixel box is the projected vertex box, clipped to the image
    for name in ("table", "mug", "chair_a", "chair_b"):  # (chair_b hides the unit's left edge)
        inst = tiny_room.ids[name]
        og = geom[inst]
        world = og.mesh.vertices @ og.matrix[:3, :3].T + og.matrix[:3, 3]
        uv = cam.project(world, *tiny_view)[:, :2]
        proj = np.array([*uv.min(axis=0), *uv.max(axis=0)])
        proj = np.clip(proj, 0, [cam.width, cam.height, cam.width, cam.height])
        got = ann.box2d[ann.instance.tolist().index(inst)]
        assert np.abs(got - proj).max() <= 2.0, (name, got, proj)  # pixel-centre sampling


def test_matches_plain_reference(tiny_renderer: Any, tiny_view: Any, table: ObjectTable) -> None:
    view = tiny_renderer.render(*tiny_view)
    ann = annotate(view, table, min_visible_pixels=1)
    for inst, box, count in zip(ann.instance, ann.box2d, ann.visible_pixels, strict=True):
        rows, cols = np.nonzero(view.instance == inst)
        assert count == len(rows)
        assert box.tolist() == [cols.min(), rows.min(), cols.max() + 1, rows.max() + 1]


def test_3d_boxes_and_support(tiny_room: Any, table: ObjectTable) -> None:
    k = table.instance.tolist().index(tiny_room.ids["table"])
    assert table.aabb_min[k] == pytest.approx([0.8, 2.5, 0.0])
    assert table.aabb_max[k] == pytest.approx([1.8, 3.1, 0.75])
    assert table.obb[k] == pytest.approx([1.3, 2.8, 0.375, 1.0, 0.6, 0.75, 0.0])
    m = table.instance.tolist().index(tiny_room.ids["mug"])
    assert table.support[m] == tiny_room.ids["table"] and table.support[k] == -1
    assert table.dynamics[m] == "high"
    without_room = ObjectTable.from_scene(tiny_room.geometry)
    assert without_room.obb[k] == pytest.approx(table.obb[k])
    assert (without_room.support == -1).all()


def test_unknown_ids_raise(table: ObjectTable) -> None:
    ids = np.full((4, 4), -1, dtype=np.int32)
    ids[0, 0] = 999
    view = RenderedView(rgb=np.zeros((4, 4, 3), np.uint8), instance=ids, depth=None)
    with pytest.raises(RenderError, match="not objects"):
        annotate(view, table)
    empty = annotate(
        RenderedView(np.zeros((4, 4, 3), np.uint8), np.full((4, 4), -1, np.int32), None), table
    )
    assert len(empty) == 0 and empty.box2d.shape == (0, 4)
