"""Room generator: believable, deterministic, physically valid rooms of every type."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import open3d as o3d
import pytest
import trimesh

from sgdata.errors import ConfigError
from sgdata.usd.room_io import read_room
from sgdata.usd.scene_dirs import write_rooms
from sgdata.usd.stage import validate_stage
from sgdata.world.catalog import Catalog
from sgdata.world.placement import ancestors
from sgdata.world.room_checks import room_problems
from sgdata.world.room_recipes import ROOM_TYPES, load_room_recipes
from sgdata.world.rooms import generate_room
from sgdata.world.scene import Room, SceneObject
from sgdata.world.shapes import build_shape


def test_same_seed_same_room(catalog: Catalog, kitchen: Room) -> None:
    assert generate_room("kitchen", 0, 0, catalog) == kitchen
    assert generate_room("kitchen", 0, 1, catalog) != kitchen
    assert generate_room("kitchen", 1, 0, catalog) != kitchen


def test_same_seed_byte_identical_usda(tmp_path: Path, catalog: Catalog) -> None:
    write_rooms(tmp_path / "a", "bathroom", count=2, seed=7, catalog=catalog)
    write_rooms(tmp_path / "b", "bathroom", count=2, seed=7, catalog=catalog)
    for name in ("bathroom_000", "bathroom_001"):
        first = (tmp_path / "a" / name / "room.usda").read_bytes()
        assert first == (tmp_path / "b" / name / "room.usda").read_bytes()


@pytest.mark.parametrize("room_type", ROOM_TYPES)
def test_rooms_hold_signature_classes_and_enough_objects(
    room_type: str, rooms_by_type: dict[str, list[Room]], catalog: Catalog
) -> None:
    signature = load_room_recipes(catalog)[room_type].signature
    for room in rooms_by_type[room_type]:
        classes = {o.class_name for o in room.objects}
        assert set(signature) <= classes, f"{room.room_id} lacks {set(signature) - classes}"
        assert 20 <= len(room.objects) <= 80, f"{room.room_id} has {len(room.objects)} objects"


@pytest.mark.parametrize("room_type", ROOM_TYPES)
def test_rooms_are_physically_valid(
    room_type: str, rooms_by_type: dict[str, list[Room]], catalog: Catalog
) -> None:
    for room in rooms_by_type[room_type]:
        assert room_problems(room, catalog) == []
        ids = [o.instance for o in room.objects]
        assert len(ids) == len(set(ids))
        for obj in room.objects:
            assert obj.instance > 0
            count = sum(o.class_name == obj.class_name for o in room.objects)
            assert count <= catalog[obj.class_name].max_instances


def _world_parts(obj: SceneObject, catalog: Catalog) -> list[trimesh.Trimesh]:
    build = build_shape(catalog[obj.class_name].shape, obj.size, obj.variant, obj.color)
    matrix = obj.placement.matrix()
    return [part.mesh.copy().apply_transform(matrix) for part in build.parts]


def _inside_any(meshes: list[trimesh.Trimesh], points: np.ndarray) -> np.ndarray:
    """Which points lie inside any of the closed meshes (open3d ray-parity occupancy)."""
    inside = np.zeros(len(points), dtype=bool)
    query = o3d.core.Tensor(points.astype(np.float32))
    for mesh in meshes:
        scene = o3d.t.geometry.RaycastingScene()
        scene.add_triangles(
            o3d.core.Tensor(np.asarray(mesh.vertices, dtype=np.float32)),
            o3d.core.Tensor(np.asarray(mesh.faces, dtype=np.uint32)),
        )
        inside |= scene.compute_occupancy(query).numpy() > 0.5
    return inside


def _attached_lineage(obj: SceneObject, by_instance: dict[int, SceneObject]) -> set[int]:
    out, current = set(), obj
    while current.attached_to is not None:
        out.add(current.attached_to)
        current = by_instance[current.attached_to]
    return out


@pytest.mark.parametrize("room_type", ROOM_TYPES)
def test_real_meshes_do_not_interpenetrate(
    room_type: str, rooms_by_type: dict[str, list[Room]], catalog: Catalog
) -> None:
    """Sample points inside every part of every object; none may lie inside another object's
    parts, except an attached part and its owner (a basin recessed into its sink) and an
    object with its container."""
    room = rooms_by_type[room_type][0]
    by_instance = room.by_instance()
    rng = np.random.default_rng(0)
    parts = {o.instance: _world_parts(o, catalog) for o in room.objects}
    boxes = {o.instance: o.world_aabb() for o in room.objects}
    offenders = []
    for a in room.objects:
        # points well inside a's parts: shrink each part's samples toward its centroid
        samples = []
        for mesh in parts[a.instance]:
            lo, hi = mesh.bounds
            points = rng.uniform(lo, hi, size=(240, 3))
            points = points[_inside_any([mesh], points)][:60]
            if len(points):
                samples.append(mesh.centroid + 0.8 * (points - mesh.centroid))
        if not samples:
            continue
        points = np.concatenate(samples)
        for b in room.objects:
            if b.instance == a.instance:
                continue
            lo, hi = boxes[b.instance]
            near = np.all((points >= lo) & (points <= hi), axis=1)
            if not near.any():
                continue
            related = _attached_lineage(a, by_instance) | _attached_lineage(b, by_instance)
            if b.instance in related or a.instance in related:
                continue
            if (
                b.instance in ancestors(a, by_instance)
                and b.class_name in catalog[a.class_name].containers
            ):
                continue
            inside = _inside_any(parts[b.instance], points[near])
            if inside.mean() > 0.02:
                offenders.append((a.prim_name, b.prim_name, round(float(inside.mean()), 3)))
    assert offenders == []


def test_usd_round_trip(tmp_path: Path, catalog: Catalog) -> None:
    (room,) = write_rooms(tmp_path, "living_room", count=1, seed=3, catalog=catalog)
    back = read_room(tmp_path / room.room_id / "room.usda")
    assert back.room_id == room.room_id and back.seed == room.seed and back.door == room.door
    assert [o.instance for o in back.objects] == [o.instance for o in room.objects]
    for a, b in zip(room.objects, back.objects, strict=True):
        assert (a.class_name, a.support, a.attached_to, a.variant) == (
            b.class_name,
            b.support,
            b.attached_to,
            b.variant,
        )
        assert np.allclose(a.placement.matrix(), b.placement.matrix(), atol=1e-6)
        assert np.allclose(a.size, b.size, atol=1e-6)


def test_generated_stages_pass_usd_validators(tmp_path: Path, catalog: Catalog) -> None:
    for room_type in ROOM_TYPES:
        (room,) = write_rooms(tmp_path, room_type, count=1, seed=2, catalog=catalog)
        assert validate_stage(tmp_path / room.room_id / "room.usda") == []


def test_bad_arguments_raise_config_errors(tmp_path: Path, catalog: Catalog) -> None:
    with pytest.raises(ConfigError, match="unknown room type 'garage'"):
        generate_room("garage", 0, 0, catalog)
    with pytest.raises(ConfigError, match="--count must be >= 1"):
        write_rooms(tmp_path / "x", "kitchen", count=0, seed=0, catalog=catalog)
    a_file = tmp_path / "file.txt"
    a_file.write_text("x")
    with pytest.raises(ConfigError, match="is a file"):
        write_rooms(a_file, "kitchen", count=1, seed=0, catalog=catalog)
    assert not (tmp_path / "x").exists()
