"""Table checks: each Parquet file's Arrow schema against ``schemas/`` field by field (names,
types, nullability, nested fields included); ids and the columns that repeat the path."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.parquet as pq

from sgdata.dataset.channels import CHANNELS
from sgdata.dataset.paths import observations_path, triplets_path
from sgdata.dataset.schema import (
    FORMAT_VERSION,
    file_schema,
    observations_schema,
    triplets_schema,
)
from sgdata.dataset.storage import HF_METADATA_KEY
from sgdata.errors import one_line
from sgdata.validate.loading import SplitTables, column_numpy, read_table_as
from sgdata.validate.problems import Collector

__all__ = ["compare_schema", "load_split", "check_ids"]


def _type_name(t: pa.DataType) -> str:
    if pa.types.is_struct(t):
        return "struct"
    if pa.types.is_fixed_size_list(t):
        return f"{_type_name(t.value_type)}[{t.list_size}]"
    if pa.types.is_list(t) or pa.types.is_large_list(t):
        return f"list<{_type_name(t.value_type)}>"
    return str(t)


def _compare_type(found: pa.DataType, wanted: pa.DataType, name: str) -> list[tuple[str, str]]:
    mismatch = [(name, f"type {_type_name(found)}; expected {_type_name(wanted)}")]
    if pa.types.is_struct(wanted):
        if not pa.types.is_struct(found):
            return mismatch
        return _compare_fields(
            [found.field(i) for i in range(found.num_fields)],
            [wanted.field(i) for i in range(wanted.num_fields)],
            f"{name}.",
            extra_ok=False,
        )
    if pa.types.is_fixed_size_list(wanted) or pa.types.is_list(wanted):
        same = (
            pa.types.is_fixed_size_list(found) and found.list_size == wanted.list_size
            if pa.types.is_fixed_size_list(wanted)
            else pa.types.is_list(found)
        )
        if not same:
            return mismatch
        fe, we = found.value_field, wanted.value_field
        out = []
        if fe.nullable != we.nullable:
            out.append((f"{name}[]", f"elements nullable={fe.nullable}; expected {we.nullable}"))
        inner = _compare_type(fe.type, we.type, f"{name}[]")
        if inner and not pa.types.is_struct(we.type):
            return out + mismatch  # report a wrong element type as the column's type
        return out + inner
    return [] if found.equals(wanted) else mismatch


def _compare_fields(
    found: list[pa.Field], wanted: list[pa.Field], prefix: str, *, extra_ok: bool
) -> list[tuple[str, str]]:
    """(field path, message) for each difference between two field lists."""
    out: list[tuple[str, str]] = []
    have = {f.name: f for f in found}
    for w in wanted:
        name = f"{prefix}{w.name}"
        f = have.get(w.name)
        if f is None:
            out.append((name, f"column missing; expected {_type_name(w.type)}"))
            continue
        if f.nullable != w.nullable:
            expected = "nullable" if w.nullable else "not nullable"
            out.append((name, f"nullable={f.nullable}; expected {expected}"))
        out.extend(_compare_type(f.type, w.type, name))
    if not extra_ok:
        known = {w.name for w in wanted}
        out.extend(
            (f"{prefix}{f.name}", "column not in the format's schema")
            for f in found
            if f.name not in known
        )
    return out


def compare_schema(
    found: pa.Schema, wanted: pa.Schema, *, extra_ok: bool = False
) -> list[tuple[str | None, str]]:
    """Differences between a file's schema and the format's: ``(field path, message)`` each.

    ``extra_ok``: columns beyond the format's are allowed (a newer minor format adds them).
    """
    return _compare_fields(list(found), list(wanted), "", extra_ok=extra_ok)


def _schema_check(root: Path, rel: str, wanted: pa.Schema, out: Collector, extra_ok: bool) -> bool:
    out.count("tables.schema")
    try:
        found = pq.read_schema(root / rel)
    except (pa.ArrowException, OSError) as exc:
        out.add("tables.schema", rel, f"not a readable Parquet file ({one_line(exc)})")
        return False
    diffs = compare_schema(found, wanted, extra_ok=extra_ok)
    hf = (wanted.metadata or {}).get(HF_METADATA_KEY)
    if hf is not None and (found.metadata or {}).get(HF_METADATA_KEY) != hf:
        diffs.append(
            (
                None,
                "schema metadata 'huggingface' missing or not the image features; datasets "
                f"will not decode the images (expected {hf.decode()})",
            )
        )
    for where, message in diffs:
        out.add("tables.schema", rel, message, field=where)
    return not diffs


def load_split(
    root: Path, raw: dict[str, Any], split: str, out: Collector, *, extra_ok: bool
) -> SplitTables:
    """Schema-check and read one split's shards (no images) and triplet table.

    Files must hold the columns of the dataset's own format version, stored as that version
    stores them (``file_schema``); columns a later minor added are read as nulls from an older
    dataset."""
    obs_schema = observations_schema()
    version = str(raw.get("format_version", FORMAT_VERSION))
    obs_wanted = file_schema(obs_schema, version)
    tables, files, file_index, file_row = [], [], [], []
    for room in raw["splits"][split]:
        rel = observations_path(split, room)
        if not (root / rel).is_file():
            continue  # reported by files.exist
        _schema_check(root, rel, obs_wanted, out, extra_ok)
        table = read_table_as(root / rel, obs_schema, skip=("image", *CHANNELS))
        if isinstance(table, str):
            out.add("tables.schema", rel, f"rows not checked: {table}")
            continue
        files.append(rel)
        tables.append(table)
        file_index.append(np.full(table.num_rows, len(files) - 1, dtype=np.int64))
        file_row.append(np.arange(table.num_rows, dtype=np.int64))
    observations = pa.concat_tables(tables).combine_chunks() if tables else None
    trel = triplets_path(split)
    triplets = None
    if (root / trel).is_file():
        _schema_check(root, trel, file_schema(triplets_schema(), version), out, extra_ok)
        read = read_table_as(root / trel, triplets_schema())
        if isinstance(read, str):
            out.add("tables.schema", trel, f"rows not checked: {read}")
        else:
            triplets = read.combine_chunks()
    empty = np.zeros(0, dtype=np.int64)
    return SplitTables(
        split=split,
        observations=observations,
        files=files,
        file_index=np.concatenate(file_index) if file_index else empty,
        file_row=np.concatenate(file_row) if file_row else empty,
        triplets=triplets,
        triplets_file=trel,
    )


def check_ids(tables: SplitTables, out: Collector) -> None:
    """Per observation row: split, room and obs_id agree with the shard; ids unique."""
    obs = tables.observations
    if obs is None:
        return
    n = obs.num_rows
    shard_room = np.array([Path(f).stem for f in tables.files], dtype=object)[tables.file_index]
    checks = {
        "split": column_numpy(obs, "split") != tables.split,
        "room_id": column_numpy(obs, "room_id") != shard_room,
    }
    ids = column_numpy(obs, "obs_id").astype(str)
    domain = column_numpy(obs, "domain")
    synthetic = domain == "synthetic"
    expect = pc.binary_join_element_wise(
        obs.column("room_id"),
        pc.cast(obs.column("layout"), pa.string()),
        pc.cast(obs.column("grid_i"), pa.string()),
        pc.cast(obs.column("grid_j"), pa.string()),
        pc.cast(obs.column("heading"), pa.string()),
        "/",
    )
    expect = column_numpy(pa.table({"e": expect}), "e", "")
    checks["obs_id"] = synthetic & (ids != expect.astype(str))
    prefix = np.char.add(column_numpy(obs, "room_id").astype(str), "/")
    checks["obs_id"] |= ~synthetic & ~np.char.startswith(ids, prefix)
    checks["domain"] = ~np.isin(domain, ["synthetic", "real"])
    checks["image_format"] = ~np.isin(column_numpy(obs, "image_format"), ["png", "jpeg"])
    out.count("tables.columns", n)
    messages = {
        "split": f"not {tables.split!r}, the split of its shard",
        "room_id": "not the room of its shard",
        "obs_id": "does not match <room_id>/<layout>/<grid_i>/<grid_j>/<heading> of the row",
        "domain": "expected synthetic or real",
        "image_format": "expected png or jpeg",
    }
    for name, bad in checks.items():
        values = column_numpy(obs, name if name != "obs_id" else "obs_id")
        for r in np.flatnonzero(bad):
            f, row = tables.where(r)
            out.add(
                "tables.columns",
                tables.files[f],
                f"{values[r]!r}: {messages[name]}",
                row=row,
                field=name,
            )
    out.count("tables.unique_ids", n)
    uniq, first, counts = np.unique(ids, return_index=True, return_counts=True)
    for k in np.flatnonzero(counts > 1):
        dup = np.flatnonzero(ids == uniq[k])
        for r in dup[1:]:
            f, row = tables.where(r)
            out.add(
                "tables.unique_ids",
                tables.files[f],
                f"obs_id {uniq[k]!r} repeats (first at row {tables.file_row[dup[0]]})",
                row=row,
                field="obs_id",
            )
