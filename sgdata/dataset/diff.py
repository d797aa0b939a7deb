"""How two datasets differ: ``sgdata diff A B`` and ``sgdata validate --against REF``.

Two generations of one recipe (config, seed, generator, format) give the same bytes on one
machine, but llvmpipe compiles its rasteriser for the host CPU, so another machine may draw an
edge pixel differently. The content sha256 then differs and says nothing of how much. This
module compares two datasets the way a user of the data would:

- the manifest: the recipe fingerprint, then every field that differs, and the counts;
- the tables: files, rows and ids per split, the triplets exactly, every other observation
  column exactly (floats within 1e-6);
- the annotations: the visible objects per view (instances, classes, slots), their 2D boxes by
  IoU and visible pixels by count, the relations exactly;
- the pixels, per channel (``image``, ``depth``, ``instances``): views and pixels that differ,
  the largest and mean absolute difference, and the worst view.

The verdict is :data:`IDENTICAL` (every file's bytes equal), :data:`WITHIN` (differences, all
inside the :class:`Tolerance`: a pixel-level delta, boxes that moved by a pixel) or
:data:`BEYOND` (another dataset, or a delta larger than the tolerance). The verdict is the
exit code of ``sgdata diff``.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa

from sgdata.dataset.channels import CHANNELS, decode_channel
from sgdata.dataset.paths import observations_path
from sgdata.dataset.reader import Dataset, decode_image, read_table
from sgdata.dataset.schema import observations_schema
from sgdata.dataset.storage import image_bytes
from sgdata.dataset.tolerance import Tolerance

__all__ = ["BEYOND", "IDENTICAL", "WITHIN", "DatasetDiff", "Tolerance", "diff_datasets"]

IDENTICAL, WITHIN, BEYOND = 0, 1, 2
VERDICTS = {IDENTICAL: "identical", WITHIN: "differ within tolerance", BEYOND: "differ"}
PIXEL_COLUMNS = ("image", *CHANNELS)
ANNOTATION_COLUMNS = ("objects", "relations")
FLOAT_ATOL = 1e-6  # float columns (poses, light, 3D boxes) are computed, not rendered
# files derived from the others (they quote the manifest's figures): a difference there
# follows from one elsewhere and is not a finding of its own
DERIVED_FILES = ("README.md", "croissant.json")


@dataclass
class ChannelDelta:
    """How one pixel channel differs over all views compared."""

    views: int = 0
    views_differing: int = 0
    pixels: int = 0
    pixels_differing: int = 0
    max_abs: int = 0
    sum_abs: float = 0.0
    views_beyond: int = 0  # views differing on more pixels than the tolerance allows
    worst_view: str | None = None
    worst_share: float = 0.0

    def add_equal(self, pixels: int) -> None:
        self.views += 1
        self.pixels += pixels

    def add(self, view: str, a: np.ndarray, b: np.ndarray, tolerance: Tolerance) -> None:
        self.views += 1
        self.pixels += a.shape[0] * a.shape[1]
        if a.shape != b.shape:
            self.views_differing += 1
            self.views_beyond += 1
            self.pixels_differing += a.shape[0] * a.shape[1]
            self.worst_view, self.worst_share = view, 1.0
            return
        delta = np.abs(a.astype(np.int32) - b.astype(np.int32))
        per_pixel = delta.reshape(a.shape[0], a.shape[1], -1).max(axis=2)
        differing = int(np.count_nonzero(per_pixel))
        if not differing:
            return
        self.views_differing += 1
        self.pixels_differing += differing
        self.max_abs = max(self.max_abs, int(delta.max()))
        self.sum_abs += float(per_pixel.sum())
        share = differing / per_pixel.size
        self.views_beyond += share > tolerance.pixel_share
        if share > self.worst_share:
            self.worst_view, self.worst_share = view, share

    def line(self, name: str) -> str:
        if not self.views_differing:
            return f"{name}: {self.views} views, equal"
        return (
            f"{name}: {self.views_differing} of {self.views} views differ, "
            f"{self.pixels_differing / self.pixels:.4%} of pixels; max |d| {self.max_abs}, "
            f"mean |d| {self.sum_abs / self.pixels:.4f} over all pixels; worst view "
            f"{self.worst_view} ({self.worst_share:.2%} of its pixels)"
        )


@dataclass
class DatasetDiff:
    """Every finding of one comparison, and the verdict they add up to."""

    a: str
    b: str
    findings: list[tuple[int, str]] = field(default_factory=list)  # (WITHIN | BEYOND, text)
    channels: dict[str, ChannelDelta] = field(default_factory=dict)
    files_differing: int = 0
    files: int = 0
    recipes: tuple[str, str] = ("", "")  # each manifest's recipe fingerprint

    @property
    def verdict(self) -> int:
        pixels = any(delta.views_differing for delta in self.channels.values())
        if not (self.files_differing or self.findings or pixels):
            return IDENTICAL
        return max((level for level, _ in self.findings), default=WITHIN)

    def note(self, level: int, text: str) -> None:
        self.findings.append((level, text))

    def lines(self) -> list[str]:
        """The report, one screen: the verdict first, then what differs and by how much."""
        out = [f"{self.a} and {self.b}: {VERDICTS[self.verdict]}"]
        first, second = (recipe[:16] for recipe in self.recipes)
        same = f"the same ({first})" if first == second else f"{first} and {second}"
        out.append(f"recipe: {same}; files: {self.files_differing} of {self.files} differ in bytes")
        out += [f"{'beyond' if lv == BEYOND else 'within'}: {text}" for lv, text in self.findings]
        out += [delta.line(name) for name, delta in self.channels.items()]
        return out


def diff_datasets(a: str | Path, b: str | Path, tolerance: Tolerance | None = None) -> DatasetDiff:
    """Compare the datasets at ``a`` and ``b``.

    Raises:
        DatasetError: either is not a readable dataset.
    """
    tolerance = tolerance or Tolerance()
    first, second = Dataset.open(a), Dataset.open(b)
    report = DatasetDiff(str(a), str(b))
    if not _compare_manifests(first, second, report):
        return report
    annotation = first.manifest.config.get("annotation") or {}
    context = _Context(tolerance, int(annotation.get("min_visible_pixels", 0)))
    for split in first.splits:
        _compare_split(first, second, split, context, report)
    for name, delta in report.channels.items():
        if delta.views_beyond:
            report.note(
                BEYOND,
                f"{name}: {delta.views_beyond} views differ on more than "
                f"{tolerance.pixel_share:.2%} of their pixels",
            )
    return report


def _compare_manifests(a: Dataset, b: Dataset, report: DatasetDiff) -> bool:
    """Manifest findings; False when the datasets are too far apart to compare table by table
    (another recipe, other splits or files)."""
    ma, mb = a.manifest, b.manifest
    files_a = {f.path: f.sha256 for f in ma.files}
    files_b = {f.path: f.sha256 for f in mb.files}
    report.files = len(files_a | files_b)
    report.files_differing = sum(files_a.get(p) != files_b.get(p) for p in files_a | files_b)
    da, db = ma.to_dict(), mb.to_dict()
    fields = [k for k in da if k not in ("counts", "files") and da[k] != db.get(k)]
    report.recipes = (ma.recipe_fingerprint(), mb.recipe_fingerprint())
    if report.recipes[0] != report.recipes[1]:
        paths = [p for k in fields for p in _differing_paths(da[k], db.get(k), k)]
        report.note(BEYOND, f"another recipe: manifest {_listed(paths)} differ")
    if da["counts"] != db["counts"]:
        paths = _differing_paths(da["counts"], db["counts"], "counts")
        report.note(BEYOND, f"manifest {_listed(paths)} differ")
    if set(files_a) != set(files_b):
        only = sorted(set(files_a) ^ set(files_b))
        report.note(BEYOND, f"files in one dataset only: {_listed(only)}")
    if report.findings:
        return False
    tables = ("observations/", "triplets/")
    others = [
        p
        for p in files_a
        if files_a[p] != files_b[p] and not p.startswith(tables) and p not in DERIVED_FILES
    ]
    if others:
        report.note(BEYOND, f"files other than the tables differ: {_listed(others)}")
    return True


@dataclass(frozen=True)
class _Context:
    tolerance: Tolerance
    min_visible_pixels: int  # the recipe's: an object seen less is not listed


def _compare_split(
    a: Dataset, b: Dataset, split: str, context: _Context, report: DatasetDiff
) -> None:
    triplets_a, triplets_b = a.triplets(split), b.triplets(split)
    if not triplets_a.equals(triplets_b):
        rows = _differing_rows(triplets_a.to_pylist(), triplets_b.to_pylist())
        report.note(BEYOND, f"{split}: triplets differ in {rows} of {triplets_a.num_rows} rows")
    for room in a.rooms(split):
        _compare_observations(a, b, split, room, context, report)


def _compare_observations(
    a: Dataset, b: Dataset, split: str, room: str, context: _Context, report: DatasetDiff
) -> None:
    path = observations_path(split, room)
    ta = read_table(a.root / path, observations_schema())
    tb = read_table(b.root / path, observations_schema())
    where = f"{split}/{room}"
    if ta.column("obs_id").to_pylist() != tb.column("obs_id").to_pylist():
        report.note(BEYOND, f"{where}: other views (obs_id lists differ)")
        return
    ids = ta.column("obs_id").to_pylist()
    for name in ta.column_names:
        if name in PIXEL_COLUMNS or name in ANNOTATION_COLUMNS:
            continue
        _compare_column(name, ta.column(name), tb.column(name), where, report)
    _compare_annotations(ids, ta, tb, where, context, report)
    for name in PIXEL_COLUMNS:
        _compare_pixels(name, ids, ta, tb, context.tolerance, report)


def _compare_pixels(
    name: str, ids: list[str], a: pa.Table, b: pa.Table, tolerance: Tolerance, report: DatasetDiff
) -> None:
    """One channel, view by view; encoded bytes first (equal bytes: nothing to decode). The
    instance mask is compared as the instances it shows, not as indices into ``objects``
    (an object missing from one list shifts the indices of those after it)."""
    sizes = [c["width"] * c["height"] for c in a.column("camera").to_pylist()]
    cells = [a.column(name).to_pylist(), b.column(name).to_pylist()]
    objects = [a.column("objects").to_pylist(), b.column("objects").to_pylist()]
    for view, size, cell_a, cell_b, objects_a, objects_b in zip(
        ids, sizes, *cells, *objects, strict=True
    ):
        if cell_a is None and cell_b is None:
            continue
        delta = report.channels.setdefault(name, ChannelDelta())
        if cell_a is None or cell_b is None:
            report.note(BEYOND, f"{view}: {name} is stored in one dataset only")
            continue
        bytes_a, bytes_b = image_bytes(cell_a), image_bytes(cell_b)
        if bytes_a == bytes_b:
            delta.add_equal(size)
        elif name == "image":
            delta.add(view, decode_image(bytes_a), decode_image(bytes_b), tolerance)
        elif name == "instances":
            mask_a = _instance_ids(decode_channel(bytes_a), objects_a)
            delta.add(view, mask_a, _instance_ids(decode_channel(bytes_b), objects_b), tolerance)
        else:
            delta.add(view, decode_channel(bytes_a), decode_channel(bytes_b), tolerance)


def _instance_ids(mask: np.ndarray, objects: list[dict[str, Any]]) -> np.ndarray:
    """An instance mask's values as instance ids + 1 (0 stays background)."""
    lookup = np.array([0, *(o["instance"] + 1 for o in objects)], dtype=np.int64)
    return lookup[np.minimum(mask, len(objects))]


