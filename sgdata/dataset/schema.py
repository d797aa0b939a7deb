"""The on-disk contract's schemas: the JSON table DSL in ``schemas/`` parsed into Arrow.

One version constant, :data:`FORMAT_VERSION`, covers the whole format (both tables and the
manifest), and one check, :func:`check_compatible`, decides what this sgdata reads: the same
major version (an older minor first passes through :data:`MIGRATIONS`, keyed by the version
migrated *from*; a newer minor has unknown manifest keys dropped, minors only add). Any other
major is refused with the command that fixes it.

The writer builds its tables against these schemas and the reader checks files against them,
so the JSON files in ``schemas/`` (installed as the ``sgdata_schemas`` package)
are the single source of truth.

The DSL: a table is ``{"name", "format_version", "doc", "fields": [field, ...]}``; a field is
``{"name", "type", "nullable", "doc"}``, plus ``"since": "<version>"`` on a nullable column a
minor version added (Arrow metadata ``b"since"``: readers fill it with nulls in files of an
older minor, and :func:`schema_at` drops it from what such a file must hold); a type is one
of ``string binary bool int8 int16 int32 int64 float32 float64``, ``image`` (encoded bytes in
memory, Hugging Face ``Image`` storage on disk: :mod:`sgdata.dataset.storage`, and
:func:`file_schema`), ``{"list": T}``, ``{"fixed_list": [T, n]}`` or ``{"struct": [field, ...]}``.
Field docs become Arrow field metadata under ``b"doc"``. List elements are non-null and named
``element`` (the Parquet-compliant name, so a schema read back from a file compares equal to
the one written).
"""

from __future__ import annotations

import json
import logging
import re
from collections.abc import Callable, Mapping
from functools import cache
from importlib import resources
from typing import Any

import pyarrow as pa

from sgdata.dataset.storage import (
    HF_METADATA_KEY,
    IMAGE_STORAGE_SINCE,
    STORAGE_KEY,
    hf_schema_metadata,
    is_image_field,
    stored_image_field,
)
from sgdata.errors import DatasetError
from sgdata.markdown import table

__all__ = [
    "FORMAT_VERSION",
    "MIGRATIONS",
    "SCHEMA_PACKAGE",
    "OLDEST_READABLE",
    "SAME_RECIPE_AS",
    "FormatVersionError",
    "check_compatible",
    "file_schema",
    "migrate_manifest_dict",
    "observations_schema",
    "parse_version",
    "triplets_schema",
    "manifest_json_schema",
    "table_schema",
    "parse_table_schema",
    "primitive_name",
    "schema_at",
    "schema_markdown",
    "since",
]

FORMAT_VERSION = "2.3.0"  # semver of the whole on-disk format: tables + dataset.json
# 1.1.0 added the observation columns textures, light_intensity and light_temperature; 2.0.0
# stores `image` as the Hugging Face Image struct and adds README.md and croissant.json; 2.0.1
# deflates PNGs with zlib's RLE strategy (same pixels, other bytes; readers change nothing).
# 2.1.0 adds the optional per-view channels depth and instances (nullable image columns).
# 2.2.0 adds each view's camera, intrinsics and camera_to_world (sgdata.dataset.camera),
# derived from columns 2.1.0 has: `sgdata migrate` fills them in an older dataset.
# 2.3.0 adds the structure mask (wall, floor, ceiling, door), stored with the instance mask;
# `sgdata migrate` renders it for an older dataset that stores instance masks.
# The oldest format this sgdata reads: 1.x differs from 2.x only in how images are stored
# (sgdata.dataset.storage reads both) and in lacking the card and Croissant files.
OLDEST_READABLE = "1.0.0"
SCHEMA_PACKAGE = "sgdata_schemas"  # the installed name of the repository's `schemas/` folder
LIST_ELEMENT = "element"  # Parquet's compliant list element name (pyarrow writes it by default)
UPGRADE_HINT = "upgrade sgdata: pip install -U sgdata"
# from-version -> function taking the raw manifest dict of that version and returning the dict
# of the next version (with its format_version set). Empty: 1.1.0 only added nullable columns
# (marked "since"), and 1.0.0 manifests need no change.
MIGRATIONS: dict[str, Callable[[dict[str, Any]], dict[str, Any]]] = {}
# version -> the version whose recipe it shares: a bump that only adds what the same config
# and seed already determine (columns derived from others, a mask drawn from the same scene)
# asks the generator for nothing new, so a dataset keeps its recipe fingerprint (and the
# results recorded on it, DESIGN §12) across it (Manifest.recipe_fingerprint)
SAME_RECIPE_AS = {"2.2.0": "2.1.0", "2.3.0": "2.2.0"}
_SEMVER = re.compile(r"^(0|[1-9]\d*)\.(0|[1-9]\d*)\.(0|[1-9]\d*)(?:[-+][0-9A-Za-z.+-]+)?$")
log = logging.getLogger(__name__)

