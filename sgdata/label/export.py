"""``sgdata label --export``: the saved labels as a real dataset (``domain = "real"`` rows).

Rows follow ``schemas/observations.v1.json`` like the generator's: one shard per room in one
split, images stored as the photo's own bytes (see :func:`sgdata.label.photos.photo_bytes`),
3D boxes, obb and support null, ``visible_pixels`` the box area (a photo has no instance mask),
and every pair of objects without an accepted relation stored as ``disjoint`` both ways, as
the generator stores it. Photos with a pose get ``<room>/<layout>/<i>/<j>/<heading>`` ids and
take part in cascaded triplets; the others get ``<room>/<photo stem>`` ids (a stem that starts
with ``<room>__``, as the Label Studio export names its image files, drops that prefix, so a
round trip through Label Studio keeps the id).
"""

from __future__ import annotations

import shutil
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path, PurePath

import pyarrow as pa

from sgdata.dataset.paths import MANIFEST, OUTPUTS, SPLITS, obs_id, observations_path
from sgdata.errors import ConfigError, DatasetError
from sgdata.label.classes import ClassNames, load_class_names
from sgdata.label.models import PhotoLabels
from sgdata.label.photos import DEFAULT_MAX_PIXELS, Photo, photo_bytes, scan_photos
from sgdata.label.proposals import DEFAULT_RULES, RELATION_NAMES, ProposalRules
from sgdata.label.store import LabelStore
from sgdata.world.triplets import HEADINGS, RoomPoses, Triplet, sample_triplets

__all__ = ["ExportSummary", "export_dataset", "SOURCE", "FILE_SEP"]

SOURCE = "sgdata label"  # config.source of an export: re-exporting may replace only these
FILE_SEP = "__"  # stands for the '/' of an obs_id in a file name (Label Studio image files)


@dataclass
class ExportSummary:
    """What an export wrote and left out."""

    root: Path
    split: str
    rooms: int = 0
    observations: int = 0
    triplets: int = 0
    unlabeled: list[str] = field(default_factory=list)  # photos without a room id (left out)
    never_labeled: list[str] = field(default_factory=list)  # photos with no labels saved
    pending: dict[str, int] = field(default_factory=dict)  # photo -> proposals never decided
    guessed: dict[str, int] = field(default_factory=dict)  # photo -> proposed boxes left out
    dropped: int = 0  # objects beyond their class's slot run
    notes: list[str] = field(default_factory=list)


@dataclass
class _Row:
    photo: Photo
    labels: PhotoLabels
    obs_id: str


def export_dataset(
    photos_dir: Path,
    out_dir: Path,
    *,
    class_map: Path | None = None,
    split: str = "test",
    name: str = "real",
    version: str = "1.0.0",
    rules: ProposalRules = DEFAULT_RULES,
    max_pixels: int = DEFAULT_MAX_PIXELS,
) -> ExportSummary:
    """Write the labeled photos of ``photos_dir`` (labels under ``out_dir/labels``) as a
    dataset in ``out_dir``: observation shards, triplet tables where poses allow, manifest.

    ``class_map`` defaults to the one ``sgdata label --classes`` remembered beside the labels.

    Raises:
        ConfigError: a bad split, class map or photos directory, or ``out_dir`` holds a
            dataset that is not an export of this tool.
        DatasetError: a label names an unknown class, or two photos get the same id.
    """
    from sgdata.dataset.vocabulary import class_vocabulary
    from sgdata.label.review import accepted_only, proposals_for, undecided

    if split not in SPLITS:
        raise ConfigError(f"--split {split!r}: expected one of {', '.join(SPLITS)}")
    store = LabelStore(out_dir)
    class_map = store.class_map(class_map)
    classes = load_class_names(class_map)
    index = scan_photos(photos_dir, max_pixels=max_pixels)
    root = store.root
    summary = ExportSummary(root, split)
    slots, vocabulary = class_vocabulary()
    dynamics = {c.name: c.dynamics for c in vocabulary}
    class_ids = {c.name: c.id for c in vocabulary}

    rooms: dict[str, list[_Row]] = {}
    for photo_name, labels in store.labeled().items():
        photo = index.get(photo_name)
        if photo is None:
            summary.notes.append(f"labels/{photo_name}.json: no such photo; left out")
            continue
        if labels.room_id is None:
            summary.unlabeled.append(photo_name)
            continue
        guessed = sum(o.proposed is not None for o in labels.objects)
        if guessed:
            summary.guessed[photo_name] = guessed
            labels = accepted_only(labels)
        pending = len(undecided(labels, proposals_for(labels, classes, rules)))
        if pending:
            summary.pending[photo_name] = pending
        rooms.setdefault(labels.room_id, []).append(_Row(photo, labels, _row_id(photo, labels)))
    summary.never_labeled = sorted(set(index.photos) - set(store.labeled()))
    if not rooms:  # an empty dataset is no export: say which photos wait, write nothing
        waiting = summary.unlabeled + summary.never_labeled
        raise ConfigError(
            f"{photos_dir}: nothing to export: no photo has labels with a room id "
            f"({len(waiting)} waiting: {_names(waiting)}); label them in the page first"
        )
    _check_rooms(rooms)

    from sgdata.dataset.manifest import FileEntry
    from sgdata.dataset.rows import write_parquet
    from sgdata.dataset.schema import observations_schema

    schema = observations_schema()
    tables, sizes = {}, Counter()
    for room_id in sorted(rooms):  # every row first: a bad label leaves the old export alone
        records = []
        for row in sorted(rooms[room_id], key=lambda r: r.obs_id):
            record, dropped = _record(row, split, classes, class_ids, dynamics, slots)
            summary.dropped += dropped
            camera = record["camera"]
            sizes[(record["image_format"], camera["width"], camera["height"])] += 1
            records.append(record)
        tables[room_id] = pa.Table.from_pylist(records, schema=schema)
    _clear_previous(root)
    files = []
    for room_id, table in tables.items():
        relative = observations_path(split, room_id)
        info = write_parquet(table, root / relative)
        files.append(FileEntry(relative, info.rows, info.sha256, info.bytes))
        summary.observations += info.rows
    summary.rooms = len(rooms)
    triplets = _triplets(rooms, split, summary)
    _write_manifest(root, name, version, split, rooms, files, triplets, sizes, rules, class_map)
    summary.triplets = len(triplets)
    return summary


