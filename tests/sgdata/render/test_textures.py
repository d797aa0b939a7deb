"""Real EGL rendering of a textured room read back from USD: textures change the image and
vary inside one surface, the same input gives the same bytes, a new layout's looks and light
are taken without rebuilding the scene, and textures can be switched off."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from sgdata.render.renderer import Renderer
from sgdata.scene_files import layout_file, room_file
from sgdata.usd.geometry import read_geometry
from sgdata.usd.meshes import Lighting, SceneGeometry
from sgdata.usd.room_io import read_room
from sgdata.usd.scene_dirs import write_layouts, write_rooms
from sgdata.world.appearance import AppearanceConfig
from sgdata.world.catalog import Catalog
from sgdata.world.poses import pose_grid

APPEARANCE = AppearanceConfig(texture_size=128)


@pytest.fixture(scope="module")
def textured(tmp_path_factory: pytest.TempPathFactory, catalog: Catalog) -> tuple[Path, tuple]:
    """A textured kitchen (tiled floor) with two layouts, and a pose looking at the floor."""
    out = tmp_path_factory.mktemp("textured_render") / "scenes"
    write_rooms(out, "kitchen", count=1, seed=0, catalog=catalog, appearance=APPEARANCE)
    room_dir = out / "kitchen_000"
    write_layouts(room_dir, count=2, seed=0, catalog=catalog, appearance=APPEARANCE)
    grid = pose_grid(read_room(room_file(room_dir)))
    i, j = grid.cells[len(grid.cells) // 2]
    return room_dir, grid.pose_world(i, j, 1)


def _floor_spread(rgb: np.ndarray, ids: np.ndarray) -> float:
    """Grey-level spread over the structure pixels of the image's bottom quarter (the floor
    just ahead of the camera, which stands on a free cell)."""
    h = rgb.shape[0]
    grey = rgb[3 * h // 4 :].astype(np.float64).mean(axis=2)
    floor = ids[3 * h // 4 :] == -1
    assert floor.sum() > 500
    return float(grey[floor].std())


def test_textures_change_the_image_and_vary_inside_the_floor(
    renderer: Renderer, textured: tuple[Path, tuple]
) -> None:
    room_dir, pose = textured
    geometry = read_geometry(layout_file(room_dir, 0))
    renderer.load(geometry)
    view = renderer.render(*pose)
    renderer.textures = False
    try:
        renderer.load(geometry)
        flat = renderer.render(*pose)
    finally:
        renderer.textures = True
    assert np.array_equal(view.instance, flat.instance)  # same geometry, same ids
    differs = np.abs(view.rgb.astype(int) - flat.rgb.astype(int)).max(axis=2) > 8
    assert differs.mean() > 0.2
    assert _floor_spread(view.rgb, view.instance) > _floor_spread(flat.rgb, flat.instance) + 3.0


def test_textured_renders_are_the_same_bytes(
    renderer: Renderer, textured: tuple[Path, tuple]
) -> None:
    room_dir, pose = textured
    renderer.load(read_geometry(layout_file(room_dir, 1)))
    a = renderer.render_rgb(*pose)[0]
    renderer.load(read_geometry(layout_file(room_dir, 1)))  # fresh primitives, cached textures
    b = renderer.render_rgb(*pose)[0]
    assert a.tobytes() == b.tobytes()


def test_new_layout_looks_and_light_without_a_rebuild(
    renderer: Renderer, textured: tuple[Path, tuple]
) -> None:
    room_dir, pose = textured
    base = read_geometry(layout_file(room_dir, 0))
    renderer.load(base)
    before = renderer.render_rgb(*pose)[0]
    other = read_geometry(layout_file(room_dir, 1))
    assert other.lighting != base.lighting
    assert renderer.update_poses(other) is False  # same shapes: re-merged, not rebuilt
    after = renderer.render_rgb(*pose)[0]
    assert not np.array_equal(before, after)
    dim = dataclasses.replace(other, lighting=Lighting(intensity=0.5))
    bright = dataclasses.replace(other, lighting=Lighting(intensity=1.5))
    renderer.update_poses(dim)
    low = renderer.render_rgb(*pose)[0].mean()
    renderer.update_poses(bright)
    assert renderer.render_rgb(*pose)[0].mean() > low + 10
    warm = Lighting(temperature=3000.0, color=(1.0, 0.7, 0.4))
    renderer.update_poses(dataclasses.replace(other, lighting=warm))
    rgb = renderer.render_rgb(*pose)[0].reshape(-1, 3).mean(axis=0)
    assert rgb[0] > rgb[2] + 20  # a warm light reddens the view


def test_scene_geometry_default_light_is_white() -> None:
    assert SceneGeometry((), ()).lighting == Lighting(1.0, None, (1.0, 1.0, 1.0))
