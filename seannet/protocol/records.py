"""Records: one small JSON file per unit (and per calibration), in a tracked folder per
dataset recipe, written atomically; a record is the result, committed as soon as it exists.

``RECORDS/<dataset name>-<recipe fingerprint, 16 hex>/<unit>.json`` for a unit,
``.../calibration-<network>-b<budget>.json`` for the batches a budget buys a network. A folder
holds the records of one recipe (:meth:`sgdata.dataset.manifest.Manifest.recipe_fingerprint`:
config, seed, generator and format, the same on every machine), so records made on two
machines combine; each names its dataset's content sha256 too, and a doc names every one it
read. A record of another recipe or protocol version found in a folder is left out, and
:func:`read_records` says so.
"""

from __future__ import annotations

import json
import os
import platform
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from seannet.errors import DataError
from seannet.protocol.design import PROTOCOL_VERSION
from seannet.provenance import provenance_record
from sgdata.dataset import Dataset
from sgdata.fileio import atomic_write_text

__all__ = [
    "RECORDS",
    "Found",
    "dataset_identity",
    "machine",
    "read_records",
    "recipe_folder",
    "write_record",
]

RECORDS = Path("results") / "records"  # under the repository root; tracked
CALIBRATION = "calibration"  # a calibration record's name starts so


def dataset_identity(ds: Dataset) -> dict[str, Any]:
    """What a record says of its dataset: both fingerprints, name, seed and format."""
    manifest = ds.manifest
    return {
        "name": manifest.name,
        "recipe": manifest.recipe_fingerprint(),
        "content_sha256": ds.manifest_sha256,
        "seed": manifest.seed,
        "format_version": manifest.format_version,
        "generator": manifest.generator.version,
    }


def recipe_folder(records: Path, identity: dict[str, Any]) -> Path:
    """The folder of ``identity``'s recipe under ``records``."""
    return records / f"{identity['name']}-{identity['recipe'][:16]}"


def machine() -> dict[str, Any]:
    """The machine a record was made on: cores, CPU, load average when the unit started."""
    return {
        "cores": os.cpu_count(),
        "cpu": _cpu_model(),
        "system": platform.platform(terse=True),
        "load_average": round(os.getloadavg()[0], 2),
    }


def _cpu_model() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def write_record(folder: Path, name: str, body: dict[str, Any]) -> Path:
    """``folder/name.json``, atomically, with the protocol version."""
    path = folder / f"{name}.json"
    record = {"protocol": PROTOCOL_VERSION, **body}
    atomic_write_text(path, json.dumps(record, indent=1, sort_keys=True) + "\n")
    return path


@dataclass
class Found:
    """The records of one recipe folder that a doc may use, and those left out (and why)."""

    folder: Path
    recipe: str
    units: dict[str, dict[str, Any]] = field(default_factory=dict)  # by unit name
    calibrations: dict[str, dict[str, Any]] = field(default_factory=dict)  # by file stem
    left_out: list[str] = field(default_factory=list)  # "<file>: <why>"

    @property
    def content_sha256s(self) -> list[str]:
        """Every dataset content sha256 the records name, sorted."""
        every = [*self.units.values(), *self.calibrations.values()]
        return sorted({r["dataset"]["content_sha256"] for r in every})

    @property
    def commits(self) -> list[tuple[str, bool]]:
        """Every (commit, dirty) the unit records were made at, sorted."""
        return sorted({(r["provenance"]["commit"], r["provenance"]["dirty"]) for r in
                       self.units.values()})  # fmt: skip


def read_records(folder: Path, recipe: str) -> Found:
    """The records of ``folder`` made on the dataset recipe ``recipe`` by this protocol
    version; the rest left out with the reason (another recipe, version, or no JSON).

    Raises:
        DataError: ``folder`` is not a directory.
    """
    if not folder.is_dir():
        raise DataError(f"{folder}: no records folder (run `seannet results run` first)")
    found = Found(folder, recipe)
    for path in sorted(folder.glob("*.json")):
        try:
            record = json.loads(path.read_text())
            their_recipe = record["dataset"]["recipe"]
            version = record["protocol"]
        except (OSError, ValueError, KeyError, TypeError):
            found.left_out.append(f"{path.name}: not a record")
            continue
        if their_recipe != recipe:
            found.left_out.append(
                f"{path.name}: another dataset recipe ({their_recipe[:16]}…, not {recipe[:16]}…)"
            )
        elif version != PROTOCOL_VERSION:
            found.left_out.append(f"{path.name}: protocol {version}, not {PROTOCOL_VERSION}")
        elif path.stem.startswith(CALIBRATION):
            found.calibrations[path.stem] = record
        else:
            found.units[path.stem] = record
    return found


def provenance() -> dict[str, Any]:
    """The process's code and command (captured at its start) and the time, for a record."""
    record = provenance_record(None)
    return {k: record[k] for k in ("commit", "dirty", "command", "started", "code_loaded")}


def find_folder(records: Path, data: Path | None) -> Found:
    """The records of ``data``'s recipe under ``records``; without ``data``, of the only
    recipe folder there (its recipe: the one its records name that the folder is named for).

    Raises:
        DataError: no such folder, or several and no ``data`` to choose.
    """
    if data is not None:
        from seannet.data.opening import open_dataset

        identity = dataset_identity(open_dataset(data))
        return read_records(recipe_folder(records, identity), identity["recipe"])
    folders = sorted(p for p in records.glob("*") if p.is_dir()) if records.is_dir() else []
    if len(folders) != 1:
        named = ", ".join(p.name for p in folders) or "none"
        raise DataError(
            f"{records}: {len(folders)} recipe folders ({named}); pass --data to choose one"
        )
    folder = folders[0]
    prefix = folder.name.rpartition("-")[2]
    for path in sorted(folder.glob("*.json")):
        try:
            recipe = json.loads(path.read_text())["dataset"]["recipe"]
        except (OSError, ValueError, KeyError, TypeError):
            continue
        if recipe.startswith(prefix):
            return read_records(folder, recipe)
    raise DataError(f"{folder}: no record of the recipe {prefix}… the folder is named for")
