"""Real EGL rendering of the tiny room: exact ids, occlusion, determinism, layout updates."""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np
import pytest

from sgdata.errors import RenderError
from sgdata.render.camera import CameraConfig
from sgdata.render.renderer import Renderer
from sgdata.usd.meshes import ObjectGeometry, SceneGeometry


def test_ids_are_only_known_instances(
    tiny_renderer: Renderer, tiny_room: Any, tiny_view: Any
) -> None:
    known = {-1, *tiny_room.ids.values()}
    for pass_ in ("raster", "raycast"):
        ids = tiny_renderer.render_ids(*tiny_view, id_pass=pass_)
        assert ids.dtype == np.int32 and ids.shape == (224, 224)
        assert set(np.unique(ids).tolist()) <= known


def test_id_passes_agree(tiny_renderer: Renderer, tiny_view: Any) -> None:
    a = tiny_renderer.render_ids(*tiny_view, id_pass="raster")
    b = tiny_renderer.render_ids(*tiny_view, id_pass="raycast")
    assert (a != b).sum() <= 10  # only pixel centres exactly on a shared edge may differ


def test_ids_match_rgb_silhouettes(tiny_renderer: Renderer, tiny_view: Any) -> None:
    """Background (walls) and objects differ in colour; the id image follows the RGB edges:
    the red mug's pixels are red in the RGB."""
    view = tiny_renderer.render(*tiny_view)
    mug = view.rgb[view.instance == 2].astype(int)
    assert len(mug) > 20
    assert np.all(mug[:, 0] > mug[:, 1] + 40)


def test_wall_occludes_hidden_crate(
    tiny_renderer: Renderer, tiny_room: Any, tiny_view: Any
) -> None:
    ids = tiny_renderer.render_ids(*tiny_view)
    assert tiny_room.ids["crate"] not in ids
    # the crate would be in view without the wall: it projects inside the image
    crate = tiny_room.room.by_instance()[tiny_room.ids["crate"]]
    uvz = tiny_renderer.camera.project(crate.corners(), *tiny_view)
    assert np.all(uvz[:, 2] > 0) and np.all((uvz[:, :2] > 0) & (uvz[:, :2] < 224))


def test_same_input_same_bytes(tiny_renderer: Renderer, tiny_view: Any) -> None:
    a = tiny_renderer.render(*tiny_view)
    b = tiny_renderer.render(*tiny_view)
    assert a.rgb.dtype == np.uint8 and a.rgb.shape == (224, 224, 3)
    assert a.rgb.tobytes() == b.rgb.tobytes()
    assert np.array_equal(a.instance, b.instance)
    c = tiny_renderer.render(*tiny_view, rng=np.random.default_rng(7))
    d = tiny_renderer.render(*tiny_view, rng=np.random.default_rng(7))
    assert c.rgb.tobytes() == d.rgb.tobytes()
    assert c.rgb.tobytes() != a.rgb.tobytes()  # the light jitter shows
    assert np.array_equal(c.instance, a.instance)


def test_depth_is_view_axis_distance(
    tiny_renderer: Renderer, tiny_room: Any, tiny_view: Any
) -> None:
    view = tiny_renderer.render(*tiny_view)
    assert view.depth is not None and view.depth.dtype == np.float32
    # pixel (u=112, v=50) sees the north wall (y = 4, 3.5 m ahead of the eye); its ray has
    # forward component 1, so the depth (distance along the view axis) is 3.5 / ray_y
    cam = tiny_renderer.camera
    right, up, forward = cam.basis(tiny_view[2])
    ray = right * (112.5 - 112) / cam.focal + up * (112 - 50.5) / cam.focal + forward
    assert view.instance[50, 112] == -1
    assert view.depth[50, 112] == pytest.approx(3.5 / ray[1], abs=0.01)


def test_update_poses_moves_without_rebuild(
    tiny_renderer: Renderer, tiny_room: Any, tiny_view: Any
) -> None:
    chair = tiny_room.ids["chair_b"]
    before = tiny_renderer.render_ids(*tiny_view)
    structure_before = set(tiny_renderer._scene.mesh_nodes) - {tiny_renderer._merged_node}
    moved = []
    for og in tiny_room.geometry.objects:
        if og.instance == chair:
            m = og.matrix.copy()
            m[0, 3] += 0.4
            og = ObjectGeometry(og.instance, og.class_name, og.mesh, m)
        moved.append(og)
    rebuilt = tiny_renderer.update_poses(SceneGeometry(tiny_room.geometry.structure, tuple(moved)))
    after = tiny_renderer.render_ids(*tiny_view)
    assert rebuilt is False
    assert set(tiny_renderer._scene.mesh_nodes) - {tiny_renderer._merged_node} == structure_before
    cols_before = np.nonzero((before == chair).any(axis=0))[0]
    cols_after = np.nonzero((after == chair).any(axis=0))[0]
    assert cols_after.min() > cols_before.min() + 10  # moved right in the image
    # a different instance set rebuilds
    assert tiny_renderer.update_poses(
        SceneGeometry(tiny_room.geometry.structure, tuple(moved[:-1]))
    )
    assert tiny_renderer.update_poses(tiny_room.geometry)


def test_render_before_load_is_an_error() -> None:
    r = Renderer.__new__(Renderer)  # no GL context needed to check the guard
    r._scene = None
    with pytest.raises(RenderError, match="call Renderer.load"):
        r.render(0.0, 0.0, 0.0)


@pytest.mark.parametrize(
    "kwargs", [{"hfov_deg": 0.0}, {"pitch_deg": 95.0}, {"width": 0}, {"znear": 0.0}]
)
def test_camera_config_is_validated(kwargs: dict[str, float]) -> None:
    with pytest.raises(RenderError):
        CameraConfig(**kwargs)  # type: ignore[arg-type]


def test_camera_projection_conventions() -> None:
    cam = dataclasses.replace(CameraConfig(), pitch_deg=0.0)
    # a point straight ahead at eye height lands on the image centre
    uvz = cam.project(np.array([[3.0, 0.0, 1.5]]), 0.0, 0.0, 0.0)
    assert uvz[0] == pytest.approx([112.0, 112.0, 3.0])
    # heading 90 deg looks along +Y; +X is then to the right (larger u)
    uvz = cam.project(np.array([[0.5, 2.0, 1.5]]), 0.0, 0.0, np.pi / 2)
    assert uvz[0, 0] > 112 and uvz[0, 1] == pytest.approx(112.0)
    # points above the eye are in the upper half (smaller v)
    uvz = cam.project(np.array([[3.0, 0.0, 2.0]]), 0.0, 0.0, 0.0)
    assert uvz[0, 1] < 112


def test_closing_one_renderer_leaves_the_others_working(tiny_room) -> None:  # noqa: ANN001
    """pyrender's close terminates the process's shared EGL display; ours does so only when
    the last renderer closes."""
    from sgdata.render.renderer import Renderer

    first, second = Renderer(), Renderer()
    first.load(tiny_room.geometry)
    second.load(tiny_room.geometry)
    before = first.render(1.0, 1.0, 0.0).rgb.copy()
    second.close()
    assert np.array_equal(first.render(1.0, 1.0, 0.0).rgb, before)
    first.close()
    third = Renderer()
    third.load(tiny_room.geometry)
    assert np.array_equal(third.render(1.0, 1.0, 0.0).rgb, before)
    third.close()
