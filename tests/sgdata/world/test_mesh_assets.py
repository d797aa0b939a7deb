"""Mesh files as catalog classes: reading, units and axes, surfaces, bad assets, rooms."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import trimesh

from sgdata.errors import CatalogError
from sgdata.world.catalog import load_catalog
from sgdata.world.mesh_assets import (
    asset_files,
    class_assets,
    class_shape,
    orientation_warning,
)
from sgdata.world.rooms import generate_room
from sgdata.world.shapes import merged_mesh
from tests.asset_meshes import bowl, plate, table, write_demo_assets

DEMO = ("DiningTable", "Mug", "Bowl", "Plate")


@pytest.fixture(scope="module")
def demo(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("demo_assets")
    write_demo_assets(folder)
    return folder / "catalog.toml"


def _catalog_with(tmp_path: Path, entry: str, name: str = "Mug") -> Path:
    path = tmp_path / "user.toml"
    path.write_text(f"[classes.{name}]\n{entry}\n", encoding="utf-8")
    return path


def test_units_and_up_axes_are_measured(demo: Path) -> None:
    catalog = load_catalog(extra=[demo])
    found = {name: class_assets(catalog[name])[0] for name in DEMO}
    assert (found["DiningTable"].up, found["DiningTable"].units) == ("y", "m")  # glTF
    assert (found["Mug"].up, found["Mug"].units) == ("y", "cm")  # OBJ in cm
    assert (found["Bowl"].up, found["Bowl"].units) == ("z", "mm")  # PLY in mm
    assert (found["Plate"].up, found["Plate"].units) == ("z", "m")
    assert found["DiningTable"].size == (1.2, 0.8, 0.75)
    assert found["Mug"].size == pytest.approx((0.104, 0.08, 0.1), abs=1e-3)
    assert found["Bowl"].size == pytest.approx((0.16, 0.16, 0.06), abs=1e-3)
    for asset in found.values():  # the local frame: footprint centred, resting on z = 0
        lo, hi = asset.vertices.min(axis=0), asset.vertices.max(axis=0)
        assert lo[2] == pytest.approx(0.0) and (lo[:2] + hi[:2]) == pytest.approx([0, 0])


def test_overriding_a_class_keeps_its_rules_and_place_in_the_vocabulary(demo: Path) -> None:
    shipped = load_catalog()
    catalog = load_catalog(extra=[demo])
    assert catalog.names() == shipped.names()
    mug = catalog["Mug"]
    assert mug.mesh is not None and mug.variants == 1
    assert mug.receptacles == shipped["Mug"].receptacles
    assert mug.dynamics == shipped["Mug"].dynamics


def test_new_class_is_appended(tmp_path: Path) -> None:
    (tmp_path / "p.stl").write_bytes(plate().export(file_type="stl"))
    entry = (
        'mesh = "p.stl"\ndynamics = "high"\nplacement = "surface"\n'
        'receptacles = ["DiningTable"]\nsize_min = [0.2, 0.2, 0.01]\nsize_max = [0.3, 0.3, 0.03]'
    )
    catalog = load_catalog(extra=[_catalog_with(tmp_path, entry, "Charger")])
    assert catalog.names()[-1] == "Charger"
    assert catalog["Charger"].shape == "mesh"


def test_table_top_and_bowl_inside_are_support_surfaces(demo: Path) -> None:
    catalog = load_catalog(extra=[demo])
    (top,) = class_assets(catalog["DiningTable"])[0].surfaces
    assert (top.z, top.inside, top.clearance) == (0.75, False, np.inf)
    assert (top.x1 - top.x0, top.y1 - top.y0) == pytest.approx((1.2, 0.8))
    (inner,) = class_assets(catalog["Bowl"])[0].surfaces
    assert inner.inside and inner.z < 0.01
    assert inner.x1 - inner.x0 < 0.08  # on the flat bottom, not the rim's box
    (mug_inside,) = class_assets(catalog["Mug"])[0].surfaces  # the rim is a ring: no surface
    assert mug_inside.inside


def test_footprint_is_the_convex_hull(demo: Path) -> None:
    catalog = load_catalog(extra=[demo])
    hull = class_assets(catalog["Plate"])[0].footprint
    radius = np.hypot(hull[:, 0], hull[:, 1])
    assert len(hull) == 48 and radius == pytest.approx(0.12, abs=1e-3)


def test_colours_come_from_materials_vertex_colours_and_textures(demo: Path) -> None:
    catalog = load_catalog(extra=[demo])
    table = class_assets(catalog["DiningTable"])[0].face_colors
    assert {tuple(np.round(c * 255).astype(int)) for c in table} == {(150, 100, 60), (40, 40, 44)}
    bowl_colors = np.unique(class_assets(catalog["Bowl"])[0].face_colors, axis=0)
    assert np.round(bowl_colors * 255).astype(int).tolist() == [[60, 110, 170]]
    mug = np.unique(np.round(class_assets(catalog["Mug"])[0].face_colors * 255), axis=0)
    assert mug.tolist() == [[200, 40, 40], [240, 230, 220]]  # the checker texture's two colours


def test_geometry_is_scaled_to_the_object_size(demo: Path) -> None:
    spec = load_catalog(extra=[demo])["Plate"]
    vertices, faces, colors = merged_mesh(class_shape(spec, (0.48, 0.48, 0.04), 0, (1, 0, 0)))
    assert np.ptp(vertices, axis=0) == pytest.approx((0.48, 0.48, 0.04))
    assert len(faces) == len(colors) == class_assets(spec)[0].triangles


def test_rooms_place_mesh_classes_deterministically(demo: Path) -> None:
    catalog = load_catalog(extra=[demo])
    room = generate_room("kitchen", 0, 0, catalog)
    assert room == generate_room("kitchen", 0, 0, catalog)
    meshes = [o for o in room.objects if catalog[o.class_name].mesh is not None]
    assert {o.class_name for o in meshes} >= {"DiningTable", "Plate"}
    for obj in meshes:  # keep: the file's true size
        assert obj.size == pytest.approx(class_assets(catalog[obj.class_name])[0].size)
    by_id = room.by_instance()
    table = next(o for o in meshes if o.class_name == "DiningTable")
    on_table = [o for o in room.objects if o.support == table.instance]
    for obj in on_table:  # resting on the measured top
        assert obj.placement.z == pytest.approx(0.75)
        assert by_id[obj.support].class_name == "DiningTable"


def test_fit_scales_into_the_bounds(tmp_path: Path) -> None:
    (tmp_path / "b.ply").write_bytes(bowl(radius=0.3, height=0.2).export(file_type="ply"))
    path = _catalog_with(tmp_path, 'mesh = "b.ply"\nscale = "fit"\nunits = "m"', "Bowl")
    spec = load_catalog(extra=[path])["Bowl"]
    size = class_assets(spec)[0].size
    bounds = zip(size, spec.size_min, spec.size_max, strict=True)
    assert all(lo - 1e-3 <= s <= hi + 1e-3 for s, lo, hi in bounds)


def test_asset_files_hash_meshes_and_textures(demo: Path) -> None:
    names = [Path(p).name for p, _ in asset_files(load_catalog(extra=[demo]))]
    assert names == ["bowl.ply", "material_0.png", "mug.obj", "plate.stl", "table.glb"]


def test_same_files_same_bytes(tmp_path: Path) -> None:
    a, b = write_demo_assets(tmp_path / "a"), write_demo_assets(tmp_path / "b")
    assert [p.read_bytes() for p in a] == [p.read_bytes() for p in b]


# ------------------------------------------------------------------------- bad assets


def _refusal(tmp_path: Path, name: str, data: bytes | str, entry: str = "") -> str:
    path = tmp_path / name
    path.write_bytes(data if isinstance(data, bytes) else data.encode())
    user = _catalog_with(tmp_path, f'mesh = "{name}"\n{entry}', "Plate")
    with pytest.raises(CatalogError) as info:
        class_assets(load_catalog(extra=[user])["Plate"])
    message = str(info.value)
    assert "\n" not in message
    return message


def _obj(vertices: list[str], faces: list[str]) -> str:
    return "".join(f"v {v}\n" for v in vertices) + "".join(f"f {f}\n" for f in faces)


def test_empty_mesh(tmp_path: Path) -> None:
    assert "holds no triangles" in _refusal(tmp_path, "e.obj", "# nothing\n")


def test_an_empty_file_is_named_as_such_not_by_the_readers_index_error(tmp_path: Path) -> None:
    message = _refusal(tmp_path, "e.glb", b"")
    assert message.endswith("e.glb: the file is empty (0 bytes); re-export it"), message


def test_nan_vertices(tmp_path: Path) -> None:
    text = _obj(["0 0 0", "nan 0 0", "0 1 0", "1 1 1"], ["1 2 3", "1 3 4"])
    message = _refusal(tmp_path, "n.obj", text)
    assert "n.obj" in message and "NaN" in message


def test_degenerate_faces(tmp_path: Path) -> None:
    text = _obj(["0 0 0", "1 0 0", "2 0 0", "0 1 0"], ["1 2 3", "1 3 2", "1 2 4"])
    assert "no area" in _refusal(tmp_path, "d.obj", text)


def test_a_one_kilometre_mesh(tmp_path: Path) -> None:
    mesh = plate()
    mesh.apply_scale(1000 / 0.24)  # 1 km across, in metres
    message = _refusal(tmp_path, "k.stl", mesh.export(file_type="stl"), 'units = "m"')
    assert "k.stl" in message and "measures 1000" in message and 'scale = "fit"' in message


def test_missing_texture(tmp_path: Path) -> None:
    (tmp_path / "t.mtl").write_text("newmtl a\nmap_Kd gone.png\n", encoding="utf-8")
    text = "mtllib t.mtl\n" + _obj(["0 0 0", "0.2 0 0", "0 0.2 0", "0 0 0.02"], ["1 2 3", "1 2 4"])
    message = _refusal(tmp_path, "t.obj", text)
    assert "texture 'gone.png'" in message and "t.obj" in message


def test_unknown_format(tmp_path: Path) -> None:
    assert "unknown mesh format '.fbx'" in _refusal(tmp_path, "x.fbx", b"\0\1\2")


def test_glob_matching_nothing(tmp_path: Path) -> None:
    user = _catalog_with(tmp_path, 'mesh = "nowhere/*.glb"')
    with pytest.raises(CatalogError, match="matches no file"):
        load_catalog(extra=[user])


def test_unreadable_file(tmp_path: Path) -> None:
    assert "cannot read the mesh" in _refusal(tmp_path, "bad.glb", b"not a glb at all")


def test_recipe_fields_are_refused_on_a_mesh_class(tmp_path: Path) -> None:
    (tmp_path / "p.stl").write_bytes(plate().export(file_type="stl"))
    user = _catalog_with(tmp_path, 'mesh = "p.stl"\nshape = "plate"')
    with pytest.raises(CatalogError, match="'shape' is for recipe classes"):
        load_catalog(extra=[user])


def test_the_up_axis_is_said_glb_by_its_format_obj_measured(tmp_path: Path) -> None:
    """One Z-up table written as .glb (glTF is Y up by its specification, so the file is
    read as such, never guessed) and as .obj (no convention: measured). Either both come out
    with one up axis, or the class gets a warning naming each file's axis and its source."""
    geometry = trimesh.util.concatenate(table())
    folder = tmp_path / "tables"
    folder.mkdir()
    (folder / "table.glb").write_bytes(geometry.export(file_type="glb"))
    (folder / "table.obj").write_text(geometry.export(file_type="obj"), encoding="utf-8")
    entry = 'mesh = "tables/table.*"'
    catalog = load_catalog(extra=[_catalog_with(tmp_path, entry, "DiningTable")])
    glb, obj = sorted(class_assets(catalog["DiningTable"]), key=lambda a: a.path)
    assert (glb.up, glb.up_from) == ("y", "format")
    assert obj.up_from == "measured"
    warning = orientation_warning("DiningTable", (glb, obj))
    if glb.up == obj.up:
        assert warning is None
    else:
        assert warning is not None
        assert "table.glb: Y (format)" in warning and f"table.obj: {obj.up.upper()}" in warning
    # an axis the class entry gives is taken as given, for every file
    given = load_catalog(extra=[_catalog_with(tmp_path, entry + '\nup = "z"', "DiningTable")])
    assets = class_assets(given["DiningTable"])
    assert {(a.up, a.up_from) for a in assets} == {("z", "given")}
    assert orientation_warning("DiningTable", assets) is None