_PRIMITIVES: dict[str, pa.DataType] = {
    "string": pa.string(),
    "binary": pa.binary(),
    "bool": pa.bool_(),
    "int8": pa.int8(),
    "int16": pa.int16(),
    "int32": pa.int32(),
    "int64": pa.int64(),
    "float32": pa.float32(),
    "float64": pa.float64(),
}
_IMAGE = "image"  # the DSL's image type: binary in memory, IMAGE_STORAGE on disk
_FIELD_KEYS = {"name", "type", "nullable", "doc"}
_OPTIONAL_KEYS = {"since"}


def _read_json(filename: str) -> dict[str, Any]:
    try:
        text = resources.files(SCHEMA_PACKAGE).joinpath(filename).read_text(encoding="utf-8")
    except FileNotFoundError:
        raise DatasetError(
            f"schema file {filename!r} is missing from the {SCHEMA_PACKAGE} package; "
            "reinstall sgdata (pip install -e . in a checkout)"
        ) from None
    return json.loads(text)


def _parse_type(spec: Any, where: str) -> pa.DataType:
    if isinstance(spec, str):
        if spec == _IMAGE:
            return pa.binary()
        if spec not in _PRIMITIVES:
            raise DatasetError(
                f"{where}: unknown type {spec!r}; expected one of {[*_PRIMITIVES, _IMAGE]}"
            )
        return _PRIMITIVES[spec]
    if isinstance(spec, dict) and len(spec) == 1:
        ((kind, arg),) = spec.items()
        if kind == "list":
            element = pa.field(LIST_ELEMENT, _parse_type(arg, f"{where}[]"), nullable=False)
            return pa.list_(element)
        if kind == "fixed_list" and isinstance(arg, list) and len(arg) == 2:
            inner, size = arg
            if not isinstance(size, int) or size < 1:
                raise DatasetError(f"{where}: fixed_list size {size!r}; expected an int >= 1")
            element = pa.field(LIST_ELEMENT, _parse_type(inner, f"{where}[]"), nullable=False)
            return pa.list_(element, size)
        if kind == "struct" and isinstance(arg, list):
            return pa.struct([_parse_field(f, where) for f in arg])
    raise DatasetError(
        f"{where}: malformed type {spec!r}; expected a primitive name, "
        '{"list": T}, {"fixed_list": [T, n]} or {"struct": [fields]}'
    )


def _parse_field(spec: Any, parent: str) -> pa.Field:
    if not isinstance(spec, dict) or not _FIELD_KEYS <= set(spec) <= _FIELD_KEYS | _OPTIONAL_KEYS:
        raise DatasetError(
            f"{parent}: field {spec!r}; expected exactly the keys {sorted(_FIELD_KEYS)} "
            f"(and optionally {sorted(_OPTIONAL_KEYS)})"
        )
    where = f"{parent}.{spec['name']}"
    if not isinstance(spec["nullable"], bool):
        raise DatasetError(f"{where}: nullable {spec['nullable']!r}; expected true or false")
    metadata = {b"doc": str(spec["doc"]).encode("utf-8")}
    if spec["type"] == _IMAGE:
        metadata[STORAGE_KEY] = _IMAGE.encode()
    if "since" in spec:
        added = spec["since"]
        if not spec["nullable"] or parse_version(added) > parse_version(FORMAT_VERSION):
            raise DatasetError(
                f"{where}: since {added!r}; only a nullable column may be added, in a version "
                f"up to {FORMAT_VERSION}"
            )
        metadata[b"since"] = str(added).encode("utf-8")
    return pa.field(
        spec["name"], _parse_type(spec["type"], where), nullable=spec["nullable"], metadata=metadata
    )


def since(field: pa.Field) -> str | None:
    """The format version that added column ``field``, or None for one as old as the major."""
    value = (field.metadata or {}).get(b"since")
    return value.decode() if value else None


