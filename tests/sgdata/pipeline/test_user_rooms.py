"""``sgdata generate`` over ``[rooms] files``: hand-written USD rooms made a dataset, end to end."""

from __future__ import annotations

import hashlib
import json
import os
import subprocess
import sys
from pathlib import Path

import pyarrow.parquet as pq
import pytest
from pxr import Sdf, Usd, UsdGeom

from sgdata.errors import ConfigError, UsdError
from sgdata.pipeline.config import GenerateConfig, RoomsConfig, config_to_dict, load_config
from sgdata.pipeline.generate import LEDGER, plan_rooms
from sgdata.pipeline.user_rooms import resolve_user_rooms

from ...cli_runner import run_cli
from ..usd.user_stages import write_user_room

SGDATA = [sys.executable, "-m", "sgdata_cli.sgdata_app"]
MUG_IN_OPT = "/Room/Furniture/Dining/Table/Mug"  # the nested room's mug, a child of its table

# three rooms, one per split: Z-up metres meshes (a bare path), Y-up centimetres gprims under
# nested Xforms, and one with the optional attributes, no door and its mug called a Teacup
CONFIG = """\
[dataset]
name = "own-rooms"
seed = 3

[rooms]
files = [
    "rooms/kitchen corner.usda",
    { path = "rooms/yup.usda", split = "val" },
    { path = "rooms/opt.usda", split = "test", id = "flat-7", type = "kitchen" },
]
classes = "classes.toml"

[layouts]
count = 2

[camera]
width = 96
height = 96

[annotation]
min_visible_pixels = 4

[triplets]
train = 24
val = 10
test = 10
"""


def sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def digest_tree(root: Path) -> dict[str, str]:
    """sha256 of every file of a dataset (the ledger excluded)."""
    return {
        p.relative_to(root).as_posix(): sha256(p)
        for p in sorted(root.rglob("*"))
        if p.is_file() and LEDGER not in p.parts
    }


def set_class(path: Path, prim: str, name: str) -> None:
    stage = Usd.Stage.Open(str(path))
    stage.GetPrimAtPath(prim).GetAttribute("sgdata:class").Set(name)
    stage.GetRootLayer().Save()


def write_project(folder: Path) -> Path:
    """The user's folder: three rooms, a class file and the config; returns the config."""
    rooms = folder / "rooms"
    rooms.mkdir(parents=True)
    write_user_room(rooms / "kitchen corner.usda")
    write_user_room(rooms / "yup.usda", up="Y", mpu=0.01, gprims=True, nested=True)
    opt = write_user_room(rooms / "opt.usda", optional=True, door=False, nested=True)
    set_class(opt, MUG_IN_OPT, "Teacup")
    (folder / "classes.toml").write_text('[classes]\nTeacup = "Mug"\n')
    config = folder / "own.toml"
    config.write_text(CONFIG)
    return config


def run(*args: str, hash_seed: str = "0") -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "COLUMNS": "120", "PYTHONHASHSEED": hash_seed}
    return subprocess.run([*SGDATA, *args], capture_output=True, text=True, env=env, timeout=600)


