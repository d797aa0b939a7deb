"""The on-disk format: rows match the schemas, Parquet files are deterministic and atomic, plain
pyarrow / polars / DuckDB read them, the manifest validates and versions, Dataset reads it all.
Real files in tmp_path; views are built by hand (no rendering)."""

from __future__ import annotations

import dataclasses
import json
import os
import re
from pathlib import Path

import duckdb
import numpy as np
import polars as pl
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from sgdata.annotate.records import ViewRecord
from sgdata.annotate.relations import RelationRules
from sgdata.dataset import (
    MIGRATIONS,
    Counts,
    Dataset,
    FormatVersionError,
    Generator,
    ImageInfo,
    Manifest,
    ObsKey,
    check_compatible,
    classes_from_slots,
    decode_image,
    file_entry,
    migrate_manifest_dict,
    obs_id,
    observation_table,
    observations_path,
    parse_obs_id,
    read_table,
    schema,
    triplet_table,
    triplets_path,
    write_manifest,
    write_parquet,
)
from sgdata.dataset.schema import (
    FORMAT_VERSION,
    file_schema,
    is_image_field,
    observations_schema,
    triplets_schema,
)
from sgdata.errors import DatasetError
from sgdata.pipeline.config import GenerateConfig, config_to_dict
from sgdata.world.triplets import PoseKey, Triplet

CLASSES = {"Table": ("static", 0, 2), "Mug": ("high", 2, 4), "Chair": ("low", 6, 3)}
CLASS_IDS = {name: i for i, name in enumerate(CLASSES)}
H, W = 12, 16


def make_record(
    rng: np.random.Generator, room_id: str, layout: int, i: int, j: int, heading: int, k: int
) -> ViewRecord:
    """A view with ``k`` objects (instances 10, 11, ...), a relation chain and a random image."""
    names = list(CLASSES)
    inst = np.arange(10, 10 + k, dtype=np.int64)
    lo = rng.uniform(0, 2, size=(k, 3))
    support = np.full(k, -1, dtype=np.int64)
    support[1:] = 10  # everything rests on the first object
    return ViewRecord(
        room_id=room_id,
        layout=layout,
        seed=int(rng.integers(0, 2**62)),
        x=float(i) * 0.25,
        y=float(j) * 0.25,
        theta=heading * np.pi / 2,
        grid_i=i,
        grid_j=j,
        heading=heading,
        image_width=W,
        image_height=H,
        hfov_deg=90.0,
        eye_height=1.2,
        pitch_deg=10.0,
        rgb=rng.integers(0, 256, size=(H, W, 3), dtype=np.uint8),
        obj_instance=inst,
        obj_class=[names[n % 3] for n in range(k)],
        obj_slot=np.arange(k, dtype=np.int64),
        obj_dynamics=[CLASSES[names[n % 3]][0] for n in range(k)],
        obj_box2d=rng.integers(0, 12, size=(k, 4)).astype(np.int32),
        obj_visible_pixels=rng.integers(20, 200, size=k),
        obj_box3d_min=lo,
        obj_box3d_max=lo + 0.5,
        obj_obb=rng.uniform(-1, 1, size=(k, 7)),
        obj_support=support,
        rel_src=inst[1:],
        rel_dst=np.full(max(k - 1, 0), 10, dtype=np.int64),
        rel_type=np.zeros(max(k - 1, 0), dtype=np.int8),
        dropped_objects=k // 3,
    )


def room_records(room_id: str, seed: int = 0) -> list[ViewRecord]:
    rng = np.random.default_rng(seed)
    keys = [(layout, i, 0, h) for layout in (0, 1) for i in (0, 1) for h in (0, 1)]
    return [make_record(rng, room_id, *key, k=n % 4) for n, key in enumerate(keys)]


def obs_table(room_id: str, split: str = "train", **kwargs: object) -> pa.Table:
    return observation_table(
        room_records(room_id),
        room_type="kitchen",
        split=split,
        class_ids=CLASS_IDS,
        **kwargs,  # type: ignore[arg-type]
    )


def make_triplets(room_id: str, split: str) -> list[Triplet]:
    a, p, n = PoseKey(0, 0, 0, 0), PoseKey(1, 0, 0, 0), PoseKey(0, 1, 0, 0)
    turn = PoseKey(1, 1, 0, 1)
    return [
        Triplet(room_id, split, 0, a, p, n),
        Triplet(room_id, split, 4, n, a, turn),
    ]


