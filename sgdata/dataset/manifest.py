"""``dataset.json``: the manifest as a typed, validated dataclass.

The manifest is validated twice over, and every problem is reported at once: first against
``schemas/manifest.v1.schema.json`` (JSON Schema 2020-12, shapes and types), then by
:meth:`Manifest.problems` (cross-field rules: class ids, slot runs, counts vs splits, files).

Before either, the raw dict goes through :func:`sgdata.schema.migrate_manifest_dict`: the one
version check (:func:`sgdata.schema.check_compatible`) and the migrations of older minors.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import jsonschema

from sgdata.annotate.relations import RelationType
from sgdata.dataset.paths import CARD, CROISSANT, MANIFEST, SPLITS
from sgdata.dataset.schema import (
    FORMAT_VERSION,
    SAME_RECIPE_AS,
    manifest_json_schema,
    migrate_manifest_dict,
)
from sgdata.errors import DatasetError
from sgdata.fileio import sha256_file

__all__ = [
    "FORMAT_NAME",
    "ClassEntry",
    "FileEntry",
    "Generator",
    "ImageInfo",
    "Counts",
    "Manifest",
    "classes_from_slots",
    "file_entry",
    "relation_type_names",
    "manifest_bytes",
    "parse_manifest",
    "read_manifest",
]

FORMAT_NAME = "sgdata"
META_FILES = (CARD, CROISSANT)  # written by publish.write_manifest from the manifest itself
META_SINCE = "2.0.0"  # the format version that added META_FILES
NUM_TIERS = 5


@dataclass(frozen=True)
class Generator:
    """The program that wrote the dataset."""

    name: str  # "sgdata"
    version: str  # sgdata.__version__


@dataclass(frozen=True)
class ClassEntry:
    """One class of the vocabulary and its run of GCN node slots."""

    name: str  # catalog name
    id: int  # objects[].class_id; equals the position in Manifest.classes
    dynamics: str  # static | low | high
    slot_start: int  # first slot of the class's run
    slot_count: int  # run length (the catalog's max_instances)


@dataclass(frozen=True)
class ImageInfo:
    """How observation images are encoded."""

    format: str  # png | jpeg
    width: int  # pixels
    height: int  # pixels


@dataclass(frozen=True)
class Counts:
    """Sizes of the dataset, per split where it has splits."""

    rooms: int
    observations: dict[str, int]  # split -> rows of observations/<split>/*.parquet
    triplets: dict[str, int]  # split -> rows of triplets/<split>.parquet
    tiers: dict[str, list[int]]  # split -> triplets of tier 0..4


@dataclass(frozen=True)
class FileEntry:
    """A file of the dataset, relative to the root, with its checksum."""

    path: str  # '/'-separated, relative to the dataset root
    rows: int | None  # table rows; None for non-table files (USD scenes)
    sha256: str  # hex digest
    bytes: int  # size


@dataclass(frozen=True)
class Manifest:
    """``dataset.json``, field for field (see docs/dataset.md and the JSON Schema).

    Raises:
        DatasetError: on construction, listing every cross-field problem (:meth:`problems`).
    """

    name: str  # the dataset's name (config dataset.name)
    version: str  # the dataset's own version (config dataset.version)
    generator: Generator
    seed: int  # config dataset.seed
    config: dict[str, Any]  # resolved GenerateConfig as plain JSON (config_to_dict)
    classes: tuple[ClassEntry, ...]  # the class vocabulary in id order
    num_slots: int  # M
    relation_rules: dict[str, Any]  # RelationRules.to_dict()
    image: ImageInfo
    splits: dict[str, tuple[str, ...]]  # split -> room ids, in storage order
    counts: Counts
    files: tuple[FileEntry, ...]  # sorted by path
    relation_types: tuple[str, ...] = field(default_factory=lambda: relation_type_names())
    format: str = FORMAT_NAME
    format_version: str = FORMAT_VERSION

    def __post_init__(self) -> None:
        found = self.problems()
        if found:
            raise DatasetError(_report("dataset.json is inconsistent", found))

    def problems(self) -> list[str]:
        """Every cross-field inconsistency (empty when the manifest is sound)."""
        out: list[str] = []
        ids = [c.id for c in self.classes]
        if ids != list(range(len(ids))):
            out.append(f"classes: ids {ids}; expected 0..{len(ids) - 1} in order")
        names = [c.name for c in self.classes]
        if len(set(names)) != len(names):
            out.append("classes: class names repeat")
        end = 0
        for c in sorted(self.classes, key=lambda c: c.slot_start):
            if c.slot_start < end:
                out.append(f"classes: slot run of {c.name!r} overlaps the previous class's run")
            end = c.slot_start + c.slot_count
        if end > self.num_slots:
            out.append(f"classes: slot runs end at {end}, past num_slots={self.num_slots}")
        unknown = sorted(set(self.splits) - set(SPLITS))
        if unknown:
            out.append(f"splits: unknown split(s) {unknown}; expected some of {list(SPLITS)}")
        rooms = [r for ids_ in self.splits.values() for r in ids_]
        if len(set(rooms)) != len(rooms):
            out.append("splits: a room appears in more than one split")
        if self.counts.rooms != len(rooms):
            out.append(f"counts.rooms={self.counts.rooms} but splits list {len(rooms)} rooms")
        for key in ("observations", "triplets", "tiers"):
            have = set(getattr(self.counts, key))
            if have != set(self.splits):
                out.append(f"counts.{key}: splits {sorted(have)}; expected {sorted(self.splits)}")
        for split, tiers in self.counts.tiers.items():
            if len(tiers) != NUM_TIERS:
                out.append(f"counts.tiers.{split}: {len(tiers)} values; expected {NUM_TIERS}")
            elif sum(tiers) != self.counts.triplets.get(split, sum(tiers)):
                out.append(f"counts.tiers.{split} sums to {sum(tiers)}, not counts.triplets")
        paths = [f.path for f in self.files]
        if paths != sorted(set(paths)):
            out.append("files: paths must be unique and sorted")
        bad = [p for p in paths if p.startswith("/") or ".." in p.split("/") or "\\" in p]
        if bad:
            out.append(f"files: paths {bad[:3]} are not relative '/'-separated paths")
        return out

    # ------------------------------------------------------------------ JSON

    def to_dict(self) -> dict[str, Any]:
        """The JSON object: top-level keys in a fixed order, free-form dicts sorted by key."""
        return {
            "format": self.format,
            "format_version": self.format_version,
            "name": self.name,
            "version": self.version,
            "generator": {"name": self.generator.name, "version": self.generator.version},
            "seed": self.seed,
            "config": _sorted_keys(self.config),
            "classes": [
                {
                    "name": c.name,
                    "id": c.id,
                    "dynamics": c.dynamics,
                    "slot_start": c.slot_start,
                    "slot_count": c.slot_count,
                }
                for c in self.classes
            ],
            "num_slots": self.num_slots,
            "relation_types": list(self.relation_types),
            "relation_rules": _sorted_keys(self.relation_rules),
            "image": {
                "format": self.image.format,
                "width": self.image.width,
                "height": self.image.height,
            },
            "splits": {s: list(self.splits[s]) for s in _split_order(self.splits)},
            "counts": {
                "rooms": self.counts.rooms,
                "observations": _by_split(self.counts.observations),
                "triplets": _by_split(self.counts.triplets),
                "tiers": {s: list(v) for s, v in _by_split(self.counts.tiers).items()},
            },
            "files": [
                {"path": f.path, "rows": f.rows, "sha256": f.sha256, "bytes": f.bytes}
                for f in self.files
            ],
        }

    def recipe_fingerprint(self) -> str:
        """sha256 of what was asked for: every field but what generation produced (``counts``
        and ``files``). The same wherever the same config, seed, generator and format made
        the dataset, even where the bytes differ (renderers on other CPUs); results recorded
        per dataset combine on it (DESIGN §12). A format that only added derived columns
        counts as the one before it (:data:`~sgdata.dataset.schema.SAME_RECIPE_AS`)."""
        recipe = {k: v for k, v in self.to_dict().items() if k not in ("counts", "files")}
        while recipe["format_version"] in SAME_RECIPE_AS:
            recipe["format_version"] = SAME_RECIPE_AS[recipe["format_version"]]
        text = json.dumps(recipe, sort_keys=True, ensure_ascii=False, separators=(",", ":"))
        return hashlib.sha256(text.encode()).hexdigest()

    def to_json(self) -> str:
        """Deterministic text of ``dataset.json`` (indent 2, trailing newline, no timestamps)."""
        return json.dumps(self.to_dict(), indent=2, ensure_ascii=False) + "\n"

    @classmethod
    def from_dict(cls, raw: Any, *, source: str = MANIFEST) -> Manifest:
        """Validate a parsed ``dataset.json`` (after the version check and migrations).

        Raises:
            FormatVersionError: unreadable format version.
            DatasetError: every schema violation, then every cross-field problem, at once.
        """
        if not isinstance(raw, dict):
            raise DatasetError(f"{source}: expected a JSON object, got {type(raw).__name__}")
        if "format_version" in raw:
            raw = migrate_manifest_dict(raw)
        validator = jsonschema.Draft202012Validator(manifest_json_schema())
        errors = sorted(validator.iter_errors(raw), key=lambda e: list(map(str, e.path)))
        if errors:
            lines = [_describe(e) for e in errors]
            raise DatasetError(_report(f"{source} does not match the manifest schema", lines))
        counts = raw["counts"]
        try:
            return cls(
                format=raw["format"],
                format_version=raw["format_version"],
                name=raw["name"],
                version=raw["version"],
                generator=Generator(**raw["generator"]),
                seed=raw["seed"],
                config=raw["config"],
                classes=tuple(ClassEntry(**c) for c in raw["classes"]),
                num_slots=raw["num_slots"],
                relation_types=tuple(raw["relation_types"]),
                relation_rules=raw["relation_rules"],
                image=ImageInfo(**raw["image"]),
                splits={s: tuple(r) for s, r in raw["splits"].items()},
                counts=Counts(
                    rooms=counts["rooms"],
                    observations=dict(counts["observations"]),
                    triplets=dict(counts["triplets"]),
                    tiers={s: list(v) for s, v in counts["tiers"].items()},
                ),
                files=tuple(FileEntry(**f) for f in raw["files"]),
            )
        except DatasetError as exc:
            raise DatasetError(f"{source}: {exc}") from None

    @classmethod
    def from_json(cls, text: str, *, source: str = MANIFEST) -> Manifest:
        """Parse and validate the text of ``dataset.json`` (see :meth:`from_dict`)."""
        try:
            raw = json.loads(text)
        except json.JSONDecodeError as exc:
            raise DatasetError(f"{source}: not valid JSON ({exc})") from None
        return cls.from_dict(raw, source=source)

    # ------------------------------------------------------------------ lookups

    @property
    def class_ids(self) -> dict[str, int]:
        """Class name -> id (``objects[].class_id``)."""
        return {c.name: c.id for c in self.classes}

    @property
    def slot_runs(self) -> dict[str, tuple[int, int]]:
        """Class name -> (first slot, run length)."""
        return {c.name: (c.slot_start, c.slot_count) for c in self.classes}

    def file(self, path: str) -> FileEntry:
        """The entry of ``path``; raises DatasetError if the manifest does not list it."""
        for entry in self.files:
            if entry.path == path:
                return entry
        raise DatasetError(f"{path}: not listed in {MANIFEST} files")


def _report(title: str, lines: list[str]) -> str:
    return f"{title} ({len(lines)} problem{'s' if len(lines) != 1 else ''}): " + "; ".join(lines)


def _describe(error: jsonschema.ValidationError) -> str:
    where = "/".join(str(p) for p in error.absolute_path) or "(top level)"
    got = f" (got {error.instance!r})" if error.validator == "const" else ""
    return f"{where}: {error.message}{got}"


def _sorted_keys(value: Any) -> Any:
    if isinstance(value, Mapping):
        return {str(k): _sorted_keys(value[k]) for k in sorted(value, key=str)}
    if isinstance(value, list | tuple):
        return [_sorted_keys(v) for v in value]
    return value


def _split_order(splits: Iterable[str]) -> list[str]:
    return sorted(splits, key=lambda s: (SPLITS.index(s) if s in SPLITS else len(SPLITS), s))


def _by_split(values: Mapping[str, Any]) -> dict[str, Any]:
    return {s: values[s] for s in _split_order(values)}


def relation_type_names() -> tuple[str, ...]:
    """Relation type names in code order: ``("on", "in", "proximity", "disjoint")``."""
    return tuple(t.name.lower() for t in sorted(RelationType))


def classes_from_slots(
    runs: Mapping[str, tuple[int, int]], dynamics: Mapping[str, str]
) -> tuple[ClassEntry, ...]:
    """The class vocabulary from slot runs (``SlotTable.runs``, catalog order) and dynamics.

    Class ids follow the order of ``runs``.
    """
    missing = [name for name in runs if name not in dynamics]
    if missing:
        raise DatasetError(f"classes {missing}: no dynamics given")
    return tuple(
        ClassEntry(name=n, id=i, dynamics=str(dynamics[n]), slot_start=int(s), slot_count=int(c))
        for i, (n, (s, c)) in enumerate(runs.items())
    )


def file_entry(root: Path, path: str, *, rows: int | None = None) -> FileEntry:
    """A :class:`FileEntry` for an existing file ``root / path`` (hashes it)."""
    digest, size = sha256_file(Path(root) / path)
    return FileEntry(path=path, rows=rows, sha256=digest, bytes=size)


def read_manifest(root: Path) -> Manifest:
    """The validated manifest of the dataset at ``root``.

    Raises:
        DatasetError: no ``dataset.json`` (an unfinished or foreign directory), or invalid.
    """
    return parse_manifest(manifest_bytes(root), Path(root) / MANIFEST)


def manifest_bytes(root: Path) -> bytes:
    """The bytes of ``root/dataset.json`` as stored (what its sha256 covers), read once.

    Raises:
        DatasetError: no ``dataset.json`` (an unfinished or foreign directory).
    """
    path = Path(root) / MANIFEST
    if not path.is_file():
        raise DatasetError(
            f"{root}: no {MANIFEST}; not an sgdata dataset "
            "(or generation did not finish: run sgdata generate --resume)"
        )
    return path.read_bytes()


def parse_manifest(raw: bytes, path: Path) -> Manifest:
    """The validated manifest from the bytes of ``path`` (:func:`manifest_bytes`).

    Raises:
        DatasetError: not UTF-8 text, or not a valid manifest.
    """
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise DatasetError(
            f"{path}: not UTF-8 text ({exc.reason} at byte {exc.start}); expected the JSON "
            "manifest generation writes"
        ) from None
    return Manifest.from_json(text, source=str(path))
