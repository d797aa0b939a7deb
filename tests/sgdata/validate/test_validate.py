"""sgdata.validate: a generated dataset is clean; each kind of damage is found and located."""

from __future__ import annotations

import hashlib
import io
import json
import shutil
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.parquet as pq
import pytest
from PIL import Image

from sgdata.dataset import Dataset, read_manifest, write_manifest, write_parquet
from sgdata.dataset.schema import file_schema, observations_schema, parse_version, schema_at
from sgdata.errors import DatasetError
from sgdata.validate import ValidationReport, validate_dataset

from ...cli_runner import run_cli

SHARD = "observations/train/bathroom_000.parquet"  # the mini dataset's train room
TRIPLETS = "triplets/train.parquet"


@pytest.fixture(scope="session")
def clean_report(mini_dataset: Path) -> ValidationReport:
    return validate_dataset(mini_dataset)


@pytest.fixture
def copy(mini_dataset: Path, tmp_path: Path) -> Path:
    target = tmp_path / "copy"
    shutil.copytree(mini_dataset, target)
    return target


# ------------------------------------------------------------------ damage helpers


def edit_manifest(root: Path, change: Callable[[dict], None]) -> None:
    raw = json.loads((root / "dataset.json").read_text())
    change(raw)
    (root / "dataset.json").write_text(json.dumps(raw, indent=2))


def rewrite(root: Path, rel: str, table: pa.Table, *, update_manifest: bool = True) -> None:
    """Write ``table`` over ``rel``; with ``update_manifest``, fix its rows/sha256/bytes (and
    write the card and croissant.json again, as a writer would)."""
    info = write_parquet(table, root / rel)

    def fix(raw: dict) -> None:
        for entry in raw["files"]:
            if entry["path"] == rel:
                entry.update(rows=info.rows, sha256=info.sha256, bytes=info.bytes)

    if update_manifest:
        edit_manifest(root, fix)
        write_manifest(read_manifest(root), root)


def deflated_the_old_way(png: bytes) -> bytes:
    """A PNG as formats before 2.0.1 wrote it: zlib's default strategy, level 6."""
    buffer = io.BytesIO()
    with Image.open(io.BytesIO(png)) as image:
        image.save(buffer, format="PNG", optimize=False, compress_level=6)
    return buffer.getvalue()


def legacy_dataset(
    root: Path, *, drop: tuple[str, ...] | list[str] = (), version: str = "1.1.0"
) -> None:
    """Turn a generated dataset into one of an older format, as that sgdata wrote it: without
    the columns later minors added, PNGs deflated the old way (before 2.0.1), its own
    ``format_version`` in each table's metadata and, for 1.x, images as bare bytes (non-null
    binary, no huggingface metadata), no card, no croissant.json."""
    raw = json.loads((root / "dataset.json").read_text())
    bare = version.startswith("1.")
    old_png = parse_version(version) < parse_version("2.0.1")
    files = []
    for entry in raw["files"]:
        path = root / entry["path"]
        if bare and entry["path"] in ("README.md", "croissant.json"):
            path.unlink()
            continue
        stamp = {b"format_version": version.encode()}
        if entry["path"].startswith("triplets/"):
            table = pq.read_table(path)
            pq.write_table(table.replace_schema_metadata({**table.schema.metadata, **stamp}), path)
            entry.update(sha256=hashlib.sha256(path.read_bytes()).hexdigest())
            entry.update(bytes=path.stat().st_size)
        if entry["path"].startswith("observations/"):
            table = pq.read_table(path).drop_columns(list(drop))
            # the columns a later minor added (the channels of 2.1.0) were not there yet
            known = schema_at(observations_schema(), version).names
            table = table.drop_columns([n for n in table.column_names if n not in known])
            at = table.schema.get_field_index("image")
            old = [
                {"bytes": deflated_the_old_way(cell["bytes"]) if old_png else cell["bytes"]}
                | {"path": None}
                for cell in table.column("image").to_pylist()
            ]
            column = pa.array(old, type=table.schema.field(at).type)
            table = table.set_column(at, table.schema.field(at), column)
            metadata = {**table.schema.metadata, **stamp}
            if not bare:  # the Image features of the columns that version had
                hf = file_schema(observations_schema(), version).metadata[b"huggingface"]
                metadata = {**metadata, b"huggingface": hf}
            if bare:
                doc = {b"doc": table.schema.field("image").metadata[b"doc"]}
                field = pa.field("image", pa.binary(), nullable=False, metadata=doc)
                table = table.set_column(at, field, pc.struct_field(column, "bytes"))
                metadata = {k: v for k, v in metadata.items() if k != b"huggingface"}
            pq.write_table(table.replace_schema_metadata(metadata), path)
            digest = hashlib.sha256(path.read_bytes()).hexdigest()
            entry.update(sha256=digest, bytes=path.stat().st_size)
        files.append(entry)
    raw.update(files=files, format_version=version)
    (root / "dataset.json").write_text(json.dumps(raw, indent=2))
    if not bare:  # the card and croissant.json of that dataset, as its writer made them
        write_manifest(read_manifest(root), root)