def test_generate_user_rooms_end_to_end(tmp_path: Path) -> None:
    config = write_project(tmp_path / "project")
    sources = sorted((tmp_path / "project").rglob("*.usda")) + [tmp_path / "project/classes.toml"]
    before = {p: sha256(p) for p in sources}
    one, two = tmp_path / "one", tmp_path / "two"
    done = run("generate", str(config), str(one), "--workers", "1", hash_seed="1")
    assert done.returncode == 0, done.stderr
    done = run("generate", str(config), str(two), "--workers", "2", hash_seed="2")
    assert done.returncode == 0, done.stderr
    assert {p: sha256(p) for p in sources} == before  # the user's files: byte-unchanged
    assert digest_tree(one) == digest_tree(two)  # whatever the workers and hash seed
    assert not any(str(tmp_path) in p.read_text() for p in one.rglob("*.usda"))

    checked = run_cli("sgdata", "validate", str(one), "--usd", "--sources", str(config.parent))
    assert checked.returncode == 0, checked.stdout + checked.stderr
    assert "clean" in checked.stdout and "sources.unchanged" in checked.stdout

    manifest = json.loads((one / "dataset.json").read_text())
    assert manifest["splits"] == {"train": ["kitchen_corner"], "val": ["yup"], "test": ["flat-7"]}
    entries = manifest["config"]["rooms"]["files"]
    assert [(e["path"], e["split"], e["id"], e["type"]) for e in entries] == [
        ("rooms/kitchen corner.usda", "train", "kitchen_corner", "custom"),
        ("rooms/yup.usda", "val", "yup", "custom"),
        ("rooms/opt.usda", "test", "flat-7", "kitchen"),
    ]
    for entry in entries:
        assert entry["sha256"] == before[tmp_path / "project" / entry["path"]]
    listed = {f["path"] for f in manifest["files"]}
    for room in ("kitchen_corner", "yup", "flat-7"):
        scene = ("source.usda", "room.usda", "layout_0.usda", "layout_1.usda")
        assert {f"scenes/{room}/{name}" for name in scene} <= listed

    on = manifest["relation_types"].index("on")
    for split, room in (("train", "kitchen_corner"), ("val", "yup"), ("test", "flat-7")):
        rows = pq.read_table(one / f"observations/{split}/{room}.parquet").to_pylist()
        assert {r["room_type"] for r in rows} == {"kitchen" if room == "flat-7" else "custom"}
        mug_on_table = 0
        for row in rows:
            objects = {o["instance"]: o for o in row["objects"]}
            classes = {o["class_name"] for o in objects.values()}
            assert "Teacup" not in classes  # the alias was read as the catalog's Mug
            relations = {(r["src"], r["dst"], r["type"]) for r in row["relations"]}
            for mug in (o for o in objects.values() if o["class_name"] == "Mug"):
                table = objects.get(mug["support"])
                if table is not None and table["class_name"] == "DiningTable":
                    assert (mug["instance"], table["instance"], on) in relations
                    mug_on_table += 1
        assert mug_on_table > 0, room

    # the user edits a room afterwards: validate --sources names it, the dataset itself is fine
    with open(config.parent / "rooms" / "yup.usda", "a") as handle:
        handle.write("\n")
    checked = run_cli(
        "sgdata", "validate", str(one), "--quick", "--sources", str(config.parent), "--json"
    )
    assert checked.returncode == 1, checked.stdout + checked.stderr
    problems = json.loads(checked.stdout)["problems"]
    assert [(p["check"], p["field"]) for p in problems] == [
        ("sources.unchanged", "config.rooms.files[1]")
    ]
    assert "'rooms/yup.usda' changed since the dataset was made" in problems[0]["message"]


FRIDGE_BODY = "/Room/Fridge/Body"


def set_points(path: Path, prim: str, k: int, value: float) -> None:
    """Set every coordinate of point ``k`` of a mesh to ``value``."""
    stage = Usd.Stage.Open(str(path))
    attr = UsdGeom.Mesh(stage.GetPrimAtPath(prim)).GetPointsAttr()
    points = list(attr.Get())
    points[k] = (value, value, value)
    attr.Set(points)
    stage.GetRootLayer().Save()


def write_bad_project(folder: Path, case: str) -> Path:
    config = write_project(folder)
    rooms = folder / "rooms"
    text = CONFIG
    if case == "missing file":
        text = text.replace("rooms/yup.usda", "rooms/nope.usda")
    elif case == "no class prim":
        stage = Usd.Stage.CreateInMemory()
        UsdGeom.Cube.Define(stage, "/Room/Box")
        stage.GetRootLayer().Export(str(rooms / "yup.usda"))
    elif case == "unknown class":
        set_class(rooms / "kitchen corner.usda", "/Room/Mug", "Saucer")
    elif case == "class file missing":
        text = text.replace('"classes.toml"', '"nope.toml"')
    elif case == "alias of no catalog class":
        (folder / "classes.toml").write_text('Teacup = "Cupp"\n')
    elif case == "bad split":
        text = text.replace('split = "val"', 'split = "dev"')
    elif case == "not usd":
        (rooms / "yup.usda").write_text("this is not USD\n")
    elif case == "nan in a mesh":  # crashed generate with OverflowError (issue 26)
        set_points(rooms / "kitchen corner.usda", "/Room/Things/Table/Top", 3, float("nan"))
    elif case == "face index past the points":  # was "has no geometry to measure" (issue 26)
        stage = Usd.Stage.Open(str(rooms / "opt.usda"))
        attr = UsdGeom.Mesh(stage.GetPrimAtPath(FRIDGE_BODY)).GetFaceVertexIndicesAttr()
        indices = list(attr.Get())
        indices[5] = 8  # the box has points 0..7
        attr.Set(indices)
        stage.GetRootLayer().Save()
    elif case == "centimetres at metersPerUnit 1":  # was a 400 m room (issue 26)
        stage = Usd.Stage.Open(str(rooms / "yup.usda"))
        UsdGeom.SetStageMetersPerUnit(stage, 1.0)
        stage.GetRootLayer().Save()
    config.write_text(text)
    return config