def _names(photos: list[str], shown: int = 5) -> str:
    """The first ``shown`` photo names, and how many more."""
    more = f" and {len(photos) - shown} more" if len(photos) > shown else ""
    return (", ".join(photos[:shown]) or "none") + more


def _clear_previous(root: Path) -> None:
    manifest = root / MANIFEST
    if manifest.exists():
        import json

        try:
            source = json.loads(manifest.read_text(encoding="utf-8"))["config"]["source"]
        except (ValueError, KeyError, TypeError):
            source = None
        if source != SOURCE:
            raise ConfigError(
                f"{root}: holds a dataset that is not a `sgdata label` export; "
                "export into another directory"
            )
    for item in OUTPUTS:
        target = root / item
        if target.is_dir():
            shutil.rmtree(target)
        elif target.exists():
            target.unlink()


def _row_id(photo: Photo, labels: PhotoLabels) -> str:
    assert labels.room_id is not None
    if labels.pose is not None:
        p = labels.pose
        return obs_id(labels.room_id, p.layout, p.i, p.j, p.heading)
    stem = PurePath(photo.name).stem
    prefix = labels.room_id + FILE_SEP
    if stem.startswith(prefix) and len(stem) > len(prefix):
        stem = stem[len(prefix) :]  # a file named by the Label Studio export: no second prefix
    return f"{labels.room_id}/{stem}"


def _check_rooms(rooms: dict[str, list[_Row]]) -> None:
    for room_id, rows in rooms.items():
        seen: dict[str, str] = {}
        for row in rows:
            if row.obs_id in seen:
                raise DatasetError(
                    f"photos {seen[row.obs_id]} and {row.photo.name} both become {row.obs_id!r}; "
                    "give them different poses (or rename one)"
                )
            seen[row.obs_id] = row.photo.name
        types = sorted({r.labels.room_type or "" for r in rows})
        if len(types) != 1 or not types[0]:
            shown = ", ".join(t or "(none)" for t in types)
            raise DatasetError(
                f"room {room_id}: room types {shown}; set one room type on every photo of the room"
            )


def _record(
    row: _Row,
    split: str,
    classes: ClassNames,
    class_ids: dict[str, int],
    dynamics: dict[str, str],
    slots,
) -> tuple[dict, int]:
    labels, photo = row.labels, row.photo
    objects = sorted(labels.objects, key=lambda o: o.id)
    names = []
    for o in objects:
        resolved = classes.resolve(o.class_name)
        if resolved is None:
            shown = repr(o.class_name) if o.class_name else "no class"
            raise DatasetError(
                f"{photo.name}: object {o.id} has {shown}; pick a catalog class "
                "(or map the name with --classes)"
            )
        if o.box[2] > photo.width or o.box[3] > photo.height:
            raise DatasetError(
                f"{photo.name}: object {o.id} box {o.box} lies outside the "
                f"{photo.width}x{photo.height} photo"
            )
        names.append(resolved)
    assignment = slots.assign([(o.id, n) for o, n in zip(objects, names, strict=True)])
    kept = {o.id for o, s in zip(objects, assignment.slots, strict=True) if s >= 0}
    out_objects = [
        {
            "instance": o.id,
            "class_name": n,
            "class_id": class_ids[n],
            "slot": int(s),
            "dynamics": dynamics[n],
            "box2d": list(o.box),
            "visible_pixels": (o.box[2] - o.box[0]) * (o.box[3] - o.box[1]),
            "box3d_min": None,
            "box3d_max": None,
            "obb": None,
            "support": None,
        }
        for o, n, s in zip(objects, names, assignment.slots, strict=True)
        if s >= 0
    ]
    image, image_format = photo_bytes(photo)
    pose = labels.pose
    return {
        "obs_id": row.obs_id,
        "room_id": labels.room_id,
        "room_type": labels.room_type,
        "layout": pose.layout if pose else 0,
        "split": split,
        "domain": "real",
        "x": None,
        "y": None,
        "theta": None,
        "grid_i": pose.i if pose else None,
        "grid_j": pose.j if pose else None,
        "heading": pose.heading if pose else None,
        "camera": {
            "width": photo.width,
            "height": photo.height,
            "hfov_deg": None,
            "eye_height": None,
            "pitch_deg": None,
        },
        "image": image,
        "image_format": image_format,
        "objects": out_objects,
        "relations": _relations(labels, sorted(kept)),
        "dropped_objects": assignment.dropped,
        "scene": None,
        "seed": 0,
    }, assignment.dropped