def _compare_column(
    name: str, a: pa.ChunkedArray, b: pa.ChunkedArray, where: str, report: DatasetDiff
) -> None:
    if a.equals(b):
        return
    if pa.types.is_floating(a.type):
        va, vb = a.to_numpy(zero_copy_only=False), b.to_numpy(zero_copy_only=False)
        if np.allclose(va, vb, rtol=0, atol=FLOAT_ATOL, equal_nan=True):
            report.note(WITHIN, f"{where}: {name} differs by at most {np.abs(va - vb).max():.2g}")
            return
    rows = _differing_rows(a.to_pylist(), b.to_pylist())
    report.note(BEYOND, f"{where}: {name} differs in {rows} of {len(a)} views")


@dataclass
class _AnnotationTally:
    """How the annotations of one room's views differ."""

    edge_objects: int = 0  # seen in one dataset only, at the visibility threshold
    other_objects: list[str] = field(default_factory=list)  # views: clearly seen in one only
    moved: int = 0
    worst_iou: float = 1.0
    worst_iou_view: str = ""
    pixel_counts: int = 0
    beyond: set[str] = field(default_factory=set)  # views past the tolerance
    relations: int = 0  # views whose relations among objects seen in both differ

    def findings(self, where: str) -> Iterator[tuple[int, str]]:
        if self.other_objects:
            yield (
                BEYOND,
                (
                    f"{where}: objects seen clearly in one dataset only, in "
                    f"{len(self.other_objects)} views (first {self.other_objects[0]})"
                ),
            )
        if self.relations:
            yield (
                BEYOND,
                f"{where}: relations among the same objects differ in {self.relations} views",
            )
        parts = []
        if self.edge_objects:
            parts.append(f"{self.edge_objects} objects at the visibility threshold in one only")
        if self.moved:
            parts.append(
                f"{self.moved} boxes moved (lowest IoU {self.worst_iou:.3f}, {self.worst_iou_view})"
            )
        if self.pixel_counts:
            parts.append(f"{self.pixel_counts} visible-pixel counts differ")
        if parts:
            over = f"; beyond tolerance in {len(self.beyond)} views" if self.beyond else ""
            yield (BEYOND if self.beyond else WITHIN), f"{where}: {', '.join(parts)}{over}"