def pixels(images: pa.ChunkedArray) -> list[np.ndarray]:
    return [np.asarray(Image.open(io.BytesIO(b))) for b in images.to_pylist()]


def rows_of(root: Path, rel: str) -> tuple[list[dict], pa.Schema]:
    table = pq.read_table(root / rel)
    return table.to_pylist(), table.schema


def checks(report: ValidationReport) -> set[str]:
    return {p.check for p in report.problems}


def find(report: ValidationReport, check: str) -> list:
    found = [p for p in report.problems if p.check == check]
    assert found, f"{check} not reported; got {sorted(checks(report))}"
    return found


# ------------------------------------------------------------------ tests


def test_generated_dataset_is_clean(clean_report: ValidationReport) -> None:
    assert clean_report.ok, [(p.check, p.location(), p.message) for p in clean_report.problems]
    assert clean_report.checked["relations.recompute"] > 0
    assert clean_report.checked["images.decode"] > 0
    assert clean_report.checked["triplets.offsets"] == 40
    data = json.loads(clean_report.to_json())
    assert data["ok"] is True and data["problems"] == []


def test_quick_skips_images(mini_dataset: Path) -> None:
    report = validate_dataset(mini_dataset, quick=True)
    assert report.ok and "images.decode" in report.skipped
    assert "images.decode" not in report.checked


def test_not_a_dataset(tmp_path: Path) -> None:
    with pytest.raises(DatasetError, match="no dataset.json"):
        validate_dataset(tmp_path)
    with pytest.raises(DatasetError, match="no such directory"):
        validate_dataset(tmp_path / "nothing")


def test_truncated_shard(copy: Path) -> None:
    table = pq.read_table(copy / SHARD)
    rewrite(copy, SHARD, table.slice(0, table.num_rows - 3), update_manifest=False)
    report = validate_dataset(copy, quick=True)
    assert not report.ok
    (rows,) = find(report, "files.rows")
    assert rows.file == SHARD and f"{table.num_rows - 3} rows" in rows.message
    assert find(report, "files.sha256")[0].file == SHARD


def test_changed_bytes_change_sha(copy: Path) -> None:
    scene = copy / "scenes/bathroom_000/layout_1.usda"
    text = scene.read_bytes()
    at = text.index(b"(", text.index(b"xformOp:translate ="))
    digit = next(k for k in range(at, len(text)) if text[k : k + 1].isdigit())
    flipped = b"1" if text[digit : digit + 1] != b"1" else b"2"
    scene.write_bytes(text[:digit] + flipped + text[digit + 1 :])
    report = validate_dataset(copy, quick=True)
    assert checks(report) == {"files.sha256"}
    assert report.problems[0].file == "scenes/bathroom_000/layout_1.usda"


def test_changed_column_type(copy: Path) -> None:
    table = pq.read_table(copy / SHARD)
    at = table.schema.get_field_index("layout")
    layout = pa.field("layout", pa.int64(), nullable=False)
    rewrite(copy, SHARD, table.set_column(at, layout, table.column("layout").cast(pa.int64())))
    report = validate_dataset(copy, quick=True)
    (problem,) = find(report, "tables.schema")
    assert (problem.file, problem.field) == (SHARD, "layout")
    assert "int64" in problem.message and "int16" in problem.message
    assert checks(report) == {"tables.schema"}  # the rows were still checked, and are fine


