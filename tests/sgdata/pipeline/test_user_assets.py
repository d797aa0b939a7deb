"""``sgdata generate`` with ``[catalog] files``: mesh-file classes placed, rendered, annotated
and recorded (sha256 in the manifest, ``validate --sources``), and bad assets refused first."""

from __future__ import annotations

import hashlib
import io
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest
from PIL import Image

from sgdata.pipeline.config import load_config
from tests.asset_meshes import write_demo_assets

from ...cli_runner import run_cli

SGDATA = [sys.executable, "-m", "sgdata_cli.sgdata_app"]

CONFIG = """\
[dataset]
name = "assets-demo"
seed = 0

[rooms]
types = ["kitchen"]
train = 1
val = 0
test = 0

[layouts]
count = 2

[triplets]
train = 10
val = 0
test = 0

[outputs]
instances = true

[catalog]
files = ["catalog.toml"]
"""
# a new class (none of the shipped ones) that the kitchen recipe places, two per room
NEW_CLASS = """
[classes.Charger]
mesh = "meshes/plate*.stl"
dynamics = "high"
placement = "surface"
receptacles = ["CounterTop", "DiningTable"]
size_min = [0.2, 0.2, 0.01]
size_max = [0.3, 0.3, 0.03]
max_instances = 2
rooms = { kitchen = [2, 2] }
"""


def run(*args: str, hash_seed: str = "0") -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "COLUMNS": "160", "PYTHONHASHSEED": hash_seed}
    return subprocess.run([*SGDATA, *args], capture_output=True, text=True, env=env, timeout=600)


def digest_tree(root: Path) -> dict[str, str]:
    return {
        p.relative_to(root).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(root.rglob("*"))
        if p.is_file() and ".ledger" not in p.parts
    }


@pytest.mark.slow  # sgdata generate of rooms holding mesh-file classes, in a subprocess
def test_generate_with_mesh_classes_end_to_end(tmp_path: Path) -> None:
    project = tmp_path / "project"
    write_demo_assets(project)
    with open(project / "catalog.toml", "a", encoding="utf-8") as catalog:
        catalog.write(NEW_CLASS)
    config = project / "config.toml"
    config.write_text(CONFIG, encoding="utf-8")
    one, two = tmp_path / "one", tmp_path / "two"
    done = run("generate", str(config), str(one), "--workers", "1", hash_seed="1")
    assert done.returncode == 0, done.stderr
    done = run("generate", str(config), str(two), "--workers", "1", hash_seed="2")
    assert done.returncode == 0, done.stderr
    assert digest_tree(one) == digest_tree(two)  # same files + seed: same bytes

    manifest = json.loads((one / "dataset.json").read_text())
    assets = {a["path"]: a["sha256"] for a in manifest["config"]["catalog"]["assets"]}
    assert set(assets) == {
        "catalog.toml",
        "meshes/bowl.ply",
        "meshes/material_0.png",
        "meshes/mug.obj",
        "meshes/plate.stl",
        "meshes/table.glb",
    }
    for rel, digest in assets.items():
        assert hashlib.sha256((project / rel).read_bytes()).hexdigest() == digest

    rows = pq.read_table(one / "observations/train/kitchen_000.parquet").to_pylist()
    on = manifest["relation_types"].index("on")
    seen_on_table = 0
    for row in rows:
        objects = {o["instance"]: o for o in row["objects"]}
        relations = {(r["src"], r["dst"], r["type"]) for r in row["relations"]}
        for obj in objects.values():
            support = objects.get(obj["support"])
            if support is not None and support["class_name"] == "DiningTable":
                assert (obj["instance"], support["instance"], on) in relations
                seen_on_table += 1
    assert seen_on_table > 0  # things rest on the mesh table's measured top
    # the new class is in the room and in views, with a box and its own mask pixels
    chargers = [
        (row, k)
        for row in rows
        for k, o in enumerate(row["objects"])
        if o["class_name"] == "Charger"
    ]
    assert chargers, "the new class appears in no view"
    for row, k in chargers:
        u1, v1, u2, v2 = row["objects"][k]["box2d"]
        mask = np.asarray(Image.open(io.BytesIO(row["instances"]["bytes"])))
        rows_, cols = np.nonzero(mask == k + 1)
        assert len(rows_) == row["objects"][k]["visible_pixels"]
        assert (cols.min(), rows_.min(), cols.max() + 1, rows_.max() + 1) == (u1, v1, u2, v2)

    # relations re-computable from the stored boxes and supports (every pair agrees)
    checked = run_cli("sgdata", "validate", str(one), "--sources", str(project))
    assert checked.returncode == 0, checked.stdout + checked.stderr
    assert "sources.unchanged" in checked.stdout

    # a view of a layout, checked and annotated with the config's catalog (its mesh classes)
    for layout in ("0", "1"):
        view = run_cli(
            "sgdata", "render", str(one / "scenes" / "kitchen_000"), "--layout", layout,
            "--config", str(config), "-o", str(tmp_path / f"view_{layout}.png"),
        )  # fmt: skip
        assert view.returncode == 0, view.stderr
        assert (tmp_path / f"view_{layout}.png").is_file()

    with open(project / "meshes/plate.stl", "ab") as handle:
        handle.write(b"\n")
    changed = run_cli("sgdata", "validate", str(one), "--quick", "--sources", str(project))
    assert changed.returncode != 0
    assert "meshes/plate.stl" in changed.stdout and "changed since" in changed.stdout


def test_a_bad_asset_stops_the_run_before_anything_is_written(tmp_path: Path) -> None:
    project = tmp_path / "project"
    write_demo_assets(project)
    (project / "meshes/plate.stl").unlink()
    (project / "meshes/plate_nan.obj").write_text(
        "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n", encoding="utf-8"
    )
    catalog = project / "catalog.toml"
    catalog.write_text(
        catalog.read_text().replace("meshes/plate*.stl", "meshes/plate*.obj"), encoding="utf-8"
    )
    config = project / "config.toml"
    config.write_text(CONFIG, encoding="utf-8")
    out = tmp_path / "out"
    done = run("generate", str(config), str(out), "--workers", "1")
    assert done.returncode == 2
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and "plate_nan.obj" in lines[0] and "NaN" in lines[0]
    assert not out.exists()


def test_the_demo_config_names_the_demo_catalog() -> None:
    config = load_config(Path(__file__).parents[3] / "configs" / "assets.toml")
    assert config.catalog.files == ("demo_assets/catalog.toml",)
    assert config.catalog.paths()[0].parent.name == "demo_assets"


def test_a_new_class_no_room_recipe_places_is_warned_about(tmp_path: Path) -> None:
    project = tmp_path / "project"
    write_demo_assets(project)
    with open(project / "catalog.toml", "a", encoding="utf-8") as catalog:
        catalog.write(NEW_CLASS.replace("rooms = { kitchen = [2, 2] }\n", ""))
    config = project / "config.toml"
    config.write_text(CONFIG, encoding="utf-8")
    out = tmp_path / "out"
    out.mkdir()
    (out / "dataset.json").write_text("{}")  # generate refuses it: only the warning runs
    done = run("generate", str(config), str(out))
    assert done.returncode == 2
    assert "warning: class Charger is in your catalog but no room recipe places it" in " ".join(
        done.stdout.split()
    )