def _compare_annotations(
    ids: list[str],
    a: pa.Table,
    b: pa.Table,
    where: str,
    context: _Context,
    report: DatasetDiff,
) -> None:
    """Objects matched by instance: the same ones (an object at the visibility threshold may be
    listed in one dataset only), boxes by IoU, visible pixels by count; the relations among
    the objects both list, exactly."""
    tally = _AnnotationTally()
    sizes = [c["width"] * c["height"] for c in a.column("camera").to_pylist()]
    columns = [t.column(c).to_pylist() for c in ANNOTATION_COLUMNS for t in (a, b)]
    for view, size, objects_a, objects_b, relations_a, relations_b in zip(
        ids, sizes, *columns, strict=True
    ):
        allowed = context.tolerance.pixel_share * size
        by_a = {o["instance"]: o for o in objects_a}
        by_b = {o["instance"]: o for o in objects_b}
        one_only = by_a.keys() ^ by_b.keys()
        for instance in one_only:
            seen = (by_a.get(instance) or by_b[instance])["visible_pixels"]
            if seen > context.min_visible_pixels + allowed:
                tally.other_objects.append(view)
            else:
                tally.edge_objects += 1
        both = by_a.keys() & by_b.keys()
        for instance in sorted(both):
            a_object, b_object = by_a[instance], by_b[instance]
            if _identity(a_object) != _identity(b_object):
                tally.other_objects.append(view)
            elif a_object["slot"] != b_object["slot"] and not one_only:
                tally.beyond.add(view)  # slots shift only when an object joins or leaves
            else:
                _compare_geometry(view, a_object, b_object, allowed, context, tally)
        kept_a = [r for r in relations_a if r["src"] in both and r["dst"] in both]
        kept_b = [r for r in relations_b if r["src"] in both and r["dst"] in both]
        tally.relations += kept_a != kept_b
    for level, text in tally.findings(where):
        report.note(level, text)