def test_dropped_column(copy: Path) -> None:
    table = pq.read_table(copy / SHARD)
    rewrite(copy, SHARD, table.drop_columns(["seed"]))
    report = validate_dataset(copy, quick=True)
    problems = find(report, "tables.schema")
    assert any(p.field == "seed" and "missing" in p.message for p in problems)


def test_dangling_triplet_id(copy: Path) -> None:
    rows, schema = rows_of(copy, TRIPLETS)
    rows[4]["negative"] = "bathroom_000/1/99/99/0"
    rewrite(copy, TRIPLETS, pa.Table.from_pylist(rows, schema=schema))
    report = validate_dataset(copy, quick=True)
    (problem,) = find(report, "triplets.references")
    assert (problem.file, problem.row, problem.field) == (TRIPLETS, 4, "negative")
    assert checks(report) == {"triplets.references"}


def _first(rows: list[dict], pick: Callable[[dict], bool]) -> int:
    return next(k for k, r in enumerate(rows) if pick(r))


def test_box2d_outside_image(copy: Path) -> None:
    rows, schema = rows_of(copy, SHARD)
    k = _first(rows, lambda r: len(r["objects"]) > 1)
    box = rows[k]["objects"][1]["box2d"]
    rows[k]["objects"][1]["box2d"] = [box[0], box[1], 96 + 7, box[3]]
    rewrite(copy, SHARD, pa.Table.from_pylist(rows, schema=schema))
    report = validate_dataset(copy, quick=True)
    (problem,) = find(report, "objects.box2d")
    assert (problem.file, problem.row, problem.field) == (SHARD, k, "objects[1].box2d")
    assert "103" in problem.message
    assert checks(report) == {"objects.box2d"}


def test_a_stated_camera_that_its_pose_does_not_give(copy: Path) -> None:
    rows, schema = rows_of(copy, SHARD)
    rows[2]["camera_to_world"][3] += 0.25  # the camera 25 cm off its stated x
    rows[3]["intrinsics"] = None
    rewrite(copy, SHARD, pa.Table.from_pylist(rows, schema=schema))
    report = validate_dataset(copy, quick=True)
    dropped, moved = find(report, "rows.camera")  # by column, then row
    assert (moved.file, moved.row, moved.field) == (SHARD, 2, "camera_to_world")
    assert (dropped.row, dropped.field) == (3, "intrinsics") and "null;" in dropped.message
    assert "sgdata migrate" in moved.message and checks(report) == {"rows.camera"}


def test_one_way_proximity(copy: Path) -> None:
    rows, schema = rows_of(copy, SHARD)
    k = _first(rows, lambda r: any(e["type"] == 2 for e in r["relations"]))
    edges = rows[k]["relations"]
    drop = next(e for e in edges if e["type"] == 2)
    rows[k]["relations"] = [e for e in edges if e is not drop]
    rewrite(copy, SHARD, pa.Table.from_pylist(rows, schema=schema))
    report = validate_dataset(copy, quick=True)
    (problem,) = find(report, "relations.symmetric")
    assert (problem.file, problem.row) == (SHARD, k)
    assert f"{drop['dst']}->{drop['src']}" in problem.message
    assert checks(report) <= {"relations.symmetric", "relations.recompute"}


def _view_with_on(root: Path) -> tuple[str, list[dict], pa.Schema, int, dict]:
    for rel in sorted(p.relative_to(root).as_posix() for p in root.glob("observations/*/*")):
        rows, schema = rows_of(root, rel)
        for k, r in enumerate(rows):
            on = [e for e in r["relations"] if e["type"] == 0]
            if on:
                return rel, rows, schema, k, on[0]
    pytest.skip("no view with an 'on' relation in the mini dataset")


def test_on_and_in_for_one_pair(copy: Path) -> None:
    rel, rows, schema, k, on = _view_with_on(copy)
    edges = rows[k]["relations"] + [{"src": on["dst"], "dst": on["src"], "type": 1}]
    rows[k]["relations"] = sorted(edges, key=lambda e: (e["src"], e["dst"]))
    rewrite(copy, rel, pa.Table.from_pylist(rows, schema=schema))
    report = validate_dataset(copy, quick=True)
    (problem,) = find(report, "relations.on_and_in")
    assert (problem.file, problem.row) == (rel, k)
    assert problem.field.startswith("relations[") and problem.field.endswith("].type")


