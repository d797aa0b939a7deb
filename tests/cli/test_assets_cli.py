"""``sgdata assets add``: a class entry written for a folder of meshes, the measures printed."""

from __future__ import annotations

import contextlib
import tomllib
from pathlib import Path

from tests.asset_meshes import write_demo_assets
from tests.cli_runner import Done, run_cli


def run(*args: str, cwd: Path) -> Done:
    """``sgdata args...`` in this process, from the folder ``cwd`` (its paths are relative)."""
    with contextlib.chdir(cwd):
        return run_cli("sgdata", *args, columns=160)


def test_assets_add_writes_the_entry_and_prints_the_measures(tmp_path: Path) -> None:
    write_demo_assets(tmp_path, catalog=False)
    folder = tmp_path / "mugs"
    folder.mkdir()
    for name in ("mug.obj", "mug.mtl", "material_0.png"):
        (tmp_path / "meshes" / name).rename(folder / name)
    done = run(
        "assets", "add", "mugs", "--class", "Mug", "--dynamics", "high",
        "--placement", "surface", cwd=tmp_path,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert "mug.obj" in done.stdout and "cm" in done.stdout and "0.104" in done.stdout
    entry = tomllib.loads((tmp_path / "catalog.toml").read_text())["classes"]["Mug"]
    assert entry["mesh"] == "mugs/*.obj"
    assert entry["dynamics"] == "high"


def test_a_new_class_gets_bounds_from_its_files(tmp_path: Path) -> None:
    write_demo_assets(tmp_path, catalog=False)
    folder = tmp_path / "plates"
    folder.mkdir()
    (tmp_path / "meshes/plate.stl").rename(folder / "plate.stl")
    done = run(
        "assets", "add", "plates", "--class", "Charger", "--dynamics", "high",
        "--placement", "surface", "--on", "DiningTable", cwd=tmp_path,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    entry = tomllib.loads((tmp_path / "catalog.toml").read_text())["classes"]["Charger"]
    assert entry["size_min"] == [0.216, 0.216, 0.018]
    assert entry["receptacles"] == ["DiningTable"]
    assert "appears: in no generated room" in done.stdout and "--rooms" in done.stdout
    # --rooms puts it into the kitchen recipe, and says where it will stand
    done = run(
        "assets", "add", "plates", "--class", "Charger", "--dynamics", "high",
        "--placement", "surface", "--on", "DiningTable", "--rooms", "kitchen:1-2", cwd=tmp_path,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    entry = tomllib.loads((tmp_path / "catalog.toml").read_text())["classes"]["Charger"]
    assert entry["rooms"] == {"kitchen": [1, 2]} and entry["max_instances"] == 2
    assert "appears: kitchen rooms (1-2 per room, on DiningTable)" in done.stdout
    done = run(
        "assets", "add", "plates", "--class", "Charger", "--dynamics", "high",
        "--placement", "surface", "--on", "DiningTable", "--rooms", "garage", cwd=tmp_path,
    )  # fmt: skip
    assert done.returncode == 2 and "'garage'" in done.stderr
    assert tomllib.loads((tmp_path / "catalog.toml").read_text())["classes"]["Charger"] == entry


def test_a_bad_mesh_is_one_line_and_leaves_the_catalog(tmp_path: Path) -> None:
    folder = tmp_path / "bad"
    folder.mkdir()
    (folder / "empty.obj").write_text("# nothing\n", encoding="utf-8")
    (tmp_path / "catalog.toml").write_text("# mine\n", encoding="utf-8")
    done = run("assets", "add", "bad", "--class", "Mug", cwd=tmp_path)
    assert done.returncode == 2
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and "empty.obj" in lines[0] and "no triangles" in lines[0]
    assert (tmp_path / "catalog.toml").read_text() == "# mine\n"


def test_a_new_class_of_implausible_size_is_refused_with_the_fix(tmp_path: Path) -> None:
    """An 800 m table as a new class is refused in one line naming the size and the units fix,
    and the catalog is left as it was (an override of a shipped class is refused alike)."""
    folder = tmp_path / "tables"
    folder.mkdir()
    corners = [(x, y, z) for x in (0, 800) for y in (0, 600) for z in (0, 500)]
    faces = ["1 2 4 3", "5 7 8 6", "1 5 6 2", "3 4 8 7", "1 3 7 5", "2 6 8 4"]
    (folder / "table.obj").write_text(
        "".join(f"v {x} {y} {z}\n" for x, y, z in corners) + "".join(f"f {f}\n" for f in faces)
    )
    (tmp_path / "catalog.toml").write_text("# mine\n", encoding="utf-8")
    done = run(
        "assets", "add", "tables", "--class", "LowTable", "--dynamics", "static",
        "--placement", "floor", "--units", "m", "--up", "z", cwd=tmp_path,
    )  # fmt: skip
    assert done.returncode == 2
    (line,) = done.stderr.strip().splitlines()
    assert "800 x 600 x 500 m looks wrong for a floor object (at most 5 m a side)" in line
    assert "--units mm or cm" in line
    assert (tmp_path / "catalog.toml").read_text() == "# mine\n"