def _compare_geometry(
    view: str,
    a: dict[str, Any],
    b: dict[str, Any],
    allowed: float,
    context: _Context,
    tally: _AnnotationTally,
) -> None:
    iou = box_iou(a["box2d"], b["box2d"])
    tally.moved += iou < 1.0
    if iou < tally.worst_iou:
        tally.worst_iou, tally.worst_iou_view = iou, view
    gap = abs(a["visible_pixels"] - b["visible_pixels"])
    tally.pixel_counts += gap > 0
    exact = all(_close(a[key], b[key]) for key in ("box3d_min", "box3d_max", "obb", "support"))
    if iou < context.tolerance.min_iou or gap > allowed or not exact:
        tally.beyond.add(view)


def box_iou(a: list[int], b: list[int]) -> float:
    """IoU of two ``[u1, v1, u2, v2]`` boxes (u2, v2 exclusive); 1 for two empty boxes."""
    inter_w = max(0, min(a[2], b[2]) - max(a[0], b[0]))
    inter_h = max(0, min(a[3], b[3]) - max(a[1], b[1]))
    inter = inter_w * inter_h
    union = (a[2] - a[0]) * (a[3] - a[1]) + (b[2] - b[0]) * (b[3] - b[1]) - inter
    return inter / union if union > 0 else 1.0


def _identity(obj: dict[str, Any]) -> tuple:
    return obj["class_name"], obj["class_id"], obj["dynamics"]


def _close(a: Any, b: Any) -> bool:
    if a is None or b is None or isinstance(a, int):
        return a == b
    return bool(np.allclose(a, b, rtol=0, atol=FLOAT_ATOL))


def _differing_rows(a: list, b: list) -> int:
    return sum(x != y for x, y in zip(a, b, strict=False)) + abs(len(a) - len(b))


def _differing_paths(a: Any, b: Any, prefix: str) -> list[str]:
    """The dotted paths under which two JSON values differ, deepest first named."""
    if isinstance(a, dict) and isinstance(b, dict):
        keys = sorted(set(a) | set(b))
        return [
            p
            for k in keys
            if a.get(k) != b.get(k)
            for p in _differing_paths(a.get(k), b.get(k), f"{prefix}.{k}")
        ]
    return [prefix]


def _listed(items: list[str], show: int = 5) -> str:
    more = f" and {len(items) - show} more" if len(items) > show else ""
    return ", ".join(items[:show]) + more
