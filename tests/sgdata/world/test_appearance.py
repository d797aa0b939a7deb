"""Procedural textures (deterministic bytes, seamless, distinct variants), UVs of the catalog's
shapes, the surface -> texture mapping, and per-layout appearance draws within their ranges."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from sgdata.errors import ConfigError
from sgdata.world.appearance import (
    AppearanceConfig,
    light_color,
    room_looks,
    sample_appearance,
    tinted,
)
from sgdata.world.catalog import load_catalog
from sgdata.world.materials import CLASS_TEXTURES, body_texture, part_texture, structure_texture
from sgdata.world.scene import Dynamics, Room
from sgdata.world.shapes import box_uvs, build_shape, merged_mesh
from sgdata.world.shapes.base import DARK, METAL
from sgdata.world.textures import TEXTURE_KINDS, texture_image

CATALOG = load_catalog(Path(__file__).resolve().parents[3] / "assets" / "catalog.toml")
SIZE = 64  # small images keep the tests fast; every kind scales with the size


def _texture_digests() -> str:
    import hashlib

    from sgdata.world.textures import _image

    _image.cache_clear()
    return ",".join(
        hashlib.sha256(texture_image(k, v, SIZE).tobytes()).hexdigest()[:16]
        for k, spec in TEXTURE_KINDS.items()
        for v in range(spec.variants)
    )


def test_textures_are_the_same_bytes_twice_and_in_another_process() -> None:
    first, second = _texture_digests(), _texture_digests()
    assert first == second
    code = (
        "import sys; sys.path.insert(0, 'tests/sgdata/world'); "
        "from test_appearance import _texture_digests; print(_texture_digests())"
    )
    root = Path(__file__).resolve().parents[3]
    other = subprocess.run(
        [sys.executable, "-c", code],
        cwd=root,
        capture_output=True,
        text=True,
        check=True,
        env={"PYTHONHASHSEED": "12345", "PATH": ""},
    )
    assert other.stdout.strip() == first


@pytest.mark.parametrize("kind", sorted(TEXTURE_KINDS))
def test_textures_vary_within_an_image_and_between_variants(kind: str) -> None:
    images = [texture_image(kind, v, SIZE) for v in range(TEXTURE_KINDS[kind].variants)]
    for image in images:
        assert image.shape == (SIZE, SIZE, 3) and image.dtype == np.uint8
        assert not image.flags.writeable
        assert image.std() > 0.5  # a pattern, not a flat colour
        assert 150 < image.mean() < 250  # bright detail maps: materials multiply a colour
    digests = {im.tobytes() for im in images}
    assert len(digests) == len(images)


@pytest.mark.parametrize("kind", sorted(TEXTURE_KINDS))
def test_textures_tile_seamlessly(kind: str) -> None:
    """The jump across the image's wrap-around edge is no larger than jumps inside it."""
    image = texture_image(kind, 0, 128).astype(np.float64)[..., 0]
    inside = np.abs(np.diff(image, axis=1)).max(axis=0)
    wrap = np.abs(image[:, 0] - image[:, -1])
    assert wrap.mean() <= inside.mean() * 1.5 + 1.0


def test_bad_texture_requests_are_refused() -> None:
    with pytest.raises(ConfigError, match="texture kind 'marble'"):
        texture_image("marble", 0, SIZE)
    with pytest.raises(ConfigError, match="variant 9"):
        texture_image("wood", 9, SIZE)
    with pytest.raises(ConfigError, match="power of two"):
        texture_image("wood", 0, 100)


def test_every_catalog_class_maps_to_a_texture_kind() -> None:
    assert set(CLASS_TEXTURES) <= set(CATALOG.names())
    for name in CATALOG.names():
        assert name in CLASS_TEXTURES, name
        assert body_texture(name) in TEXTURE_KINDS
    assert body_texture("Teacup") in TEXTURE_KINDS  # a user's class gets the default
    assert structure_texture("Floor", "kitchen") == "tiles"
    assert structure_texture("Floor", "bedroom") == "wood"
    assert structure_texture("Walls", "bedroom") == "plaster"
    assert part_texture(METAL, "wood") == ("metal", False)
    f32 = tuple(float(np.float32(c)) for c in DARK)  # as read back from USD
    assert part_texture(f32, "fabric") == ("smooth", False)
    assert part_texture((0.4, 0.3, 0.2), "fabric") == ("fabric", True)