def test_relations_recompute_mismatch(copy: Path) -> None:
    rows, schema = rows_of(copy, SHARD)
    k = _first(rows, lambda r: any(e["type"] == 2 for e in r["relations"]))
    first = next(e for e in rows[k]["relations"] if e["type"] == 2)
    pair = {first["src"], first["dst"]}
    for e in rows[k]["relations"]:
        if {e["src"], e["dst"]} == pair:
            e["type"] = 3  # proximity -> disjoint, both directions: still well-formed
    rewrite(copy, SHARD, pa.Table.from_pylist(rows, schema=schema))
    report = validate_dataset(copy, quick=True)
    assert checks(report) == {"relations.recompute"}
    (problem,) = report.problems
    assert (problem.file, problem.row, problem.field) == (SHARD, k, "relations")
    assert "stored disjoint" in problem.message and "recomputed" in problem.message


def test_skewed_composition(copy: Path) -> None:
    rows, schema = rows_of(copy, TRIPLETS)
    for r in rows:
        if r["tier"] == 0:
            r["tier"] = 1
            break
    rewrite(copy, TRIPLETS, pa.Table.from_pylist(rows, schema=schema))
    report = validate_dataset(copy, quick=True)
    problems = find(report, "triplets.tiers")
    assert any(p.file == TRIPLETS and p.field == "tier" for p in problems)
    assert any(p.file == "dataset.json" for p in problems)  # counts.tiers no longer match
    assert "triplets.tier_rules" in checks(report)  # a tier-0 triplet cannot pass as tier 1


def test_room_in_two_splits(copy: Path) -> None:
    edit_manifest(copy, lambda raw: raw["splits"]["val"].append("bathroom_000"))
    report = validate_dataset(copy, quick=True)
    (problem,) = find(report, "splits.disjoint")
    assert "bathroom_000" in problem.message and problem.file == "dataset.json"
    assert problem.field == "splits/val"


def test_corrupt_image(copy: Path) -> None:
    table = pq.read_table(copy / SHARD)
    images = table.column("image").to_pylist()  # {bytes, path} on disk
    images[2] = {"bytes": b"\x89PNG garbage" + bytes(200), "path": None}
    at = table.schema.get_field_index("image")
    field = table.schema.field("image")
    table = table.set_column(at, field, pa.array(images, field.type))
    rewrite(copy, SHARD, table)
    report = validate_dataset(copy)
    assert checks(report) == {"images.decode"}
    (problem,) = report.problems
    assert (problem.file, problem.row, problem.field) == (SHARD, 2, "image")


def test_unlisted_shard(copy: Path) -> None:
    shutil.copy(copy / SHARD, copy / "observations/train/bathroom_999.parquet")
    report = validate_dataset(copy, quick=True)
    assert checks(report) == {"files.unlisted"}


def test_manifest_schema_and_version(copy: Path) -> None:
    edit_manifest(copy, lambda raw: raw.update(num_slots="many", format_version="1.0.0"))
    report = validate_dataset(copy, quick=True)
    assert find(report, "manifest.schema")[0].field == "num_slots"
    edit_manifest(copy, lambda raw: raw.update(format_version="3.0.0"))
    report = validate_dataset(copy, quick=True)
    assert "newer" in find(report, "manifest.version")[0].message


@pytest.mark.parametrize(
    ("path", "check"),
    [
        (("observations", "train"), "counts.observations"),
        (("triplets", "val"), "counts.triplets"),
        (("rooms",), "counts.rooms"),
    ],
)
def test_manifest_count_off_by_one(copy: Path, path: tuple[str, ...], check: str) -> None:
    def bump(manifest: dict) -> None:
        parent = manifest["counts"]
        for key in path[:-1]:
            parent = parent[key]
        parent[path[-1]] += 1

    edit_manifest(copy, bump)
    report = validate_dataset(copy, quick=True)
    assert check in checks(report)  # (a count that disagrees with another may be flagged too)
    (problem,) = find(report, check)
    assert problem.file == "dataset.json" and "the files hold" in problem.message


