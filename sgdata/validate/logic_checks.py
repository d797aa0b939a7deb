"""Logic checks on observation rows, vectorised over every object and relation of a split:
2D boxes, visible pixels, 3D boxes, classes, slots, instances, poses, relation structure."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from sgdata.dataset.camera import CAMERA_SINCE, camera_columns
from sgdata.dataset.paths import MANIFEST
from sgdata.dataset.schema import parse_version as _version
from sgdata.validate.loading import Flat, SplitTables, column_numpy, flatten_list
from sgdata.validate.problems import Collector

__all__ = ["check_rows", "check_objects", "check_relations"]

DYNAMICS = ("static", "low", "high")
ON, IN, PROXIMITY, DISJOINT = 0, 1, 2, 3


def _report(
    out: Collector,
    tables: SplitTables,
    check: str,
    bad: np.ndarray,
    rows: np.ndarray,
    field: str | list[str],
    message: Any,
) -> None:
    """One problem per True of ``bad``; ``rows`` maps entries to observation rows; ``field``
    and ``message`` are strings or per-entry callables/lists."""
    for k in np.flatnonzero(bad):
        f, row = tables.where(rows[k])
        where = field(k) if callable(field) else field
        text = message(k) if callable(message) else message
        out.add(check, tables.files[f], text, row=row, field=where)


def check_rows(tables: SplitTables, raw: dict[str, Any], out: Collector) -> None:
    """Row-level rules: poses present for synthetic rows; a real row's grid pose (grid_i,
    grid_j, heading) all set (a photo labeled with its pose) or all null; the camera size is
    the manifest's for synthetic rows."""
    obs = tables.observations
    if obs is None:
        return
    n = obs.num_rows
    rows = np.arange(n)
    synthetic = column_numpy(obs, "domain") == "synthetic"
    out.count("rows.pose", n)
    grid = ("grid_i", "grid_j", "heading")
    grid_null = [obs.column(name).is_null().to_numpy(zero_copy_only=False) for name in grid]
    partial = np.any(grid_null, axis=0) & ~np.all(grid_null, axis=0)
    for name in ("x", "y", "theta", *grid):
        null = obs.column(name).is_null().to_numpy(zero_copy_only=False)
        _report(out, tables, "rows.pose", synthetic & null, rows, name, "null in a synthetic row")
        if name in grid:
            msg = "null while the row's other grid fields are set (expected all three or none)"
            _report(out, tables, "rows.pose", ~synthetic & partial & null, rows, name, msg)
    heading = column_numpy(obs, "heading", -1)
    posed = synthetic | ~grid_null[2]
    bad = posed & ((heading < 0) | (heading > 3))
    _report(
        out, tables, "rows.pose", bad, rows, "heading", lambda k: f"{heading[k]}: expected 0..3"
    )
    camera = obs.column("camera").combine_chunks()
    width = column_numpy(camera, "width")
    height = column_numpy(camera, "height")
    image = raw["image"]
    out.count("rows.camera", n)
    bad = synthetic & ((width != image["width"]) | (height != image["height"]))
    msg = lambda k: (  # noqa: E731
        f"{width[k]}x{height[k]}; {MANIFEST} image is {image['width']}x{image['height']}"
    )
    _report(out, tables, "rows.camera", bad, rows, "camera", msg)
    if _version(raw["format_version"]) >= _version(CAMERA_SINCE):
        _check_stated_camera(tables, rows, out)


def _check_stated_camera(tables: SplitTables, rows: np.ndarray, out: Collector) -> None:
    """Each view's ``intrinsics`` and ``camera_to_world`` are what its pose and camera
    columns give (:func:`sgdata.dataset.camera.camera_columns`); null where those are."""
    obs = tables.observations
    for name, derived in zip(("intrinsics", "camera_to_world"), camera_columns(obs), strict=True):
        stated = obs.column(name).to_pylist()
        wanted = derived.to_pylist()
        bad = np.array([_differs(a, b) for a, b in zip(stated, wanted, strict=True)], bool)
        msg = lambda k, s=stated, w=wanted: (  # noqa: E731
            f"{_short(s[k])}; the row's x, y, theta and camera give {_short(w[k])} "
            "(regenerate, or run sgdata migrate on a dataset written before the camera)"
        )
        _report(out, tables, "rows.camera", bad, rows, name, msg)