# --------------------------------------------------------------------------- layout


def test_obs_id_round_trip() -> None:
    value = obs_id("kitchen_003", 2, 5, 7, 3)
    assert value == "kitchen_003/2/5/7/3"
    assert parse_obs_id(value) == ObsKey("kitchen_003", 2, 5, 7, 3)
    for bad in ("kitchen/2/5/7", "kitchen/a/5/7/3", "/1/2/3/4"):
        with pytest.raises(DatasetError, match="expected <room_id>"):
            parse_obs_id(bad)
    with pytest.raises(DatasetError, match="room id"):
        obs_id("a/b", 0, 0, 0, 0)
    assert observations_path("val", "bedroom_000") == "observations/val/bedroom_000.parquet"
    with pytest.raises(DatasetError, match="split 'dev'"):
        triplets_path("dev")


# --------------------------------------------------------------------------- rows


@pytest.mark.parametrize("k", [0, 5])
def test_observation_table_matches_schema(k: int) -> None:
    rec = make_record(np.random.default_rng(k), "kitchen_000", 1, 2, 3, 1, k)
    table = observation_table([rec], room_type="kitchen", split="train", class_ids=CLASS_IDS)
    schema = observations_schema()
    assert table.schema.equals(schema, check_metadata=True)
    for f in schema:  # nullability holds in the data, not only in the declared schema
        if not f.nullable:
            assert table.column(f.name).null_count == 0
    row = table.to_pylist()[0]
    assert row["obs_id"] == "kitchen_000/1/2/3/1"
    assert row["domain"] == "synthetic" and row["scene"] == "scenes/kitchen_000/layout_1.usda"
    assert row["camera"] == pytest.approx(
        {"width": W, "height": H, "hfov_deg": 90.0, "eye_height": 1.2, "pitch_deg": 10.0}
    )
    assert len(row["objects"]) == k and len(row["relations"]) == max(k - 1, 0)
    if k:
        first, second = row["objects"][:2]
        assert first["support"] is None and second["support"] == 10
        assert second["class_id"] == CLASS_IDS[second["class_name"]]
        assert first["box2d"] == rec.obj_box2d[0].tolist()
        assert first["obb"] == pytest.approx(rec.obj_obb[0].astype(np.float32).tolist())
        assert row["relations"][0] == {"src": 11, "dst": 10, "type": 0}


def test_png_is_lossless_and_jpeg_decodes() -> None:
    records = room_records("kitchen_000")
    table = observation_table(records, room_type="kitchen", split="train", class_ids=CLASS_IDS)
    for rec, data in zip(records, table.column("image").to_pylist(), strict=True):
        assert data[:8] == b"\x89PNG\r\n\x1a\n"
        np.testing.assert_array_equal(decode_image(data), rec.rgb)
    jpeg = obs_table("kitchen_000", image_format="jpeg", jpeg_quality=80)
    assert set(jpeg.column("image_format").to_pylist()) == {"jpeg"}
    assert decode_image(jpeg.column("image")[0].as_py()).shape == (H, W, 3)


def test_observation_table_refuses_bad_records() -> None:
    rec = make_record(np.random.default_rng(0), "kitchen_000", 0, 0, 0, 0, 3)
    with pytest.raises(DatasetError, match="not in class_ids"):
        observation_table([rec], room_type="kitchen", split="train", class_ids={"Table": 0})
    rec.obj_class = rec.obj_class[:2]
    with pytest.raises(DatasetError, match="obj_class"):
        observation_table([rec], room_type="kitchen", split="train", class_ids=CLASS_IDS)
    with pytest.raises(DatasetError, match="2 scene_paths for 8 records"):
        obs_table("kitchen_000", scene_paths=["a", "b"])
    paths = [f"s/{n}" for n in range(8)]
    assert obs_table("kitchen_000", scene_paths=paths).column("scene").to_pylist() == paths
    assert obs_table("kitchen_000", scene_path=None).column("scene").null_count == 8
    with pytest.raises(DatasetError, match="image format"):
        obs_table("kitchen_000", image_format="webp")