def schema_at(schema: pa.Schema, version: str) -> pa.Schema:
    """``schema`` as a file of format ``version`` holds it: without the columns added later.

    Raises:
        FormatVersionError: ``version`` is not a semantic version.
    """
    at = parse_version(version)
    keep = [f for f in schema if since(f) is None or parse_version(since(f)) <= at]
    return pa.schema(keep, metadata=schema.metadata)


def file_schema(schema: pa.Schema, version: str = FORMAT_VERSION) -> pa.Schema:
    """``schema`` (in memory) as a Parquet file of format ``version`` holds it: without the
    columns added later and, from 2.0.0, image columns as Hugging Face ``Image`` storage with
    the ``huggingface`` schema metadata (as :func:`sgdata.dataset.storage.file_table` writes).

    Raises:
        FormatVersionError: ``version`` is not a semantic version.
    """
    at = schema_at(schema, version)
    if parse_version(version) < parse_version(IMAGE_STORAGE_SINCE) or not any(
        is_image_field(f) for f in at
    ):
        return at
    fields = [stored_image_field(f) if is_image_field(f) else f for f in at]
    metadata = {**(at.metadata or {}), HF_METADATA_KEY: hf_schema_metadata(at)}
    return pa.schema(fields, metadata=metadata)


def parse_table_schema(spec: dict[str, Any]) -> pa.Schema:
    """Arrow schema of one table from its DSL dict (see the module docstring).

    Schema metadata holds ``name``, ``doc`` and ``format_version``.

    Raises:
        DatasetError: malformed DSL, or a ``format_version`` other than :data:`FORMAT_VERSION`.
    """
    name = spec.get("name", "?")
    if spec.get("format_version") != FORMAT_VERSION:
        raise DatasetError(
            f"schema {name!r}: format_version {spec.get('format_version')!r}; "
            f"expected {FORMAT_VERSION} (sgdata.schema.FORMAT_VERSION)"
        )
    fields = [_parse_field(f, name) for f in spec.get("fields", [])]
    names = [f.name for f in fields]
    if len(set(names)) != len(names) or not names:
        raise DatasetError(f"schema {name!r}: expected unique, non-empty field names: {names}")
    return pa.schema(
        fields,
        metadata={
            b"name": str(name).encode(),
            b"doc": str(spec.get("doc", "")).encode(),
            b"format_version": FORMAT_VERSION.encode(),
        },
    )


@cache
def table_schema(name: str) -> pa.Schema:
    """The Arrow schema of table ``name`` (``observations`` or ``triplets``)."""
    major = FORMAT_VERSION.split(".", 1)[0]
    return parse_table_schema(_read_json(f"{name}.v{major}.json"))


def observations_schema() -> pa.Schema:
    """Schema of ``observations/<split>/<room>.parquet``: one row per view."""
    return table_schema("observations")


def triplets_schema() -> pa.Schema:
    """Schema of ``triplets/<split>.parquet``: one row per cascaded triplet."""
    return table_schema("triplets")


@cache
def _manifest_json_schema_text() -> str:
    major = FORMAT_VERSION.split(".", 1)[0]
    return json.dumps(_read_json(f"manifest.v{major}.schema.json"))


def manifest_json_schema() -> dict[str, Any]:
    """The JSON Schema (2020-12) of ``dataset.json`` (a fresh copy: callers may mutate it)."""
    return json.loads(_manifest_json_schema_text())


# --------------------------------------------------------------------------- versions


class FormatVersionError(DatasetError):
    """The dataset's ``format_version`` is malformed or not readable by this sgdata."""


def parse_version(version: object) -> tuple[int, int, int]:
    """``(major, minor, patch)`` of a format version (pre-release and build tags dropped).

    Raises:
        FormatVersionError: not a semantic version.
    """
    match = _SEMVER.match(version) if isinstance(version, str) else None
    if match is None:
        raise FormatVersionError(
            f"dataset.json format_version {version!r}: expected a semantic version like "
            f"{FORMAT_VERSION}; the manifest is corrupt (regenerate the dataset)"
        )
    return int(match[1]), int(match[2]), int(match[3])