BAD = {
    "missing file": "rooms.files[1] 'rooms/nope.usda': no such file",
    "no class prim": "yup.usda: no prim carries sgdata:class",
    "unknown class": "/Room/Mug sgdata:class 'Saucer' is not a catalog class",
    "class file missing": "rooms.classes: ",
    "alias of no catalog class": "class 'Teacup' is 'Cupp'; expected",
    "bad split": "rooms/yup.usda': split 'dev'; expected one of",
    "not usd": "rooms.files[1]: ",
    "nan in a mesh": "/Room/Things/Table/Top points[3] is (nan, ",
    "face index past the points": "/Room/Fridge/Body faceVertexIndices[5] is 8, past the mesh's 8",
    "centimetres at metersPerUnit 1": (
        "yup.usda: /Room measures 400 x 300 x 250 m with the stage's metersPerUnit 1 and "
        "upAxis Y; a home's room is at most 30 m a side: if the file is in centimetres set its "
        "metersPerUnit = 0.01"
    ),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_input_is_one_line_and_writes_nothing(
    tmp_path: Path, case: str, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    from sgdata_cli.sgdata_app import main  # the console script's own entry point

    config = write_bad_project(tmp_path / "project", case)
    users = {p: sha256(p) for p in (tmp_path / "project").rglob("*") if p.is_file()}
    out = tmp_path / "out"
    monkeypatch.setattr(sys, "argv", ["sgdata", "generate", str(config), str(out)])
    with pytest.raises(SystemExit) as exited:
        main()
    assert exited.value.code == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("sgdata: error: "), lines
    assert BAD[case] in lines[0]
    assert not out.exists()
    assert {p: sha256(p) for p in (tmp_path / "project").rglob("*") if p.is_file()} == users


def test_files_parse_plan_and_mix_with_procedural_rooms(tmp_path: Path) -> None:
    config = tmp_path / "mix.toml"
    config.write_text(
        '[rooms]\ntypes = ["bathroom"]\ntrain = 1\nval = 0\ntest = 1\n'
        'files = ["a/b/my room.usda", { path = "/abs/c.usda", split = "test", id = "c" }]\n'
    )
    loaded = load_config(config)
    assert loaded.rooms.base_dir == str(tmp_path)
    assert loaded.rooms.resolve("a/b/my room.usda") == tmp_path / "a/b/my room.usda"
    assert loaded.rooms.resolve("/abs/c.usda") == Path("/abs/c.usda")
    plan = [(t.room_id, t.split) for t in plan_rooms(loaded)]
    assert plan == [("bathroom_000", "train"), ("bathroom_001", "test"), ("my_room", "train"),
                    ("c", "test")]  # fmt: skip
    # files alone: no procedural rooms unless types are given
    only = RoomsConfig(files=loaded.rooms.files)
    assert only.types == ()
    assert [t.room_id for t in plan_rooms(GenerateConfig(rooms=only))] == ["my_room", "c"]
    assert RoomsConfig().types == ("kitchen", "living_room", "bedroom", "bathroom")
    with pytest.raises(ConfigError, match="both get room id 'c'"):
        config.write_text('[rooms]\nfiles = ["x/c.usda", "y/c.usda"]\n')
        load_config(config)
    with pytest.raises(ConfigError, match="unknown key 'rooms.files\\[0\\].base_dir'"):
        config.write_text('[rooms]\nfiles = [{ path = "c.usda", base_dir = "/" }]\n')
        load_config(config)
    with pytest.raises(ConfigError, match="unknown key 'rooms.base_dir'"):
        config.write_text('[rooms]\nfiles = ["c.usda"]\nbase_dir = "/"\n')
        load_config(config)


def test_a_procedural_room_id_is_refused(tmp_path: Path) -> None:
    from sgdata.pipeline.generate import generate_dataset

    (tmp_path / "rooms").mkdir()
    write_user_room(tmp_path / "rooms" / "bathroom_000.usda")
    config = tmp_path / "c.toml"
    config.write_text('[rooms]\ntypes = ["bathroom"]\nfiles = ["rooms/bathroom_000.usda"]\n')
    with pytest.raises(ConfigError, match="room id 'bathroom_000' is a procedural room's"):
        generate_dataset(load_config(config), tmp_path / "out")
    assert not (tmp_path / "out").exists()


def test_pinned_sha256_and_type_from_the_file(tmp_path: Path) -> None:

    path = write_user_room(tmp_path / "room.usda")
    layer = Sdf.Layer.FindOrOpen(str(path))
    stage = Usd.Stage.Open(layer)
    stage.GetPrimAtPath("/Room").CreateAttribute("sgdata:roomType", Sdf.ValueTypeNames.Token).Set(
        "living_room"
    )
    layer.Save()
    config = tmp_path / "c.toml"
    config.write_text('[rooms]\nfiles = ["room.usda"]\n')
    resolved = resolve_user_rooms(load_config(config))
    entry = resolved.rooms.files[0]
    assert (entry.type, entry.sha256) == ("living_room", sha256(path))
    config.write_text(f'[rooms]\nfiles = [{{ path = "room.usda", sha256 = "{"0" * 64}" }}]\n')
    with pytest.raises(ConfigError, match=f"sha256 is {entry.sha256}, not the 0000"):
        resolve_user_rooms(load_config(config))


def test_a_file_changed_after_the_check_is_refused(tmp_path: Path) -> None:
    from sgdata.errors import UsdError
    from sgdata.pipeline.user_rooms import copy_user_room, resolve_user_rooms

    path = write_user_room(tmp_path / "room.usda")
    config = tmp_path / "c.toml"
    config.write_text('[rooms]\nfiles = ["room.usda"]\n')
    resolved = resolve_user_rooms(load_config(config))
    with open(path, "a") as handle:
        handle.write("\n")
    with pytest.raises(UsdError, match="changed since this generation started"):
        copy_user_room(resolved.rooms.files[0], resolved, tmp_path / "scene")
    assert not (tmp_path / "scene").exists()


def test_implausible_sizes_can_be_allowed_in_rooms(tmp_path: Path) -> None:
    write_user_room(tmp_path / "big.usda", up="Y", mpu=0.01, gprims=True)
    stage = Usd.Stage.Open(str(tmp_path / "big.usda"))
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)  # centimetres read as metres: a 400 m room
    stage.GetRootLayer().Save()
    config = tmp_path / "big.toml"
    config.write_text('[rooms]\nfiles = ["big.usda"]\n')
    with pytest.raises(UsdError, match=r"raise \[rooms\] max_room_size \(now 30\)"):
        resolve_user_rooms(load_config(config))
    config.write_text('[rooms]\nfiles = ["big.usda"]\nmax_room_size = 500.0\n')
    with pytest.raises(UsdError, match=r"/Room/Fridge \(Fridge\) measures 70 x 80 x 180 m"):
        resolve_user_rooms(load_config(config))
    config.write_text('[rooms]\nfiles = ["big.usda"]\nmax_room_size = 500\nmax_object_size = 200\n')
    resolved = resolve_user_rooms(load_config(config))
    assert config_to_dict(resolved.rooms)["max_room_size"] == 500.0  # recorded when set
    # left at their defaults, the limits stay out of the manifest: its bytes do not change
    assert "max_room_size" not in config_to_dict(RoomsConfig())
    with pytest.raises(ConfigError, match="rooms.max_object_size must be a positive number"):
        RoomsConfig(max_object_size=float("nan"))
