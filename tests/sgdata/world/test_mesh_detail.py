"""Render detail: mesh classes draw at most max_triangles per variant; placement: the full mesh."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import trimesh

from sgdata.errors import CatalogError
from sgdata.world.catalog import DEFAULT_MAX_TRIANGLES, load_catalog
from sgdata.world.mesh_assets import class_assets, mesh_build
from sgdata.world.mesh_detail import budgets, decimate
from sgdata.world.shapes import merged_mesh


def _ball_class(tmp_path: Path, extra: str = "") -> object:
    mesh = trimesh.creation.icosphere(subdivisions=5, radius=0.15)  # 20,480 triangles
    mesh.apply_translation((0, 0, 0.15))
    (tmp_path / "ball.ply").write_bytes(mesh.export(file_type="ply"))
    (tmp_path / "user.toml").write_text(
        '[classes.Ball]\nmesh = "ball.ply"\ndynamics = "high"\nplacement = "floor"\n'
        f'units = "m"\nsize_min = [0.2, 0.2, 0.2]\nsize_max = [0.4, 0.4, 0.4]\n{extra}',
        encoding="utf-8",
    )
    return load_catalog(extra=[tmp_path / "user.toml"])["Ball"]


def test_a_heavy_mesh_draws_within_its_budget(tmp_path: Path) -> None:
    spec = _ball_class(tmp_path)
    asset = class_assets(spec)[0]
    assert asset.triangles == 20480 and spec.mesh.max_triangles == DEFAULT_MAX_TRIANGLES
    vertices, faces, _ = merged_mesh(mesh_build(spec, asset.size, 0))
    assert DEFAULT_MAX_TRIANGLES / 2 <= len(faces) <= DEFAULT_MAX_TRIANGLES
    assert np.ptp(vertices, axis=0) == pytest.approx(asset.size, rel=0.02)  # same shape
    assert len(asset.footprint) > 60  # placement: the full mesh's hull


def test_simplifying_is_deterministic(tmp_path: Path) -> None:
    spec = _ball_class(tmp_path)
    size = class_assets(spec)[0].size
    first = merged_mesh(mesh_build(spec, size, 0))
    mesh_build.cache_clear()
    second = merged_mesh(mesh_build(spec, size, 0))
    for a, b in zip(first, second, strict=True):
        assert np.array_equal(a, b)


def test_zero_keeps_every_triangle(tmp_path: Path) -> None:
    spec = _ball_class(tmp_path, "max_triangles = 0\n")
    _, faces, _ = merged_mesh(mesh_build(spec, class_assets(spec)[0].size, 0))
    assert len(faces) == 20480


def test_a_bad_budget_is_one_line(tmp_path: Path) -> None:
    with pytest.raises(CatalogError, match="'max_triangles' is -5; expected a whole number"):
        _ball_class(tmp_path, "max_triangles = -5\n")


def test_budgets_share_the_limit_and_spare_small_parts() -> None:
    assert budgets([10, 20], 2000) == [10, 20]
    assert budgets([30, 9000, 1000], 2000) == [30, 1794, 199]  # shares of 2000 by 10,030
    assert budgets([9000], 0) == [9000]


def test_textured_parts_keep_coordinates() -> None:
    mesh = trimesh.creation.icosphere(subdivisions=4)
    uvs = (mesh.vertices[:, :2] * 0.5 + 0.5)[mesh.faces]
    vertices, faces, new_uvs = decimate(mesh.vertices, mesh.faces, 500, uvs)
    assert len(faces) <= 500 and new_uvs.shape == (len(faces), 3, 2)
    # each corner's coordinate is its nearest original vertex's: close to the projection
    assert np.abs(new_uvs - (vertices[faces][:, :, :2] * 0.5 + 0.5)).max() < 0.1