def _differs(stated: list[float] | None, wanted: list[float] | None) -> bool:
    if stated is None or wanted is None:
        return (stated is None) != (wanted is None)
    return not np.allclose(stated, wanted, rtol=1e-9, atol=1e-9)


def _short(values: list[float] | None) -> str:
    return "null" if values is None else "[" + ", ".join(f"{v:.4g}" for v in values) + "]"


def _instance_codes(*arrays: np.ndarray) -> tuple[list[np.ndarray], int]:
    """Dense codes for instance ids shared by several arrays, and the code count."""
    joined = np.concatenate(arrays) if arrays else np.zeros(0, np.int64)
    _, inverse = np.unique(joined, return_inverse=True)
    out, start = [], 0
    for a in arrays:
        out.append(inverse[start : start + len(a)].astype(np.int64))
        start += len(a)
    return out, int(inverse.max(initial=-1)) + 1


@dataclass(frozen=True)
class _Objects:
    """The flattened objects of a split and where their problems go."""

    tables: SplitTables
    out: Collector
    obj: Flat
    synthetic: np.ndarray  # per object: its row is synthetic

    @property
    def rows(self) -> np.ndarray:
        return self.obj.parent

    def at(self, name: str) -> Any:
        """The field of entry ``k`` as ``objects[i].name``."""
        pos = self.obj.position
        return lambda k: f"objects[{pos[k]}].{name}"

    def report(self, check: str, bad: np.ndarray, field: str, message: Any) -> None:
        _report(self.out, self.tables, check, bad, self.rows, self.at(field), message)


def check_objects(tables: SplitTables, raw: dict[str, Any], out: Collector) -> Flat | None:
    """Object-level rules; returns the flattened objects for the relation checks."""
    obs = tables.observations
    if obs is None:
        return None
    obj = flatten_list(obs, "objects")
    synthetic = (column_numpy(obs, "domain") == "synthetic")[obj.parent]
    objects = _Objects(tables, out, obj, synthetic)
    _check_boxes2d(objects)
    _check_boxes3d(objects)
    class_name, safe_id, in_range = _check_classes(objects, raw["classes"])
    _check_slots(objects, raw, safe_id, in_range)
    _check_instances(objects, class_name)
    return obj


def _check_boxes2d(objects: _Objects) -> None:
    """2D boxes inside the image, and visible pixels."""
    obj, rows, e = objects.obj, objects.rows, len(objects.rows)
    camera = objects.tables.observations.column("camera").combine_chunks()
    width = column_numpy(camera, "width").astype(np.int64)[rows]
    height = column_numpy(camera, "height").astype(np.int64)[rows]
    box, _ = obj.fixed("box2d", 4, np.int64)
    u1, v1, u2, v2 = box.T
    bad = ~((u1 >= 0) & (u1 < u2) & (u2 <= width) & (v1 >= 0) & (v1 < v2) & (v2 <= height))
    objects.out.count("objects.box2d", e)
    objects.report(
        "objects.box2d",
        bad,
        "box2d",
        lambda k: (
            f"{box[k].tolist()} in a {width[k]}x{height[k]} image; expected "
            "0 <= u1 < u2 <= width and 0 <= v1 < v2 <= height"
        ),
    )
    visible = obj.get("visible_pixels")
    objects.out.count("objects.visible_pixels", e)
    objects.report(
        "objects.visible_pixels",
        visible <= 0,
        "visible_pixels",
        lambda k: f"{visible[k]}; expected > 0",
    )


def _check_boxes3d(objects: _Objects) -> None:
    """3D boxes: set and ordered in synthetic rows, null in real ones."""
    obj, synthetic = objects.obj, objects.synthetic
    lo, lo_ok = obj.fixed("box3d_min", 3, np.float64)
    hi, hi_ok = obj.fixed("box3d_max", 3, np.float64)
    obb_ok = obj.fixed("obb", 7, np.float64)[1]
    objects.out.count("objects.box3d", len(objects.rows))
    inverted = lo_ok & hi_ok & np.any(lo > hi, axis=1)
    objects.report(
        "objects.box3d",
        synthetic & inverted,
        "box3d_min",
        lambda k: f"min {lo[k].round(4).tolist()} > max {hi[k].round(4).tolist()} on some axis",
    )
    missing = synthetic & ~(lo_ok & hi_ok)
    objects.report("objects.box3d", missing, "box3d_min", "null 3D box in a synthetic row")
    real_box = ~synthetic & (lo_ok | hi_ok | obb_ok)
    objects.report(
        "objects.box3d",
        real_box,
        "box3d_min",
        "3D box set in a real row; real photos have no 3D boxes (expected null)",
    )