def test_manifest_tier_counts_checked(copy: Path) -> None:
    def shift(manifest: dict) -> None:
        tiers = manifest["counts"]["tiers"]["test"]
        tiers[0], tiers[1] = tiers[0] - 1, tiers[1] + 1

    edit_manifest(copy, shift)
    assert "counts.tiers" in checks(validate_dataset(copy, quick=True))


# ------------------------------------------------------------------ appearance (format 1.1)


def test_appearance_out_of_its_ranges(copy: Path) -> None:
    rows, schema = rows_of(copy, SHARD)
    rows[3]["light_intensity"] = 3.0  # the config draws [0.8, 1.2]
    rows[5]["light_temperature"] = None
    rows[6]["textures"] = None
    rewrite(copy, SHARD, pa.Table.from_pylist(rows, schema=schema))
    report = validate_dataset(copy, quick=True)
    problems = {(p.row, p.field) for p in find(report, "rows.appearance")}
    assert problems == {(3, "light_intensity"), (5, "light_temperature"), (6, "textures")}
    messages = {p.field: p.message for p in find(report, "rows.appearance")}
    assert "3.0: outside the configured [0.8, 1.2]" in messages["light_intensity"]
    assert checks(report) == {"rows.appearance"}


def test_a_format_1_0_dataset_without_appearance_columns_still_reads(copy: Path) -> None:
    from sgdata.dataset import Dataset

    added = ["textures", "light_intensity", "light_temperature"]
    legacy_dataset(copy, drop=added)

    def as_1_0(raw: dict) -> None:
        raw["format_version"] = "1.0.0"
        del raw["config"]["appearance"]

    edit_manifest(copy, as_1_0)
    report = validate_dataset(copy, quick=True)
    assert report.ok, report.problems[:3]
    views = Dataset.open(copy).observations("train", columns=["obs_id", *added])
    assert views.column("light_intensity").null_count == views.num_rows
    # a 1.1 dataset lacking them is reported
    edit_manifest(copy, lambda raw: raw.update(format_version="1.1.0"))
    report = validate_dataset(copy, quick=True)
    assert {p.field for p in find(report, "tables.schema")} == set(added)


def test_a_format_1_1_dataset_reads_validates_and_migrates(copy: Path, mini_dataset: Path) -> None:
    from sgdata.dataset import FORMAT_VERSION, Dataset, migrate_dataset

    legacy_dataset(copy)
    assert pq.read_schema(copy / SHARD).field("image").type == pa.binary()
    assert pq.read_schema(copy / SHARD).metadata[b"format_version"] == b"1.1.0"
    report = validate_dataset(copy)  # images decoded too
    assert report.ok, report.problems[:3]
    assert {"metadata.card", "metadata.croissant"} <= set(report.skipped)
    old, new = Dataset.open(copy), Dataset.open(mini_dataset)
    assert old.manifest.format_version == "1.1.0"  # read as it is, not renamed
    before, after = old.observations("train"), new.observations("train")
    derived = ["intrinsics", "camera_to_world"]  # 2.2.0's: null in an older file until migrated
    assert before.column("camera_to_world").null_count == before.num_rows
    assert before.drop_columns(["image", *derived]).equals(after.drop_columns(["image", *derived]))
    assert not before.column("image").equals(after.column("image"))  # other bytes, same pixels
    for a, b in zip(pixels(before.column("image")), pixels(after.column("image")), strict=True):
        assert np.array_equal(a, b)

    done = run_cli("sgdata", "migrate", copy)  # the command, end to end
    assert done.returncode == 0, done.stderr
    manifest = read_manifest(copy)
    assert manifest.format_version == FORMAT_VERSION
    report = validate_dataset(copy)
    assert report.ok and not {"metadata.card", "metadata.croissant"} & set(report.skipped)
    generated = {f.path: f.sha256 for f in new.manifest.files}
    migrated = {f.path: f.sha256 for f in manifest.files}
    assert migrated == generated  # the very bytes generate writes: tables, card, croissant
    assert (copy / "dataset.json").read_bytes() == (mini_dataset / "dataset.json").read_bytes()
    before = {p.name: p.read_bytes() for p in copy.iterdir() if p.is_file()}
    again = migrate_dataset(copy)  # a current dataset: nothing changes, to the byte
    assert {p.name: p.read_bytes() for p in copy.iterdir() if p.is_file()} == before
    assert again.files == manifest.files and again.format_version == manifest.format_version
    done = run_cli("sgdata", "migrate", copy / "scenes")
    assert done.returncode != 0 and "no dataset.json" in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1