def test_triplet_table() -> None:
    triplets = make_triplets("kitchen_000", "train")
    ids = set(obs_table("kitchen_000").column("obs_id").to_pylist())
    table = triplet_table(triplets, ids)
    assert table.schema.equals(triplets_schema(), check_metadata=True)
    rows = table.to_pylist()
    assert [r["triplet_id"] for r in rows] == [0, 1]
    assert rows[0]["positive"] == "kitchen_000/1/0/0/0"
    assert rows[1]["negative_offset"] == [0, 0, 1]
    assert rows[0]["negative_offset"] == list(triplets[0].negative_offset)
    with pytest.raises(DatasetError, match="not in the split's observations"):
        triplet_table(triplets, {"kitchen_000/0/0/0/0"})
    with pytest.raises(DatasetError, match="one split a table"):
        triplet_table([*triplets, *make_triplets("kitchen_001", "val")])
    assert triplet_table([]).num_rows == 0


# --------------------------------------------------------------------------- parquet files


def test_write_parquet_is_deterministic(tmp_path: Path) -> None:
    a = write_parquet(obs_table("kitchen_000"), tmp_path / "a" / "x.parquet")
    b = write_parquet(obs_table("kitchen_000"), tmp_path / "b" / "x.parquet")
    assert (tmp_path / "a" / "x.parquet").read_bytes() == (
        tmp_path / "b" / "x.parquet"
    ).read_bytes()
    assert a == b and a.rows == 8 and a.bytes == (tmp_path / "a" / "x.parquet").stat().st_size
    rows, digest, size = a  # a plain tuple as well
    assert len(digest) == 64 and size > 0
    assert sorted(os.listdir(tmp_path / "a")) == ["x.parquet"]  # no temp file left


def test_write_parquet_failure_leaves_nothing(tmp_path: Path) -> None:
    union = pa.UnionArray.from_sparse(
        pa.array([0, 1], type=pa.int8()), [pa.array([1, 2]), pa.array(["a", "b"])]
    )
    target = tmp_path / "bad.parquet"
    with pytest.raises(DatasetError, match="cannot write the table as Parquet"):
        write_parquet(pa.table({"u": union}), target)
    assert list(tmp_path.iterdir()) == []
    # an existing file is left as it was
    write_parquet(obs_table("kitchen_000"), target)
    before = target.read_bytes()
    with pytest.raises(DatasetError):
        write_parquet(pa.table({"u": union}), target)
    assert target.read_bytes() == before and sorted(os.listdir(tmp_path)) == ["bad.parquet"]


def test_write_parquet_unwritable_dir(tmp_path: Path) -> None:
    blocker = tmp_path / "not_a_dir"
    blocker.write_text("a file where the directory should be")
    with pytest.raises(DatasetError, match="cannot write here"):
        write_parquet(obs_table("kitchen_000"), blocker / "x.parquet")
    assert sorted(os.listdir(tmp_path)) == ["not_a_dir"]
    if os.geteuid() != 0:  # root writes into read-only directories anyway
        locked = tmp_path / "locked"
        locked.mkdir()
        locked.chmod(0o500)
        try:
            with pytest.raises(DatasetError, match="cannot write here"):
                write_parquet(obs_table("kitchen_000"), locked / "x.parquet")
            assert list(locked.iterdir()) == []
        finally:
            locked.chmod(0o700)


def test_plain_tools_read_the_files(tmp_path: Path) -> None:
    obs, tri = tmp_path / "obs.parquet", tmp_path / "tri.parquet"
    table = obs_table("kitchen_000")
    write_parquet(table, obs)
    write_parquet(triplet_table(make_triplets("kitchen_000", "train")), tri)
    n_objects = sum(len(o) for o in table.column("objects").to_pylist())

    back = pq.read_table(obs)  # on disk: the image as the Hugging Face {bytes, path} struct
    stored = file_schema(observations_schema())
    assert back.schema.equals(stored, check_metadata=True)
    images = [f.name for f in observations_schema() if is_image_field(f)]  # image + channels
    assert back.drop_columns(images).equals(table.drop_columns(images))
    for channel in images[1:]:  # obs_table stores no channels: null structs on disk
        assert back.column(channel).null_count == back.num_rows
    assert back.column("image").to_pylist() == [
        {"bytes": b, "path": None} for b in table.column("image").to_pylist()
    ]
    assert read_table(obs, observations_schema()).equals(table)  # in memory: the bytes
    cell = back.column("image")[0].as_py()  # a consumer on plain pyarrow: the dict decodes too
    np.testing.assert_array_equal(
        decode_image(cell), decode_image(table.column("image")[0].as_py())
    )
    with pytest.raises(DatasetError, match="expected encoded bytes or a dict with 'bytes'"):
        decode_image({"path": "x.png"})

    frame = pl.read_parquet(obs)
    assert frame.height == 8
    assert frame.select(pl.col("objects").list.len().sum()).item() == n_objects
    exploded = frame.select("obs_id", "objects").explode("objects").unnest("objects")
    assert exploded.drop_nulls("instance").height == n_objects
    png = frame.select(pl.col("image").struct.field("bytes")).to_series().to_list()
    assert png == table.column("image").to_pylist()

    con = duckdb.connect()
    count = con.execute(f"SELECT count(*) FROM read_parquet('{obs}'), unnest(objects)").fetchone()
    assert count[0] == n_objects
    classes = con.execute(
        f"SELECT o.class_name, count(*) FROM (SELECT unnest(objects) AS o FROM '{obs}') "
        "GROUP BY 1 ORDER BY 1"
    ).fetchall()
    assert sum(c for _, c in classes) == n_objects
    tiers = con.execute(f"SELECT tier, count(*) FROM '{tri}' GROUP BY tier ORDER BY tier")
    assert tiers.fetchall() == [(0, 1), (4, 1)]
    box = con.execute(
        f"SELECT camera.width, octet_length(image.bytes) > 0 FROM '{obs}' LIMIT 1"
    ).fetchone()
    assert box == (W, True)