def _check_classes(
    objects: _Objects, classes: list[dict[str, Any]]
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Class names in the vocabulary, ids that match them, known dynamics; returns the class
    names, the ids made safe to index with, and which ids are in range."""
    obj = objects.obj
    names = np.array([c["name"] for c in classes], dtype=object)
    class_id = obj.get("class_id").astype(np.int64)
    class_name = obj.get("class_name")
    in_range = (class_id >= 0) & (class_id < len(classes))
    safe_id = np.where(in_range, class_id, 0)
    objects.out.count("objects.class", len(objects.rows))
    known = np.isin(class_name, names)
    objects.report(
        "objects.class",
        ~known,
        "class_name",
        lambda k: f"{class_name[k]!r} is not in the {MANIFEST} class vocabulary",
    )
    mismatch = known & (~in_range | (names[safe_id] != class_name))
    objects.report(
        "objects.class",
        mismatch,
        "class_id",
        lambda k: (
            f"class_id {class_id[k]} is "
            + (f"{names[class_id[k]]!r}" if in_range[k] else "out of range")
            + f"; the object's class_name is {class_name[k]!r}"
        ),
    )
    dynamics = obj.get("dynamics")
    objects.report(
        "objects.class",
        ~np.isin(dynamics, DYNAMICS),
        "dynamics",
        lambda k: f"{dynamics[k]!r}; expected static, low or high",
    )
    return class_name, safe_id, in_range


def _check_slots(
    objects: _Objects, raw: dict[str, Any], safe_id: np.ndarray, in_range: np.ndarray
) -> None:
    """Slots in range, inside their class's run, and one object per slot in a view."""
    classes, rows = raw["classes"], objects.rows
    names = np.array([c["name"] for c in classes], dtype=object)
    slot = objects.obj.get("slot").astype(np.int64)
    num_slots = int(raw["num_slots"])
    starts = np.array([c["slot_start"] for c in classes], dtype=np.int64)[safe_id]
    counts = np.array([c["slot_count"] for c in classes], dtype=np.int64)[safe_id]
    objects.out.count("objects.slot", len(rows))
    outside = (slot < 0) | (slot >= num_slots)
    objects.report(
        "objects.slot",
        outside,
        "slot",
        lambda k: f"{slot[k]}; expected 0 <= slot < num_slots={num_slots}",
    )
    off_run = ~outside & in_range & ((slot < starts) | (slot >= starts + counts))
    objects.report(
        "objects.slot",
        off_run,
        "slot",
        lambda k: (
            f"{slot[k]} is outside the run of {names[safe_id[k]]!r} "
            f"[{starts[k]}, {starts[k] + counts[k]})"
        ),
    )
    key = rows * (num_slots + 1) + np.clip(slot, 0, num_slots)
    dup = _duplicates(key) & ~outside
    objects.report(
        "objects.slot",
        dup,
        "slot",
        lambda k: f"slot {slot[k]} is used by another object of the same view",
    )


def _check_instances(objects: _Objects, class_name: np.ndarray) -> None:
    """Instances unique in a view, one class per instance in a room, no object on itself."""
    obs, rows = objects.tables.observations, objects.rows
    instance = objects.obj.get("instance").astype(np.int64)
    objects.out.count("objects.instance", len(rows))
    (codes,), n_codes = _instance_codes(instance)
    dup = _duplicates(rows * max(n_codes, 1) + codes)
    objects.report(
        "objects.instance",
        dup,
        "instance",
        lambda k: f"instance {instance[k]} appears twice in the view",
    )
    # An instance id is one object of the room: one class in every view of the room.
    _, room_code = np.unique(column_numpy(obs, "room_id")[rows], return_inverse=True)
    _, first, same = np.unique(
        room_code.astype(np.int64) * max(n_codes, 1) + codes, return_index=True, return_inverse=True
    )
    first_class = class_name[first][same]
    obs_ids = column_numpy(obs, "obs_id")
    objects.report(
        "objects.instance",
        class_name != first_class,
        "class_name",
        lambda k: (
            f"instance {instance[k]} is {class_name[k]!r} here but {first_class[k]!r} in "
            f"{obs_ids[rows[first[same[k]]]]} of the same room; expected one class per instance"
        ),
    )
    support = objects.obj.get("support", -1).astype(np.int64)
    objects.report(
        "objects.instance",
        support == instance,
        "support",
        lambda k: f"object {instance[k]} rests on itself",
    )


def _duplicates(key: np.ndarray) -> np.ndarray:
    """True for every entry whose key occurred earlier."""
    if len(key) == 0:
        return np.zeros(0, dtype=bool)
    _, first = np.unique(key, return_index=True)
    dup = np.ones(len(key), dtype=bool)
    dup[first] = False
    return dup


def check_relations(tables: SplitTables, raw: dict[str, Any], obj: Flat, out: Collector) -> Flat:
    """Relation structure: type codes, ends among the view's objects, no self edge, one edge
    per ordered pair, never on and in for one pair, proximity and disjoint both ways."""
    obs = tables.observations
    rel = flatten_list(obs, "relations")
    p, pos = rel.parent, rel.position
    e = len(p)
    loc = lambda name: lambda k: f"relations[{pos[k]}].{name}"  # noqa: E731
    src = rel.get("src").astype(np.int64)
    dst = rel.get("dst").astype(np.int64)
    kind = rel.get("type").astype(np.int64)
    names = raw["relation_types"]
    name_of = lambda t: names[t] if 0 <= t < len(names) else str(t)  # noqa: E731

    out.count("relations.type", e)
    _report(
        out,
        tables,
        "relations.type",
        (kind < 0) | (kind >= len(names)),
        p,
        loc("type"),
        lambda k: f"{kind[k]}; expected 0..{len(names) - 1} ({MANIFEST} relation_types)",
    )

    instance = obj.get("instance").astype(np.int64)
    (c_obj, c_src, c_dst), n = _instance_codes(instance, src, dst)
    n = max(n, 1)
    obj_keys = obj.parent * n + c_obj
    out.count("relations.ends", e)
    for end, codes, values in (("src", c_src, src), ("dst", c_dst, dst)):
        missing = ~np.isin(p * n + codes, obj_keys)
        _report(
            out,
            tables,
            "relations.ends",
            missing,
            p,
            loc(end),
            lambda k, v=values: f"instance {v[k]} is not among the view's objects",
        )

    out.count("relations.self", e)
    _report(
        out,
        tables,
        "relations.self",
        src == dst,
        p,
        loc("src"),
        lambda k: f"relation {name_of(kind[k])} from instance {src[k]} to itself",
    )

    ordered = (p * n + c_src) * n + c_dst
    out.count("relations.duplicate", e)
    _report(
        out,
        tables,
        "relations.duplicate",
        _duplicates(ordered),
        p,
        loc("src"),
        lambda k: f"a second relation {src[k]}->{dst[k]} ({name_of(kind[k])}) in the view",
    )

    lo_c, hi_c = np.minimum(c_src, c_dst), np.maximum(c_src, c_dst)
    pair = (p * n + lo_c) * n + hi_c
    out.count("relations.on_and_in", e)
    on_pairs = pair[kind == ON]
    both = (kind == IN) & np.isin(pair, on_pairs)
    _report(
        out,
        tables,
        "relations.on_and_in",
        both,
        p,
        loc("type"),
        lambda k: f"pair ({src[k]}, {dst[k]}) has both an on and an in relation",
    )

    out.count("relations.symmetric", e)
    typed = ordered * 4 + np.clip(kind, 0, 3)
    reverse = ((p * n + c_dst) * n + c_src) * 4 + np.clip(kind, 0, 3)
    mutual = (kind == PROXIMITY) | (kind == DISJOINT)
    one_way = mutual & (src != dst) & ~np.isin(reverse, typed)
    _report(
        out,
        tables,
        "relations.symmetric",
        one_way,
        p,
        loc("type"),
        lambda k: (
            f"{name_of(kind[k])} {src[k]}->{dst[k]} without {dst[k]}->{src[k]} "
            f"({name_of(kind[k])} is symmetric)"
        ),
    )
    directed = (kind == ON) | (kind == IN)
    extra = directed & np.isin(pair, pair[mutual])
    _report(
        out,
        tables,
        "relations.symmetric",
        extra,
        p,
        loc("type"),
        lambda k: f"pair ({src[k]}, {dst[k]}) has {name_of(kind[k])} and another type too",
    )
    return rel
