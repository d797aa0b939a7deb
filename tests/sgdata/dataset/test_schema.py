"""The schema DSL in schemas/ parses into Arrow schemas, docs included, and matches the docs."""

from __future__ import annotations

import json
from importlib import resources
from pathlib import Path

import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from sgdata.dataset.schema import (
    FORMAT_VERSION,
    manifest_json_schema,
    observations_schema,
    parse_table_schema,
    schema_markdown,
    table_schema,
    triplets_schema,
)
from sgdata.errors import DatasetError

DOCS = Path(__file__).resolve().parents[3] / "docs" / "dataset.md"


def _dsl(name: str) -> dict:
    major = FORMAT_VERSION.split(".")[0]
    text = resources.files("sgdata_schemas").joinpath(f"{name}.v{major}.json").read_text()
    return json.loads(text)


def _walk(fields: list, schema_fields: list[pa.Field]) -> None:
    """Every DSL field has its Arrow field with the same name, nullability and doc."""
    assert [f["name"] for f in fields] == [f.name for f in schema_fields]
    for spec, arrow in zip(fields, schema_fields, strict=True):
        assert arrow.nullable is spec["nullable"]
        assert arrow.metadata[b"doc"].decode() == spec["doc"]
        t, s = arrow.type, spec["type"]
        while isinstance(s, dict) and ("list" in s or "fixed_list" in s):
            s = s["list"] if "list" in s else s["fixed_list"][0]
            assert not t.value_field.nullable  # list elements are never null
            t = t.value_type
        if isinstance(s, dict):
            _walk(s["struct"], [t.field(i) for i in range(t.num_fields)])


def test_version_is_semver_and_files_agree() -> None:
    assert len(FORMAT_VERSION.split(".")) == 3
    for name in ("observations", "triplets"):
        assert _dsl(name)["format_version"] == FORMAT_VERSION
        assert table_schema(name).metadata[b"format_version"] == FORMAT_VERSION.encode()


@pytest.mark.parametrize("name", ["observations", "triplets"])
def test_dsl_round_trips_names_nullability_docs(name: str) -> None:
    schema = table_schema(name)
    _walk(_dsl(name)["fields"], list(schema))


def test_types() -> None:
    obs = observations_schema()
    assert obs.field("obs_id").type == pa.string()
    assert obs.field("image").type == pa.binary()
    assert obs.field("heading").type == pa.int8()
    objects = obs.field("objects").type
    assert pa.types.is_list(objects)
    box2d = objects.value_type.field("box2d").type
    assert pa.types.is_fixed_size_list(box2d) and box2d.list_size == 4
    assert box2d.value_type == pa.int16()
    tri = triplets_schema()
    assert tri.field("positive_offset").type.list_size == 3


def test_cached() -> None:
    assert observations_schema() is observations_schema()
    a = manifest_json_schema()
    a["mutated"] = True
    assert "mutated" not in manifest_json_schema()


def test_schema_survives_parquet(tmp_path: Path) -> None:
    """Field docs and the element names come back from a Parquet file unchanged."""
    schema = observations_schema()
    pq.write_table(schema.empty_table(), tmp_path / "x.parquet")
    back = pq.read_schema(tmp_path / "x.parquet")
    assert back.equals(schema, check_metadata=True)


@pytest.mark.parametrize(
    ("field", "message"),
    [
        ({"name": "a", "type": "int128", "nullable": False, "doc": ""}, "unknown type"),
        ({"name": "a", "type": {"set": "int8"}, "nullable": False, "doc": ""}, "malformed type"),
        ({"name": "a", "type": "int8", "nullable": "no", "doc": ""}, "nullable"),
        ({"name": "a", "type": "int8", "nullable": False}, "expected exactly the keys"),
        ({"name": "a", "type": {"fixed_list": ["int8", 0]}, "nullable": False, "doc": ""}, "size"),
    ],
)
def test_malformed_dsl_is_refused(field: dict, message: str) -> None:
    spec = {"name": "t", "format_version": FORMAT_VERSION, "doc": "", "fields": [field]}
    with pytest.raises(DatasetError, match=message):
        parse_table_schema(spec)


def test_other_format_version_is_refused() -> None:
    spec = {"name": "t", "format_version": "9.0.0", "doc": "", "fields": []}
    with pytest.raises(DatasetError, match="9.0.0"):
        parse_table_schema(spec)


def test_manifest_json_schema_is_valid_2020_12() -> None:
    import jsonschema

    schema = manifest_json_schema()
    jsonschema.Draft202012Validator.check_schema(schema)
    assert schema["additionalProperties"] is False
    assert set(schema["required"]) == set(schema["properties"])


@pytest.mark.parametrize("name", ["observations", "triplets"])
def test_docs_tables_match_the_schemas(name: str) -> None:
    """docs/dataset.md carries the generated field tables: regenerate them when schemas change
    (python -c 'from sgdata.dataset.schema import *;
    print(schema_markdown(table_schema("...")))')."""
    assert schema_markdown(table_schema(name)) in DOCS.read_text(encoding="utf-8")