# --------------------------------------------------------------------------- manifest


def make_manifest(files: tuple = (), **overrides: object) -> Manifest:
    runs = {n: (s, c) for n, (_, s, c) in CLASSES.items()}
    fields: dict[str, object] = dict(
        name="tiny",
        version="0.1.0",
        generator=Generator("sgdata", "0.1.0"),
        seed=7,
        config=config_to_dict(GenerateConfig()),
        classes=classes_from_slots(runs, {n: d for n, (d, _, _) in CLASSES.items()}),
        num_slots=256,
        relation_rules=RelationRules().to_dict(),
        image=ImageInfo("png", W, H),
        splits={"train": ("kitchen_000", "kitchen_001"), "val": ("kitchen_002",)},
        counts=Counts(
            rooms=3,
            observations={"train": 16, "val": 8},
            triplets={"train": 4, "val": 2},
            tiers={"train": [2, 0, 0, 0, 2], "val": [1, 0, 0, 0, 1]},
        ),
        files=files,
    )
    fields.update(overrides)
    return Manifest(**fields)  # type: ignore[arg-type]


def test_manifest_round_trip() -> None:
    m = make_manifest()
    text = m.to_json()
    assert Manifest.from_json(text) == m
    assert Manifest.from_json(text).to_json() == text  # deterministic
    data = json.loads(text)
    assert list(data)[:2] == ["format", "format_version"]
    assert data["format_version"] == FORMAT_VERSION
    assert data["relation_types"] == ["on", "in", "proximity", "disjoint"]
    assert data["classes"][1] == {
        "name": "Mug",
        "id": 1,
        "dynamics": "high",
        "slot_start": 2,
        "slot_count": 4,
    }
    assert list(data["config"]) == sorted(data["config"])
    assert m.class_ids == CLASS_IDS and m.slot_runs["Chair"] == (6, 3)


def test_manifest_schema_collects_every_problem() -> None:
    data = json.loads(make_manifest().to_json())
    data["format"] = "lerobot"
    data["extra"] = 1
    del data["seed"]
    data["classes"][0]["dynamics"] = "sometimes"
    data["image"]["format"] = "gif"
    data["splits"]["dev"] = []
    with pytest.raises(DatasetError) as info:
        Manifest.from_json(json.dumps(data))
    message = str(info.value)
    assert "6 problems" in message
    for needle in ("lerobot", "extra", "'seed' is a required", "sometimes", "gif", "dev"):
        assert needle in message


def test_manifest_cross_field_problems_at_once() -> None:
    with pytest.raises(DatasetError) as info:
        make_manifest(num_slots=8, counts=Counts(2, {"train": 1}, {"train": 1}, {"train": [1]}))
    message = str(info.value)
    for needle in ("past num_slots=8", "counts.rooms=2", "counts.observations", "5"):
        assert needle in message