def test_a_format_2_0_0_dataset_migrates_to_the_bytes_generate_writes(
    copy: Path, mini_dataset: Path
) -> None:
    from sgdata.dataset import FORMAT_VERSION, Dataset, migrate_dataset

    legacy_dataset(copy, version="2.0.0")  # the old PNG deflate, everything else as now
    assert validate_dataset(copy).ok
    assert migrate_dataset(copy).format_version == FORMAT_VERSION
    for entry in read_manifest(copy).files:  # each table says the version it now is
        if entry.path.endswith(".parquet"):
            stamp = pq.read_schema(copy / entry.path).metadata[b"format_version"]
            assert stamp == FORMAT_VERSION.encode(), entry.path
    generated = {f.path: f.sha256 for f in Dataset.open(mini_dataset).manifest.files}
    assert {f.path: f.sha256 for f in read_manifest(copy).files} == generated


def test_a_format_2_2_dataset_with_masks_migrates_to_the_structure_generate_draws(
    channels_dataset: Path, tmp_path: Path
) -> None:
    """2.3.0's structure mask is drawn again from each view's scene layer: the very bytes;
    without a renderer to draw it, migrate refuses before it writes anything."""
    from sgdata.dataset import FORMAT_VERSION, migrate_dataset
    from sgdata.pipeline.structure_masks import structure_column

    old = tmp_path / "old"
    shutil.copytree(channels_dataset, old)
    legacy_dataset(old, version="2.2.0")
    assert "structure" not in pq.read_schema(old / SHARD).names
    report = validate_dataset(old)
    assert report.ok, report.problems[:3]
    before = {p: p.read_bytes() for p in old.rglob("*") if p.is_file()}
    with pytest.raises(DatasetError, match="structure masks drawn from the scene layers"):
        migrate_dataset(old)
    assert {p: p.read_bytes() for p in old.rglob("*") if p.is_file()} == before
    assert migrate_dataset(old, draw_structure=structure_column).format_version == FORMAT_VERSION
    generated = {f.path: f.sha256 for f in read_manifest(channels_dataset).files}
    assert {f.path: f.sha256 for f in read_manifest(old).files} == generated


def test_migrating_a_png_that_does_not_decode_names_the_file(copy: Path) -> None:
    legacy_dataset(copy, version="2.0.0")
    table = pq.read_table(copy / SHARD)
    at = table.schema.get_field_index("image")
    cells = table.column("image").to_pylist()
    cells[0] = {"bytes": b"\x89PNG\r\n\x1a\n not a PNG", "path": None}
    broken = pa.array(cells, type=table.schema.field(at).type)
    rewrite(copy, SHARD, table.set_column(at, table.schema.field(at), broken))
    done = run_cli("sgdata", "migrate", copy)
    assert done.returncode != 0
    assert len(done.stderr.strip().splitlines()) == 1
    assert SHARD in done.stderr and "does not decode as PNG" in done.stderr
    assert read_manifest(copy).format_version == "2.0.0"  # the manifest is written last


def test_card_and_croissant_that_disagree_are_reported(copy: Path) -> None:
    card = copy / "README.md"
    text = card.read_text()
    card.write_text(text.replace("num_examples: ", "num_examples: 1", 1))
    crate = json.loads((copy / "croissant.json").read_text())
    crate["distribution"][0]["sha256"] = "0" * 64
    (copy / "croissant.json").write_text(json.dumps(crate))
    report = validate_dataset(copy, quick=True)
    assert checks(report) == {"metadata.card", "metadata.croissant", "files.sha256", "files.bytes"}
    (problem,) = find(report, "metadata.card")
    assert "num_examples: 1" in problem.message and problem.field.startswith("front matter line")
    (problem,) = find(report, "metadata.croissant")
    first = crate["distribution"][0]["@id"]
    assert problem.field == f"distribution[{first}].sha256"
    card.unlink()
    assert "missing" in find(validate_dataset(copy, quick=True), "metadata.card")[0].message


