"""bench/assets.py: the mesh room it measures (30 objects of ~20k triangles, the same room)."""

from __future__ import annotations

from pathlib import Path

from sgdata.world.catalog import load_catalog
from sgdata.world.mesh_assets import class_assets
from sgdata.world.rooms import generate_room

from ..bench_scripts import load_bench


def test_the_mesh_room_has_thirty_heavy_objects(tmp_path: Path) -> None:
    bench = load_bench("assets")
    shipped = load_catalog()
    room = generate_room("kitchen", 0, 0, shipped)
    chosen = bench.write_meshes(room, shipped, tmp_path)
    assert sum(1 for o in room.objects if o.class_name in chosen) == bench.MESH_OBJECTS
    meshes = load_catalog(extra=[tmp_path / "catalog.toml"])
    for name in chosen[:3]:  # each file reads as its class, at its true size within bounds
        (asset,) = class_assets(meshes[name])
        assert 20_000 <= asset.triangles <= 21_000
        assert meshes[name].mesh.max_triangles == 2000
    assert meshes.names() == shipped.names()  # overrides: the vocabulary is unchanged