def test_compat_newer_major_refused_with_upgrade_hint() -> None:
    with pytest.raises(FormatVersionError) as info:
        check_compatible("3.0.0")
    assert str(info.value) == (
        "dataset.json format_version 3.0.0 is newer than this sgdata reads (2.x); "
        "upgrade sgdata: pip install -U sgdata"
    )
    assert isinstance(info.value, DatasetError)
    data = json.loads(make_manifest().to_json())
    data["format_version"] = "3.0.0"
    with pytest.raises(FormatVersionError, match="pip install -U sgdata"):
        Manifest.from_json(json.dumps(data))
    for bad in ("1.0", "one", "1.0.0.0", ""):
        with pytest.raises(FormatVersionError, match="expected a semantic version"):
            check_compatible(bad)
    with pytest.raises(FormatVersionError, match=r"older than this sgdata reads \(1.x to 2.x\)"):
        check_compatible("0.9.0")
    check_compatible("2.7.3")  # same major: fine
    check_compatible("1.1.0")  # 1.x: read through sgdata.dataset.storage


def _fake_migration(raw: dict) -> dict:
    """1.0.0 -> 1.1.0: pretend 1.0 called the dataset name 'title'."""
    raw = dict(raw)
    raw["name"] = raw.pop("title")
    raw["format_version"] = "1.1.0"
    return raw


def test_older_minor_is_migrated_through_the_hook(monkeypatch: pytest.MonkeyPatch) -> None:
    data = json.loads(make_manifest().to_json())
    data["title"] = data.pop("name")
    data["format_version"] = "1.0.0"  # an older minor than the reader's
    out = migrate_manifest_dict(data, current="1.1.0", migrations={"1.0.0": _fake_migration})
    assert out["name"] == "tiny" and out["format_version"] == "1.1.0" and "title" not in out
    # and through the registry, as the reader does it
    monkeypatch.setattr(schema, "FORMAT_VERSION", "1.1.0")
    monkeypatch.setitem(MIGRATIONS, "1.0.0", _fake_migration)
    parsed = Manifest.from_json(json.dumps(data))
    assert parsed.name == "tiny" and parsed.format_version == "1.1.0"


def test_newer_minor_drops_unknown_keys() -> None:
    data = json.loads(make_manifest().to_json())
    data["format_version"] = "2.4.0"
    data["future_field"] = {"x": 1}
    parsed = Manifest.from_json(json.dumps(data))
    assert parsed.format_version == "2.4.0"


# --------------------------------------------------------------------------- reader


def with_channels(record: ViewRecord) -> ViewRecord:
    """``record`` with a depth map, an instance mask (each object fills its 2D box) and a
    structure mask (the rest is wall, the bottom row floor)."""
    instances = np.zeros((record.image_height, record.image_width), np.uint16)
    for k, (x0, y0, x1, y1) in enumerate(record.obj_box2d, start=1):
        instances[y0 : y1 + 1, x0 : x1 + 1] = k
    depth = np.where(instances > 0, 1.5, 0.0).astype(np.float32)
    structure = np.where(instances > 0, 0, 1).astype(np.uint8)
    structure[-1][instances[-1] == 0] = 2
    return dataclasses.replace(record, depth=depth, instances=instances, structure=structure)


def build_tiny_dataset(root: Path) -> Path:
    """A hand-assembled dataset at ``root``: train (2 rooms), val (1 room), triplets, manifest."""
    splits = {"train": ["kitchen_000", "kitchen_001"], "val": ["kitchen_002"]}
    entries, obs_counts, tri_counts, tiers = [], {}, {}, {}
    for split, rooms in splits.items():
        ids: set[str] = set()
        for n, room in enumerate(rooms):
            records = [with_channels(r) for r in room_records(room, seed=n)]  # as `tiny` writes
            table = observation_table(
                records, room_type="kitchen", split=split, class_ids=CLASS_IDS
            )
            ids |= set(table.column("obs_id").to_pylist())
            rel = observations_path(split, room)
            info = write_parquet(table, root / rel)
            entries.append(file_entry(root, rel, rows=info.rows))
        triplets = [t for room in rooms for t in make_triplets(room, split)]
        rel = triplets_path(split)
        write_parquet(triplet_table(triplets, ids), root / rel)
        entries.append(file_entry(root, rel, rows=len(triplets)))
        obs_counts[split] = 8 * len(rooms)
        tri_counts[split] = len(triplets)
        tiers[split] = [sum(t.tier == k for t in triplets) for k in range(5)]
    m = make_manifest(
        files=tuple(sorted(entries, key=lambda e: e.path)),
        splits={s: tuple(r) for s, r in splits.items()},
        counts=Counts(3, obs_counts, tri_counts, tiers),
    )
    write_manifest(m, root)
    return root


@pytest.fixture
def tiny_dataset(tmp_path: Path) -> Path:
    return build_tiny_dataset(tmp_path / "ds")