def _relations(labels: PhotoLabels, ids: list[int]) -> list[dict]:
    """Accepted relations, and disjoint both ways for every other pair (as the generator)."""
    code = {name: k for k, name in enumerate(RELATION_NAMES)}
    decided = {}
    for r in labels.relations:
        decided[(min(r.src, r.dst), max(r.src, r.dst))] = r
    keep = set(ids)
    edges = []
    for k, a in enumerate(ids):
        for b in ids[k + 1 :]:
            r = decided.get((a, b))
            if r is not None and r.type in ("on", "in") and {r.src, r.dst} <= keep:
                edges.append((r.src, r.dst, code[r.type]))
            else:
                kind = code[r.type] if r is not None else code["disjoint"]
                edges.extend([(a, b, kind), (b, a, kind)])
    return [{"src": s, "dst": d, "type": t} for s, d, t in sorted(edges)]


def _triplets(rooms: dict[str, list[_Row]], split: str, summary: ExportSummary) -> list[Triplet]:
    """Cascaded triplets over the cells photographed at all four headings, as many as the
    poses allow (none when they allow none)."""
    posed = []
    for room_id in sorted(rooms):
        headings: dict[tuple[int, int, int], set[int]] = {}
        for row in rooms[room_id]:
            p = row.labels.pose
            if p is not None:
                headings.setdefault((p.layout, p.i, p.j), set()).add(p.heading)
        reachable: dict[int, set[tuple[int, int]]] = {}
        for (layout, i, j), seen in headings.items():
            if len(seen) == HEADINGS:
                reachable.setdefault(layout, set()).add((i, j))
        if reachable:
            posed.append(RoomPoses(room_id, split, {k: frozenset(v) for k, v in reachable.items()}))
    if not posed:
        summary.notes.append(
            "no triplets: no room has a grid cell photographed at all four headings"
        )
        return []
    low, high = 0, 4 * sum(len(rows) for rows in rooms.values())
    best: list[Triplet] = []
    while low < high:  # the largest total every tier can supply (tier counts grow with it)
        mid = (low + high + 1) // 2
        try:
            best_mid = sample_triplets(posed, mid, seed=0)
        except ConfigError:
            high = mid - 1
        else:
            low, best = mid, best_mid
    if len(best) != low:
        best = sample_triplets(posed, low, seed=0) if low else []
    if not best:
        summary.notes.append(
            "no triplets: the posed photos cannot fill every tier (tier 0 needs the same "
            "pose in two layouts; the others cells 1 to 4 apart)"
        )
    return best


def _write_manifest(root, name, version, split, rooms, files, triplets, sizes, rules, class_map):
    from sgdata import __version__
    from sgdata.dataset.manifest import (
        Counts,
        FileEntry,
        Generator,
        ImageInfo,
        Manifest,
    )
    from sgdata.dataset.paths import triplets_path
    from sgdata.dataset.publish import write_manifest
    from sgdata.dataset.rows import triplet_table, write_parquet
    from sgdata.dataset.vocabulary import class_vocabulary

    files = list(files)
    if triplets:
        ids = {o for rows in rooms.values() for o in (r.obs_id for r in rows)}
        relative = triplets_path(split)
        info = write_parquet(triplet_table(triplets, ids), root / relative)
        files.append(FileEntry(relative, info.rows, info.sha256, info.bytes))
    slots, vocabulary = class_vocabulary()
    # One image size in the manifest: the most common (format, size); rows keep their own.
    fmt, width, height = max(sizes, key=lambda k: sizes[k]) if sizes else ("png", 1, 1)
    manifest = Manifest(
        name=name,
        version=version,
        generator=Generator("sgdata", __version__),
        seed=0,
        config={"source": SOURCE, "split": split, "class_map": str(class_map or "")},
        classes=vocabulary,
        num_slots=slots.num_slots,
        relation_rules=rules.to_dict(),
        image=ImageInfo(fmt, width, height),
        splits={split: tuple(sorted(rooms))},
        counts=Counts(
            rooms=len(rooms),
            observations={split: sum(len(r) for r in rooms.values())},
            triplets={split: len(triplets)},
            tiers={split: [sum(t.tier == k for t in triplets) for k in range(5)]},
        ),
        files=tuple(sorted(files, key=lambda f: f.path)),
    )
    write_manifest(manifest, root)
