"""``sgdata import``: COCO, LabelMe or Label Studio boxes as saved labels, then a real dataset.

The file is read into :class:`~sgdata.label.annotations.ForeignPhoto` records, every class and
relation label is mapped (all unknown ones are reported together, once), every photo is checked
against ``--images``, and only then are the labels written to the label store
(``<out>/labels/<photo>.json``, as ``sgdata label`` saves them) and the dataset written by
:func:`sgdata.label.export.export_dataset`, the one writer of real datasets.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

from pydantic import ValidationError

from sgdata.errors import ConfigError, SgdataError
from sgdata.fileio import read_toml
from sgdata.label.annotations import AnnotationFormatError, ForeignPhoto
from sgdata.label.classes import ClassNames, load_class_names
from sgdata.label.export import ExportSummary
from sgdata.label.models import ROOM_ID_PATTERN, PhotoLabels
from sgdata.label.photos import Photo, PhotoIndex
from sgdata.label.proposals import RELATION_NAMES

__all__ = [
    "IMPORT_FORMATS",
    "ImportMap",
    "ImportSummary",
    "UnknownLabelsError",
    "import_labels",
    "load_import_map",
]

IMPORT_FORMATS = ("coco", "labelme", "labelstudio")
_UPLOAD_PREFIX = re.compile(r"^[0-9a-f]{8}-")  # Label Studio prefixes uploaded file names


class UnknownLabelsError(SgdataError):
    """Class names or relation labels of an annotation file that nothing maps."""


@dataclass(frozen=True)
class ImportMap:
    """File class names -> catalog classes, and file relation labels -> relation types."""

    classes: ClassNames
    relations: dict[str, str] = field(default_factory=dict)

    def resolve_class(self, name: str) -> str | None:
        """The catalog class of a file's class name: mapped, exact, or the one catalog class
        equal to it ignoring case, spaces, ``_`` and ``-`` (``dining table`` -> DiningTable)."""
        found = self.classes.resolve(name)
        if found is not None or not name:
            return found
        loose = [c for c in self.classes.catalog if _loose(c) == _loose(name)]
        return loose[0] if len(loose) == 1 else None

    def resolve_relation(self, label: str, symmetric: bool) -> str | None:
        """The relation type of a label: mapped, a type name in any case, or ``proximity``
        for an unlabeled symmetric (``bi``) relation."""
        if label in self.relations:
            return self.relations[label]
        if label.lower() in RELATION_NAMES:
            return label.lower()
        return "proximity" if symmetric and not label else None


def _loose(name: str) -> str:
    return re.sub(r"[^a-z0-9]", "", name.lower())


def load_import_map(path: Path | None) -> ImportMap:
    """The ``--classes`` file of ``sgdata label`` plus an optional ``[relations]`` table of
    ``label = "on" | "in" | "proximity" | "disjoint"`` pairs.

    Raises:
        ConfigError: the file is missing or not TOML, or maps onto an unknown class or type.
    """
    if path is None:
        return ImportMap(load_class_names(None))
    path = Path(path)
    raw = read_toml(path, "class map")
    table = raw.get("relations")
    if table is None:
        return ImportMap(load_class_names(path))
    if not isinstance(table, dict):
        raise ConfigError(f"{path}: relations = {table!r}; expected a [relations] table")
    relations = {}
    for label, target in table.items():
        if target not in RELATION_NAMES:
            raise ConfigError(
                f"{path}: [relations] {label!r} maps to {target!r}; "
                f"expected one of {', '.join(RELATION_NAMES)}"
            )
        relations[label] = target
    # The class pairs are checked exactly as `sgdata label --classes` checks them.
    base = load_class_names(None)
    mapped = {}
    for name, target in raw.items():
        if name == "relations":
            continue
        if not isinstance(target, str) or target not in base.catalog or not name.strip():
            raise ConfigError(
                f'{path}: {name!r} = {target!r}; expected name = "CatalogClass" pairs naming '
                "catalog classes (see assets/catalog.toml)"
            )
        mapped[name] = target
    return ImportMap(ClassNames(base.catalog, mapped), relations)


@dataclass
class ImportSummary:
    """What an import read and what its export wrote."""

    photos: int
    boxes: int
    relations: int
    export: ExportSummary
    notes: list[str] = field(default_factory=list)


def import_labels(
    fmt: str,
    annotations: Path,
    images_dir: Path,
    out_dir: Path,
    *,
    class_map: Path | None = None,
    room: str | None = None,
    room_type: str | None = None,
    split: str = "test",
) -> ImportSummary:
    """Import an annotation file as labels of the photos in ``images_dir``, then export.

    Photos whose file gives no room (only Label Studio files written by ``sgdata export`` do)
    get ``room`` (default: the annotation file's name) and ``room_type`` (default: the room
    type the room id starts with). Labels of the imported photos replace any saved ones; other
    photos' saved labels are kept and exported with them.

    Raises:
        AnnotationFormatError: the file is malformed, or names a photo ``images_dir`` lacks or
            has at another size.
        UnknownLabelsError: class names or relation labels nothing maps (all listed).
        ConfigError, DatasetError: as :func:`~sgdata.label.export.export_dataset`.
    """
    from sgdata.label.export import export_dataset
    from sgdata.label.labelstudio import read_labelstudio
    from sgdata.label.photos import scan_photos
    from sgdata.label.readers import read_coco, read_labelme
    from sgdata.label.store import LabelStore

    readers = {"coco": read_coco, "labelme": read_labelme, "labelstudio": read_labelstudio}
    if fmt not in readers:
        raise ConfigError(f"format {fmt!r}: expected one of {', '.join(IMPORT_FORMATS)}")
    mapping = load_import_map(class_map)
    room = room or _room_from(Path(annotations))
    if room_type is not None:
        from sgdata.world.room_recipes import ROOM_TYPES

        if room_type not in ROOM_TYPES:
            raise ConfigError(f"--room-type {room_type!r}: expected {' | '.join(ROOM_TYPES)}")
    if not re.match(ROOM_ID_PATTERN, room):
        raise ConfigError(f"--room {room!r}: expected letters, digits, '_', '-' and inner '.'")
    foreign, notes = readers[fmt](Path(annotations))
    index = scan_photos(images_dir)
    matched = _match_photos(foreign, index, Path(annotations))
    _check_labels(foreign, mapping, Path(annotations))
    labels = {
        photo.name: _labels(item, mapping, room, room_type)
        for item, photo in zip(foreign, matched, strict=True)
    }
    if not labels:  # nothing to write: refused before the output folder exists
        raise ConfigError(f"{annotations}: holds no photo's labels; nothing to import")
    store = LabelStore(out_dir)
    for name, value in labels.items():  # every photo checked: now write
        store.save(name, value.model_copy(update={"revision": store.load(name).revision}))
    summary = ImportSummary(
        photos=len(labels),
        boxes=sum(len(v.objects) for v in labels.values()),
        relations=sum(len(v.relations) for v in labels.values()),
        export=export_dataset(images_dir, out_dir, split=split),
        notes=notes,
    )
    return summary


def _room_from(path: Path) -> str:
    stem = re.sub(r"[^A-Za-z0-9_-]+", "_", path.stem).strip("_-")
    return stem[:64] or "real"


def _match_photos(foreign: list[ForeignPhoto], index: PhotoIndex, path: Path) -> list[Photo]:
    """The photo of every record (a Label Studio upload prefix may be dropped), sizes checked."""
    found, missing, seen = [], [], {}
    for item in foreign:
        photo = index.get(item.name) or index.get(_UPLOAD_PREFIX.sub("", item.name))
        if photo is None:
            missing.append(item.name)
            continue
        if photo.name in seen:
            raise AnnotationFormatError(
                f"{seen[photo.name]} and {item.where} both annotate photo {photo.name}"
            )
        seen[photo.name] = item.where
        if item.width is not None and (item.width, item.height) != (photo.width, photo.height):
            raise AnnotationFormatError(
                f"{item.where}: says {item.name} is {item.width}x{item.height} pixels, but it "
                f"is {photo.width}x{photo.height}; annotate the photos in --images"
            )
        item.width, item.height = photo.width, photo.height
        found.append(photo)
    if missing:
        shown = ", ".join(missing[:5]) + (
            f" and {len(missing) - 5} more" if len(missing) > 5 else ""
        )
        raise AnnotationFormatError(
            f"{path}: {len(missing)} photo(s) not in {index.root} (PNG or JPEG files): {shown}"
        )
    return found


def _check_labels(foreign: list[ForeignPhoto], mapping: ImportMap, path: Path) -> None:
    """Every class name and relation label maps, or one error lists all that do not."""
    classes = sorted(
        {b.label for p in foreign for b in p.boxes if mapping.resolve_class(b.label) is None}
    )
    relations = sorted(
        {
            r.label
            for p in foreign
            for r in p.relations
            if mapping.resolve_relation(r.label, r.symmetric) is None
        }
    )
    if not classes and not relations:
        return
    parts = []
    if classes:
        parts.append("class(es) " + ", ".join(repr(c) if c else "(no class)" for c in classes))
    if relations:
        parts.append(
            "relation label(s) " + ", ".join(repr(r) if r else "(none)" for r in relations)
        )
    raise UnknownLabelsError(
        f"{path}: unknown {' and '.join(parts)}; map them with --classes MAP.toml "
        '(name = "CatalogClass" lines; a [relations] table of label = "on" | "in" | '
        '"proximity" | "disjoint")'
    )


def _labels(
    item: ForeignPhoto, mapping: ImportMap, room: str, room_type: str | None
) -> PhotoLabels:
    """The :class:`PhotoLabels` of one mapped record (one-line errors name the record)."""
    room_id = item.room_id or room
    kind = item.room_type or room_type or _type_of(room_id)
    decisions, pairs = [], {}
    for r in item.relations:
        kind_of = mapping.resolve_relation(r.label, r.symmetric)
        pair = (min(r.src, r.dst), max(r.src, r.dst))
        if r.src == r.dst:
            raise AnnotationFormatError(f"{item.where}: {r.where}: a relation from a box to itself")
        if r.symmetric and kind_of in ("on", "in"):
            raise AnnotationFormatError(
                f"{item.where}: {r.where}: a 'bi' relation typed {kind_of!r}; "
                "on / in need a direction (right or left)"
            )
        if pair in pairs:
            raise AnnotationFormatError(
                f"{item.where}: {r.where} and {pairs[pair]} relate the same two boxes; keep one"
            )
        pairs[pair] = r.where
        src, dst = (r.src, r.dst) if kind_of in ("on", "in") else pair
        decisions.append({"src": src, "dst": dst, "type": kind_of})
    objects = [
        {"id": b.id, "class_name": mapping.resolve_class(b.label), "box": list(b.box)}
        for b in item.boxes
    ]
    try:
        return PhotoLabels.model_validate(
            {
                "room_id": room_id,
                "room_type": kind,
                "pose": item.pose,
                "objects": objects,
                "relations": decisions,
            }
        )
    except ValidationError as exc:
        first = exc.errors()[0]
        at = ".".join(str(p) for p in first["loc"])
        raise AnnotationFormatError(f"{item.where}: {at}: {first['msg']}") from None


def _type_of(room_id: str) -> str:
    from sgdata.world.room_recipes import ROOM_TYPES

    for kind in sorted(ROOM_TYPES, key=len, reverse=True):
        if room_id.startswith(kind):
            return kind
    raise ConfigError(
        f"room {room_id!r}: no room type; give --room-type {' | '.join(ROOM_TYPES)} "
        "(or a room id that starts with one)"
    )