def test_dataset_open_reads_everything(tiny_dataset: Path) -> None:
    ds = Dataset.open(tiny_dataset)
    assert ds.root == tiny_dataset and ds.splits == ["train", "val"]
    assert ds.rooms("train") == ["kitchen_000", "kitchen_001"]
    assert ds.class_names == list(CLASSES) and ds.slot_runs["Mug"] == (2, 4)
    assert ds.relation_types == ["on", "in", "proximity", "disjoint"]
    train = ds.observations("train")
    assert train.num_rows == 16 and train.schema.equals(observations_schema())
    assert train.column("room_id").to_pylist() == ["kitchen_000"] * 8 + ["kitchen_001"] * 8
    slim = ds.observations("val", columns=["obs_id", "objects"])
    assert slim.column_names == ["obs_id", "objects"] and slim.num_rows == 8
    assert [p.name for p in ds.observation_files("train")] == [
        "kitchen_000.parquet",
        "kitchen_001.parquet",
    ]
    tri = ds.triplets("val")
    assert tri.num_rows == 2 and tri.column("tier").to_pylist() == [0, 4]
    image = ds.read_image(train.column("image")[0].as_py())
    np.testing.assert_array_equal(image, room_records("kitchen_000")[0].rgb)
    assert ds.verify() == []
    with pytest.raises(DatasetError, match="split 'test' is not in"):
        ds.observations("test")
    with pytest.raises(DatasetError, match="unknown observation columns"):
        ds.observations("train", columns=["pixels"])


def test_dataset_open_errors(tiny_dataset: Path, tmp_path: Path) -> None:
    empty = tmp_path / "empty"
    empty.mkdir()
    with pytest.raises(DatasetError, match="no dataset.json; not an sgdata dataset .*--resume"):
        Dataset.open(empty)
    shard = tiny_dataset / observations_path("train", "kitchen_001")
    shard.write_bytes(shard.read_bytes()[:-10])
    ds = Dataset.open(tiny_dataset)
    size = shard.stat().st_size
    expected = f"{observations_path('train', 'kitchen_001')}: {size} bytes, expected {size + 10}"
    assert ds.verify() == [expected]
    with pytest.raises(DatasetError, match="not a readable Parquet"):
        ds.observations("train")
    shard.unlink()
    with pytest.raises(DatasetError, match="missing"):
        ds.observations("train")
    data = json.loads((tiny_dataset / "dataset.json").read_text())
    data["format_version"] = "3.1.0"
    (tiny_dataset / "dataset.json").write_text(json.dumps(data))
    with pytest.raises(FormatVersionError, match="newer than this sgdata"):
        Dataset.open(tiny_dataset)


def test_reader_ignores_columns_of_a_newer_minor(tiny_dataset: Path) -> None:
    rel = observations_path("val", "kitchen_002")
    table = pq.read_table(tiny_dataset / rel)
    pq.write_table(
        table.append_column("future", pa.array([1] * table.num_rows)), tiny_dataset / rel
    )
    assert Dataset.open(tiny_dataset).observations("val").schema.equals(observations_schema())
    pq.write_table(table.drop_columns(["seed"]), tiny_dataset / rel)
    with pytest.raises(DatasetError, match=r"no column\(s\) \['seed'\]"):
        Dataset.open(tiny_dataset).observations("val")


def test_docs_examples_run(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Every example of docs/dataset.md runs on a tiny dataset at out/tiny: sgdata, pyarrow,
    polars, DuckDB, and (with the dev extra) Hugging Face `datasets` and `mlcroissant`."""
    build_tiny_dataset(tmp_path / "out" / "tiny")
    monkeypatch.chdir(tmp_path)
    datasets = pytest.importorskip("datasets")
    pytest.importorskip("mlcroissant")
    monkeypatch.setattr(datasets.config, "HF_DATASETS_CACHE", tmp_path / "hf")
    text = (Path(__file__).resolve().parents[3] / "docs" / "dataset.md").read_text()
    blocks = re.findall(r"```(python|sql)\n(.*?)```", text, re.S)
    ran = 0
    for lang, code in blocks:
        if lang == "python":
            exec(compile(code, "docs/dataset.md", "exec"), {})
            ran += 1
        elif lang == "sql":
            con = duckdb.connect()
            for statement in filter(str.strip, code.split(";")):
                assert con.execute(statement).fetchall()
                ran += 1
    assert ran >= 10
