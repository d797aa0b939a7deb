"""``sgdata assets add``: a class entry written for a folder of meshes, the measures printed."""

from __future__ import annotations

import os
import subprocess
import sys
import tomllib
from pathlib import Path

from tests.asset_meshes import write_demo_assets

SGDATA = [sys.executable, "-m", "sgdata_cli.sgdata_app"]


def run(*args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "COLUMNS": "160", "PYTHONPATH": str(Path(__file__).parents[2])}
    return subprocess.run(
        [*SGDATA, *args], capture_output=True, text=True, env=env, timeout=300, cwd=cwd
    )


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