def test_a_shard_without_the_huggingface_metadata_is_reported(copy: Path) -> None:
    table = pq.read_table(copy / SHARD)
    metadata = {k: v for k, v in table.schema.metadata.items() if k != b"huggingface"}
    pq.write_table(table.replace_schema_metadata(metadata), copy / SHARD)
    raw = json.loads((copy / "dataset.json").read_text())
    for entry in raw["files"]:
        if entry["path"] == SHARD:
            data = (copy / SHARD).read_bytes()
            entry.update(sha256=hashlib.sha256(data).hexdigest(), bytes=len(data))
    (copy / "dataset.json").write_text(json.dumps(raw, indent=2))
    write_manifest(read_manifest(copy), copy)  # card and croissant.json follow the new sha256
    report = validate_dataset(copy, quick=True)
    (problem,) = find(report, "tables.schema")
    assert problem.file == SHARD and "'huggingface'" in problem.message
    assert checks(report) == {"tables.schema"}


def test_image_column_of_another_type(copy: Path) -> None:
    # image bytes stored as text raised TypeError in the image checks (found by tests/fuzz)
    table = pq.read_table(copy / SHARD)
    at = table.schema.get_field_index("image")
    texts = pa.array([str(v)[:20] for v in table.column("image").to_pylist()])
    rewrite(copy, SHARD, table.set_column(at, "image", texts))
    report = validate_dataset(copy)
    assert any(p.field == "image" for p in find(report, "tables.schema"))


# found by tests/fuzz: each raised a traceback (or a message of several lines) before its fix
def test_a_manifest_that_is_not_utf8(copy: Path) -> None:
    path = copy / "dataset.json"
    path.write_bytes(b"\x84" + path.read_bytes()[1:])
    with pytest.raises(DatasetError, match=r"dataset.json: not UTF-8 text \(invalid start byte"):
        Dataset.open(copy)
    assert checks(validate_dataset(copy, quick=True)) == {"manifest.json"}


def test_relation_rules_of_the_wrong_shape(copy: Path) -> None:
    edit_manifest(copy, lambda raw: raw["relation_rules"].update(containment_tolerance=None))
    report = validate_dataset(copy, quick=True)
    problems = find(report, "relations.recompute")  # one per split
    assert problems and all("relation_rules is {" in p.message for p in problems)


def test_an_unreadable_shard_is_one_line(copy: Path) -> None:
    data = (copy / SHARD).read_bytes()
    (copy / SHARD).write_bytes(data[:4] + bytes([data[4] ^ 0xFF]) + data[5:])
    with pytest.raises(DatasetError) as raised:
        split = SHARD.split("/")[1]
        Dataset.open(copy).observations(split)
    assert "not a readable Parquet file" in str(raised.value) and "\n" not in str(raised.value)


def test_text_that_is_not_utf8_in_a_shard(copy: Path) -> None:
    # a byte flipped in a shard's text ("synthetic" -> b"\x8cynthetic"): Parquet reads it without
    # a check, then validate's ids check raised ArrowException and a reader's to_pylist() a
    # UnicodeDecodeError (found by tests/fuzz)
    table = pq.read_table(copy / SHARD)
    at = table.schema.get_field_index("domain")
    flipped = [b"\x8c" + v.encode()[1:] for v in table.column("domain").to_pylist()]
    text = pa.array(flipped, pa.binary()).view(pa.string())
    rewrite(copy, SHARD, table.set_column(at, table.schema.field("domain"), text))
    with pytest.raises(DatasetError, match=r"column 'domain' .*UTF8") as raised:
        Dataset.open(copy).observations(SHARD.split("/")[1])
    assert "\n" not in str(raised.value)
    report = validate_dataset(copy, quick=True)
    (problem,) = find(report, "tables.schema")
    assert problem.file == SHARD and "column 'domain'" in problem.message