@pytest.mark.parametrize("name", ["DiningTable", "Fridge", "Sofa", "Mug", "Apple", "Chair"])
def test_uvs_of_catalog_shapes_are_box_projections_in_metres(name: str) -> None:
    spec = CATALOG[name]
    vertices, faces, _ = merged_mesh(build_shape(spec.shape, spec.size_max, 0, spec.palette[0]))
    uvs = box_uvs(vertices, faces)
    assert uvs.shape == (len(faces), 3, 2) and uvs.dtype == np.float32
    assert np.isfinite(uvs).all()
    # metres: no coordinate leaves the object's own extent
    assert np.abs(uvs).max() <= max(spec.size_max) + 1e-5
    # the corners of a face lie where the projection puts them: distances are preserved on
    # axis-aligned faces (the longest edge in st equals the longest edge in space)
    tri = vertices[faces]
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    flat = np.isclose(np.abs(normal).max(axis=1), np.linalg.norm(normal, axis=1))
    edge_xyz = np.linalg.norm(tri[flat, 1] - tri[flat, 0], axis=1)
    edge_uv = np.linalg.norm(uvs[flat, 1] - uvs[flat, 0], axis=1)
    np.testing.assert_allclose(edge_uv, edge_xyz, atol=1e-5)


def test_a_unit_cube_face_spans_one_metre_of_texture() -> None:
    from sgdata.world.shapes.base import box

    mesh = box((1.0, 1.0, 1.0), (0.5, 0.5, 0.5), (1, 1, 1)).mesh
    uvs = box_uvs(np.asarray(mesh.vertices), np.asarray(mesh.faces))
    span = uvs.reshape(-1, 2).max(axis=0) - uvs.reshape(-1, 2).min(axis=0)
    np.testing.assert_allclose(span, [2.0, 1.0])  # s runs over [-1, 1] (mirrored faces), t [0, 1]


def _room() -> Room:
    from sgdata.world.rooms import generate_room

    return generate_room("living_room", 0, 3, CATALOG)


def test_layout_appearance_lies_in_its_ranges_and_differs_between_layouts() -> None:
    room = _room()
    config = AppearanceConfig(light_intensity=(0.6, 0.9), color_temperature=(3000, 5000), tint=0.2)
    draws = [sample_appearance(room, config, seed) for seed in range(6)]
    for d in draws:
        assert 0.6 <= d.light_intensity <= 0.9
        assert 3000 <= d.color_temperature <= 5000
        moving = {o.instance for o in room.objects if o.dynamics != Dynamics.STATIC}
        assert set(d.looks) == moving  # structure and static objects keep their base look
        for instance, look in d.looks.items():
            assert all(0.8 <= t <= 1.2 for t in look.tint)
            assert look.texture == body_texture(room.by_instance()[instance].class_name)
            assert 0 <= look.variant < TEXTURE_KINDS[look.texture].variants
    assert len({d.light_intensity for d in draws}) == len(draws)
    assert len({d.color_temperature for d in draws}) > 1
    assert draws[0] == sample_appearance(room, config, 0)  # same seed, same draw


def test_room_looks_come_from_the_room_seed() -> None:
    room = _room()
    looks = room_looks(room)
    assert looks == room_looks(room)
    assert set(looks.structure) == {"Floor", "Walls", "Ceiling"}
    assert looks.structure["Floor"].texture == "wood"
    assert set(looks.objects) == {o.instance for o in room.objects}


def test_light_colour_and_tint() -> None:
    assert light_color(6500.0) == (1.0, 1.0, 1.0)
    warm, cool = light_color(3000.0), light_color(9000.0)
    assert warm[2] < warm[1] < warm[0] == 1.0
    assert cool[0] < 1.0 and cool[2] >= 1.0
    assert tinted((0.5, 0.9, 0.2), (1.2, 1.2, 0.5)) == pytest.approx((0.6, 1.0, 0.1))
    with pytest.raises(ConfigError):
        light_color(500.0)


@pytest.mark.parametrize(
    ("kwargs", "needle"),
    [
        ({"light_intensity": (1.2, 0.8)}, "appearance.light_intensity"),
        ({"color_temperature": (500.0, 6500.0)}, "appearance.color_temperature"),
        ({"tint": 1.5}, "appearance.tint"),
        ({"texture_size": 300}, "appearance.texture_size"),
    ],
)
def test_appearance_config_refuses_bad_values(kwargs: dict, needle: str) -> None:
    with pytest.raises(ConfigError, match=needle):
        AppearanceConfig(**kwargs)