def check_compatible(manifest_version: str, *, current: str | None = None) -> None:
    """Whether this sgdata reads a dataset of format ``manifest_version``; raises if not.

    ``current`` defaults to :data:`~sgdata.schema.FORMAT_VERSION`; the majors from
    :data:`OLDEST_READABLE`'s up to ``current``'s are read.

    Raises:
        FormatVersionError: malformed version, or a major outside that range.
    """
    major = parse_version(manifest_version)[0]
    ours = parse_version(current or FORMAT_VERSION)[0]
    oldest = min(parse_version(OLDEST_READABLE)[0], ours)
    if major > ours:
        raise FormatVersionError(
            f"dataset.json format_version {manifest_version} is newer than this sgdata reads "
            f"({ours}.x); {UPGRADE_HINT}"
        )
    if major < oldest:
        raise FormatVersionError(
            f"dataset.json format_version {manifest_version} is older than this sgdata reads "
            f"({oldest}.x to {ours}.x); read it with an older sgdata "
            f"(pip install 'sgdata<{oldest}') or regenerate it: sgdata generate"
        )


def migrate_manifest_dict(
    raw: dict[str, Any],
    *,
    current: str | None = None,
    migrations: Mapping[str, Callable[[dict[str, Any]], dict[str, Any]]] | None = None,
) -> dict[str, Any]:
    """``raw`` (a parsed ``dataset.json``) brought to the shape of version ``current``
    (default :data:`~sgdata.schema.FORMAT_VERSION`).

    Older minors go through ``migrations`` (default :data:`MIGRATIONS`) step by step; a
    version with no registered migration is taken as is. Newer minors lose the top-level
    keys the current schema does not know.

    Raises:
        FormatVersionError: see :func:`check_compatible`; or a migration loops.
    """
    current = current or FORMAT_VERSION
    migrations = MIGRATIONS if migrations is None else migrations
    version = raw.get("format_version")
    check_compatible(version, current=current)
    seen: set[str] = set()
    while parse_version(version) < parse_version(current) and version in migrations:
        if version in seen:
            raise FormatVersionError(f"manifest migrations loop at format_version {version}")
        seen.add(version)
        raw = migrations[version](dict(raw))
        new = raw.get("format_version")
        check_compatible(new, current=current)
        log.info("migrated dataset.json from format %s to %s", version, new)
        version = new
    if parse_version(version) > parse_version(current):
        known = set(manifest_json_schema()["properties"])
        dropped = sorted(set(raw) - known)
        if dropped:
            log.warning(
                "dataset.json format %s: ignoring keys this sgdata does not know: %s",
                version,
                dropped,
            )
        raw = {k: v for k, v in raw.items() if k in known}
    return raw


# --------------------------------------------------------------------------- docs


def _type_text(t: pa.DataType, field: pa.Field | None = None) -> str:
    if pa.types.is_fixed_size_list(t):
        return f"{_type_text(t.value_type)}[{t.list_size}]"
    if pa.types.is_list(t):
        return f"list<{_type_text(t.value_type)}>"
    if pa.types.is_struct(t):
        return "struct"
    if pa.types.is_binary(t) and field is not None and is_image_field(field):
        return _IMAGE
    return primitive_name(t)


def primitive_name(t: pa.DataType) -> str:
    """The DSL name of a primitive Arrow type (``int16``, ``float64`` ...; also the dtype
    names of Hugging Face ``datasets``)."""
    return next(name for name, p in _PRIMITIVES.items() if p == t)


def _rows(fields: list[pa.Field], prefix: str) -> list[tuple[str, str, str, str]]:
    lines: list[tuple[str, str, str, str]] = []
    for f in fields:
        doc = (f.metadata or {}).get(b"doc", b"").decode()
        if since(f):
            doc = f"{doc} (since format {since(f)})"
        doc = doc.replace("|", "\\|").replace("<", "\\<")  # Markdown table cell
        null = "yes" if f.nullable else "no"
        lines.append((f"`{prefix}{f.name}`", f"`{_type_text(f.type, f)}`", null, doc))
        inner = f.type
        while pa.types.is_list(inner) or pa.types.is_fixed_size_list(inner):
            inner = inner.value_type
        if pa.types.is_struct(inner):
            sep = "[]." if inner is not f.type else "."
            lines.extend(
                _rows([inner.field(i) for i in range(inner.num_fields)], f"{prefix}{f.name}{sep}")
            )
    return lines


def schema_markdown(schema: pa.Schema) -> str:
    """A Markdown table of ``schema``'s fields (nested ones as ``objects[].slot``), from docs."""
    header = ("column", "type", "nullable", "meaning")
    return "\n".join(table(header, _rows(list(schema), ""))) + "\n"
