"""Tests for the procedural shape recipes: closed parts inside the local box, attachments and
surfaces where they belong, determinism, modest triangle counts."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from sgdata.world.catalog import ClassSpec, load_catalog
from sgdata.world.shapes import RECIPES, build_shape, merged_mesh
from sgdata.world.shapes.base import ShapeBuild

CATALOG = load_catalog(Path(__file__).resolve().parents[3] / "assets" / "catalog.toml")
TOL = 1e-6
MAX_TRIANGLES = 2500  # one object; a room of ~60 objects should stay well under ~20k on average


def _sizes(spec: ClassSpec) -> list[tuple[float, float, float]]:
    lo, hi = np.array(spec.size_min), np.array(spec.size_max)
    return [tuple(float(v) for v in s) for s in (lo, hi, (lo + hi) / 2)]


def _cases() -> list[tuple[str, tuple[float, float, float], int]]:
    return [
        (spec.name, size, variant)
        for spec in CATALOG.classes.values()
        for size in _sizes(spec)
        for variant in range(spec.variants)
    ]


CASES = _cases()


def _build(name: str, size: tuple[float, float, float], variant: int) -> ShapeBuild:
    spec = CATALOG[name]
    return build_shape(spec.shape, size, variant, spec.palette[0])


def _inside(points: np.ndarray, size: tuple[float, float, float]) -> bool:
    w, d, h = size
    lo = np.array([-w / 2, -d / 2, 0.0]) - TOL
    hi = np.array([w / 2, d / 2, h]) + TOL
    return bool(np.all(points >= lo) and np.all(points <= hi))


@pytest.mark.parametrize(("name", "size", "variant"), CASES)
def test_parts_closed_and_inside_box(name: str, size: tuple, variant: int) -> None:
    build = _build(name, size, variant)
    assert build.parts, f"{name}: no parts"
    for i, part in enumerate(build.parts):
        assert len(part.mesh.faces) > 0, f"{name} part {i}: empty"
        assert part.mesh.is_watertight, f"{name} v{variant} part {i}: not watertight"
        assert _inside(np.asarray(part.mesh.vertices), size), (
            f"{name} v{variant} size {size} part {i}: outside the local box "
            f"{part.mesh.bounds.tolist()}"
        )
        assert all(0.0 <= c <= 1.0 for c in part.color)


@pytest.mark.parametrize(("name", "size", "variant"), CASES)
def test_attachments_inside_owner(name: str, size: tuple, variant: int) -> None:
    build = _build(name, size, variant)
    for att in build.attachments:
        assert att.class_name in CATALOG, f"{name}: attaches unknown class {att.class_name}"
        spec = CATALOG[att.class_name]
        assert spec.placement == "part", f"{att.class_name} should have placement 'part'"
        aw, ad, ah = att.size
        assert aw > 0 and ad > 0 and ah > 0
        # the part's size lies within its catalog range so the generator can sample alike
        for v, lo, hi in zip(att.size, spec.size_min, spec.size_max, strict=True):
            assert lo - TOL <= v <= hi + TOL, f"{name}: {att.class_name} size {att.size}"
        assert att.yaw == 0.0
        corners = np.array(
            [
                [att.x + sx * aw / 2, att.y + sy * ad / 2, att.z + z]
                for sx in (-1, 1)
                for sy in (-1, 1)
                for z in (0.0, ah)
            ]
        )
        if att.class_name == "CounterTop":
            # the counter slab sits on top of the cabinet body: check its footprint only
            corners[:, 2] = np.clip(corners[:, 2], 0.0, size[2])
        assert _inside(corners, size), f"{name}: {att.class_name} box outside the owner's box"


@pytest.mark.parametrize(("name", "size", "variant"), CASES)
def test_surfaces_inside_footprint(name: str, size: tuple, variant: int) -> None:
    w, d, h = size
    for s in _build(name, size, variant).surfaces:
        assert -w / 2 - TOL <= s.x0 < s.x1 <= w / 2 + TOL, f"{name}: surface x {s}"
        assert -d / 2 - TOL <= s.y0 < s.y1 <= d / 2 + TOL, f"{name}: surface y {s}"
        assert 0.0 <= s.z <= h + TOL, f"{name}: surface z {s}"
        assert s.clearance > 0


@pytest.mark.parametrize(("name", "size", "variant"), CASES)
def test_triangle_count_bounded(name: str, size: tuple, variant: int) -> None:
    _, faces, colors = merged_mesh(_build(name, size, variant))
    assert len(faces) == len(colors)
    assert len(faces) <= MAX_TRIANGLES, f"{name}: {len(faces)} triangles"


@pytest.mark.parametrize("name", sorted(CATALOG.names()))
def test_deterministic(name: str) -> None:
    spec = CATALOG[name]
    for variant in range(spec.variants):
        size = _sizes(spec)[2]
        a = merged_mesh(_build(name, size, variant))
        b = merged_mesh(_build(name, size, variant))
        for x, y in zip(a, b, strict=True):
            np.testing.assert_array_equal(x, y)
        assert _build(name, size, variant).attachments == _build(name, size, variant).attachments


def test_variants_wrap() -> None:
    """Recipes take any variant number and wrap it themselves."""
    for spec in CATALOG.classes.values():
        size = _sizes(spec)[2]
        a = merged_mesh(_build(spec.name, size, 0))[0]
        b = merged_mesh(_build(spec.name, size, spec.variants * 7))[0]
        assert len(a) > 0 and len(b) > 0


def test_every_recipe_used_or_fallback() -> None:
    used = {spec.shape for spec in CATALOG.classes.values()}
    assert used <= set(RECIPES)
    assert set(RECIPES) - used <= {"block"}, set(RECIPES) - used


def test_mid_room_triangle_budget() -> None:
    """A room of 60 typical objects stays near the ~20k triangle budget."""
    counts = [
        len(merged_mesh(_build(spec.name, _sizes(spec)[2], 0))[1])
        for spec in CATALOG.classes.values()
    ]
    assert np.mean(counts) * 60 <= 25_000, np.mean(counts)


def test_front_parts_face_minus_y() -> None:
    """Handles and knobs stand proud of the front: the stove's knobs sit at the -Y face."""
    spec = CATALOG["Stove"]
    size = _sizes(spec)[2]
    build = _build("Stove", size, 0)
    knobs = [a for a in build.attachments if a.class_name == "StoveKnob"]
    burners = [a for a in build.attachments if a.class_name == "StoveBurner"]
    assert len(knobs) == 4 and len(burners) == 4
    assert all(k.y - k.size[1] / 2 == pytest.approx(-size[1] / 2) for k in knobs)
    assert all(b.z + b.size[2] == pytest.approx(size[2]) for b in burners)
    chair = _build("Chair", _sizes(CATALOG["Chair"])[2], 0)
    top = max(chair.parts, key=lambda p: p.mesh.bounds[1][2])
    assert top.mesh.bounds[0][1] > 0.0  # the chair back is on the +Y side
