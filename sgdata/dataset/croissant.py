"""``croissant.json``: the dataset as MLCommons Croissant 1.1 metadata (JSON-LD).

Distribution: every Parquet file of the manifest as a ``cr:FileObject`` with its sha256, and
one ``cr:FileSet`` per table that the record sets read. Record sets: ``splits`` (train / val
/ test as Croissant splits), ``observations`` (one record per view, the image decoded),
``objects`` and ``relations`` (per view, the lists of structs as arrays of sub-fields) and
``triplets``. The fields follow the schemas of :mod:`sgdata.dataset.schema`, so the metadata
changes when the format does and never by hand. Deterministic: the one date is the sgdata
release's (``sgdata.__release_date__``), and no host is named.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING, Any

import pyarrow as pa

from sgdata import __release_date__
from sgdata.dataset.card import DATA_LICENSE_URL, PAPER_URL
from sgdata.dataset.paths import CROISSANT, OBSERVATIONS, TRIPLETS
from sgdata.dataset.schema import observations_schema, triplets_schema
from sgdata.dataset.storage import is_image_field
from sgdata.fileio import atomic_write_text

if TYPE_CHECKING:
    from sgdata.dataset.manifest import Manifest

__all__ = ["CONFORMS_TO", "croissant_dict", "croissant_json", "write_croissant"]

CONFORMS_TO = "http://mlcommons.org/croissant/1.1"
PARQUET = "application/x-parquet"
# The Croissant 1.1 JSON-LD context, as mlcroissant writes it.
CONTEXT: dict[str, Any] = {
    "@language": "en",
    "@vocab": "https://schema.org/",
    "arrayShape": "cr:arrayShape",
    "citeAs": "cr:citeAs",
    "column": "cr:column",
    "conformsTo": "dct:conformsTo",
    "containedIn": "cr:containedIn",
    "cr": "http://mlcommons.org/croissant/",
    "rai": "http://mlcommons.org/croissant/RAI/",
    "data": {"@id": "cr:data", "@type": "@json"},
    "dataType": {"@id": "cr:dataType", "@type": "@vocab"},
    "dct": "http://purl.org/dc/terms/",
    "equivalentProperty": "cr:equivalentProperty",
    "examples": {"@id": "cr:examples", "@type": "@json"},
    "extract": "cr:extract",
    "field": "cr:field",
    "fileProperty": "cr:fileProperty",
    "fileObject": "cr:fileObject",
    "fileSet": "cr:fileSet",
    "format": "cr:format",
    "includes": "cr:includes",
    "isArray": "cr:isArray",
    "isLiveDataset": "cr:isLiveDataset",
    "jsonPath": "cr:jsonPath",
    "key": "cr:key",
    "md5": "cr:md5",
    "parentField": "cr:parentField",
    "path": "cr:path",
    "recordSet": "cr:recordSet",
    "references": "cr:references",
    "regex": "cr:regex",
    "repeated": "cr:repeated",
    "replace": "cr:replace",
    "samplingRate": "cr:samplingRate",
    "sc": "https://schema.org/",
    "separator": "cr:separator",
    "source": "cr:source",
    "subField": "cr:subField",
    "transform": "cr:transform",
}
_SPLIT_URLS = {"train": "cr:TrainingSplit", "val": "cr:ValidationSplit", "test": "cr:TestSplit"}


def _data_type(t: pa.DataType, field: pa.Field) -> str:
    if is_image_field(field):
        return "sc:ImageObject"
    if pa.types.is_boolean(t):
        return "sc:Boolean"
    if pa.types.is_integer(t):
        return "sc:Integer"
    if pa.types.is_floating(t):
        return "sc:Float"
    return "sc:Text"


def _leaf(field: pa.Field, at: str, source: dict[str, Any]) -> dict[str, Any]:
    """A field read from ``source``; lists of primitives become arrays."""
    out: dict[str, Any] = {
        "@type": "cr:Field",
        "@id": at,
        "name": field.name,
        "description": (field.metadata or {}).get(b"doc", b"").decode(),
    }
    t = field.type
    if pa.types.is_list(t) or pa.types.is_fixed_size_list(t):
        out["isArray"] = True
        out["arrayShape"] = str(t.list_size) if pa.types.is_fixed_size_list(t) else "-1"
        t = t.value_type
    out["dataType"] = _data_type(t, field)
    out["source"] = source
    return out


def _field(field: pa.Field, record_set: str, file_set: str) -> dict[str, Any]:
    """A top-level column as a Croissant field; structs and lists of structs get sub-fields
    picked from the column by JSON path."""
    at = f"{record_set}/{field.name}"
    column = {"fileSet": {"@id": file_set}, "extract": {"column": field.name}}
    t = field.type
    inner = t.value_type if pa.types.is_list(t) else t
    if not pa.types.is_struct(inner):
        if is_image_field(field):  # on disk the {bytes, path} struct: take the bytes
            column = {**column, "transform": {"jsonPath": "bytes"}}
        return _leaf(field, at, column)
    subs = [
        _leaf(child, f"{at}/{child.name}", {**column, "transform": {"jsonPath": child.name}})
        for child in (inner.field(i) for i in range(inner.num_fields))
    ]
    out = {
        "@type": "cr:Field",
        "@id": at,
        "name": field.name,
        "description": (field.metadata or {}).get(b"doc", b"").decode(),
        "dataType": "sc:Text",
        "subField": subs,
    }
    if inner is not t:
        out["isArray"] = True
        out["arrayShape"] = "-1"
    return out


def _record_set(
    name: str, doc: str, schema: pa.Schema, columns: list[str], file_set: str
) -> dict[str, Any]:
    fields = [_field(schema.field(c), name, file_set) for c in columns]
    for f in fields:
        if f["name"] == "split":
            f["references"] = {"field": {"@id": "splits/name"}}
    return {"@type": "cr:RecordSet", "@id": name, "name": name, "description": doc, "field": fields}


def croissant_dict(manifest: Manifest) -> dict[str, Any]:
    """The Croissant JSON-LD object of the dataset ``manifest`` describes."""
    m = manifest
    tables = [f for f in m.files if f.rows is not None and f.path.endswith(".parquet")]
    obs_glob = OBSERVATIONS.format(split="*", room_id="*")
    tri_glob = TRIPLETS.format(split="*")
    distribution: list[dict[str, Any]] = [
        {
            "@type": "cr:FileObject",
            "@id": f.path,
            "name": f.path,
            "contentUrl": f.path,
            "contentSize": f"{f.bytes} B",
            "encodingFormat": PARQUET,
            "sha256": f.sha256,
        }
        for f in tables
    ]
    distribution += [
        {
            "@type": "cr:FileSet",
            "@id": f"{name}-files",
            "name": f"{name}-files",
            "description": f"the {name} tables of every split",
            "encodingFormat": PARQUET,
            "includes": glob,
        }
        for name, glob in (("observations", obs_glob), ("triplets", tri_glob))
    ]
    obs, tri = observations_schema(), triplets_schema()
    lists = ("objects", "relations")
    splits = {
        "@type": "cr:RecordSet",
        "@id": "splits",
        "name": "splits",
        "description": "the dataset's splits; a room belongs to one",
        "dataType": ["cr:Split", "sc:Enumeration"],
        "key": {"@id": "splits/name"},
        "field": [
            {"@type": "cr:Field", "@id": f"splits/{k}", "name": k, "dataType": "sc:Text"}
            for k in ("name", "url")
        ],
        "data": [{"splits/name": s, "splits/url": _SPLIT_URLS[s]} for s in m.splits],
    }
    record_sets = [
        splits,
        _record_set(
            "observations",
            "one record per view: ids, pose, camera, the decoded image",
            obs,
            [n for n in obs.names if n not in lists],
            "observations-files",
        ),
        *(
            _record_set(
                name,
                f"per view, its {obs.field(name).metadata[b'doc'].decode()}",
                obs,
                ["obs_id", name],
                "observations-files",
            )
            for name in lists
        ),
        _record_set(
            "triplets",
            "cascaded triplets: anchor, positive and negative views of one room",
            tri,
            tri.names,
            "triplets-files",
        ),
    ]
    return {
        "@context": CONTEXT,
        "@type": "sc:Dataset",
        "conformsTo": CONFORMS_TO,
        "name": m.name,
        "description": (
            f"Scene-graph views of indoor rooms whose objects move, written by "
            f"{m.generator.name} {m.generator.version} (format {m.format} {m.format_version}, "
            f"seed {m.seed})."
        ),
        "version": m.version,
        "license": DATA_LICENSE_URL,
        "url": PAPER_URL,
        "citeAs": f"SeanNet: Semantic Understanding Network for Localization Under Object "
        f"Dynamics, arXiv:2110.02276 ({PAPER_URL})",
        "datePublished": __release_date__,
        "distribution": distribution,
        "recordSet": record_sets,
    }


def croissant_json(manifest: Manifest) -> str:
    """The text of ``croissant.json`` (indent 2, trailing newline)."""
    return json.dumps(croissant_dict(manifest), indent=2, ensure_ascii=False) + "\n"


def write_croissant(root: Path, manifest: Manifest) -> Path:
    """Write ``root/croissant.json`` atomically."""
    path = Path(root) / CROISSANT
    atomic_write_text(path, croissant_json(manifest))
    return path
