"""Scene graphs from a trained detector: what a localizer sees when no generator annotates
its views (``seannet eval --graphs detected``).

Per view: the detector's boxes above a score threshold (chosen on val views: the best F1 of
boxes matched to the truth at IoU 0.5 with the same class), lifted to 3D with the depth
channel (:mod:`seannet.detection.lift`), what rests on what inferred from those boxes, and
the relations of the generator's rules. Instance ids are 1..n in descending score; a class's
detections fill its slot run in that order (the truth fills it by instance id, which a
detector cannot know).

:class:`DetectedGraphs` hands these graphs to the loaders where the generator's would be
read: it is a :class:`~seannet.data.box_noise.BoxNoise` (the boxes a detector gives), so the
embedding cache, the eval file names and every box term key on it as on any noise. The
detections are cached per split under the detector's run, keyed by the dataset's manifest,
the checkpoint and :data:`GRAPHS_CODE`.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import torch

from seannet.data.box_noise import BoxNoise, ObjectColumns, RelationColumns
from seannet.data.opening import DataSource, open_dataset
from seannet.detection.lift import infer_support, lift_boxes
from seannet.detection.train import TrainedDetector
from seannet.errors import DataError
from sgdata.annotate.relations import compute_relations
from sgdata.dataset import Dataset, decode_image, observations_schema, read_table
from sgdata.dataset.channels import decode_channel, depth_metres
from sgdata.dataset.storage import image_bytes
from sgdata.fileio import atomic_file, atomic_write_text

__all__ = [
    "GRAPHS_CODE",
    "DetectedGraphs",
    "ViewDetections",
    "choose_threshold",
    "detected_graphs",
    "detections",
    "lifted_detections",
    "match_boxes",
    "placed_detections",
    "val_threshold",
    "view_graph",
]

GRAPHS_CODE = 1  # bump when detections, lifting, support or slots change: the cache is remade
THRESHOLDS = tuple(round(0.1 + 0.05 * k, 2) for k in range(17))  # 0.1 .. 0.9
CACHE = "graphs"
Progress = Callable[[str, int, int], None]

_DETECTIONS = pa.schema(
    [
        ("obs_id", pa.string()),
        ("box2d", pa.list_(pa.float32(), 4)),
        ("label", pa.int16()),  # COCO category id: class id + 1
        ("score", pa.float32()),
        ("box3d_min", pa.list_(pa.float32(), 3)),
        ("box3d_max", pa.list_(pa.float32(), 3)),
        ("lifted", pa.bool_()),
    ]
)


@dataclass(frozen=True)
class ViewDetections:
    """One view's detections, best first."""

    box2d: np.ndarray  # (n, 4) float32
    class_id: np.ndarray  # (n,) int64 dataset class ids
    score: np.ndarray  # (n,)
    box_min: np.ndarray  # (n, 3)
    box_max: np.ndarray  # (n, 3)
    lifted: np.ndarray  # (n,) bool

    @classmethod
    def none(cls) -> ViewDetections:
        """A view the detector found nothing in."""
        return cls(np.zeros((0, 4), np.float32), np.zeros(0, np.int64), np.zeros(0),
                   np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0, bool))  # fmt: skip


@dataclass(frozen=True)
class DetectedGraphs(BoxNoise):
    """The detector's graphs in place of the generator's, as a box noise the loaders apply.

    Its fields (what the embedding cache keys on) name the detector and the threshold; the
    graphs themselves are held beside them, by view id (:meth:`of`)."""

    detector: str = ""  # the detector checkpoint's sha256
    threshold: float = 0.5  # detections kept: score >= threshold
    code: int = GRAPHS_CODE

    @classmethod
    def of(
        cls,
        views: dict[str, tuple[ObjectColumns, RelationColumns]],
        detector: str,
        threshold: float,
    ) -> DetectedGraphs:
        graphs = cls(detector=detector, threshold=threshold)
        object.__setattr__(graphs, "views", views)
        return graphs

    @property
    def active(self) -> bool:
        return True

    def label(self) -> str:
        return f"detected-{self.detector[:8]}-t{self.threshold:g}"

    def apply(
        self,
        obs_id: str,
        objects: ObjectColumns,
        relations: RelationColumns,
        *,
        slot_runs: np.ndarray,
        image_hw: tuple[int, int],
    ) -> tuple[ObjectColumns, RelationColumns]:
        try:
            return self.__dict__.get("views", {})[obs_id]
        except KeyError:
            raise DataError(
                f"view {obs_id}: no detected graph (its split was not detected)"
            ) from None


def _key(ds: Dataset, detector: TrainedDetector) -> dict[str, object]:
    return {
        "manifest_sha256": ds.manifest_sha256,
        "detector": detector.checkpoint_sha256,
        "code": GRAPHS_CODE,
    }


def _detect_split(
    ds: Dataset, split: str, detector: TrainedDetector, progress: Progress | None
) -> pa.Table:
    """Every view of ``split`` through the detector and the depth lifting, as a table."""
    columns = ["obs_id", "image", "depth", "intrinsics", "camera_to_world"]
    rows: dict[str, list] = {name: [] for name in _DETECTIONS.names}
    total = sum(pq.ParquetFile(p).metadata.num_rows for p in ds.observation_files(split))
    done = 0
    for shard in ds.observation_files(split):
        table = read_table(shard, observations_schema(), columns=columns).to_pylist()
        for start in range(0, len(table), 16):
            chunk = table[start : start + 16]
            images = [
                torch.from_numpy(decode_image(r["image"]).copy()).permute(2, 0, 1).float() / 255.0
                for r in chunk
            ]
            with torch.no_grad():
                found = detector.model(images)
            for row, dets in zip(chunk, found, strict=True):
                if row["depth"] is None or row["intrinsics"] is None:
                    raise DataError(
                        f"{ds.root}: view {row['obs_id']} has no depth or camera; detected "
                        "graphs lift boxes with depth: generate with [outputs] depth = true"
                    )
                depth = depth_metres(
                    decode_channel(image_bytes(row["depth"]), where=f"{row['obs_id']}: depth")
                )
                found = lifted_detections(
                    dets, depth, np.asarray(row["intrinsics"]), np.asarray(row["camera_to_world"])
                )
                for k in range(len(found.score)):
                    rows["obs_id"].append(row["obs_id"])
                    rows["box2d"].append(found.box2d[k].tolist())
                    rows["label"].append(int(found.class_id[k]) + 1)
                    rows["score"].append(float(found.score[k]))
                    rows["box3d_min"].append(found.box_min[k].tolist())
                    rows["box3d_max"].append(found.box_max[k].tolist())
                    rows["lifted"].append(bool(found.lifted[k]))
            done += len(chunk)
            if progress is not None:
                progress(split, done, total)
    return pa.table(rows, schema=_DETECTIONS)


def lifted_detections(
    found: dict[str, torch.Tensor],
    depth: np.ndarray,
    intrinsics: np.ndarray,
    camera_to_world: np.ndarray,
) -> ViewDetections:
    """One view's detector output (torchvision's ``boxes``, ``labels``, ``scores``) lifted to
    3D with the view's depth (metres) and camera, in the detector's order."""
    boxes = found["boxes"].numpy()
    lo, hi, ok = lift_boxes(depth, boxes, intrinsics, camera_to_world)
    return ViewDetections(
        boxes.astype(np.float32),
        found["labels"].numpy().astype(np.int64) - 1,
        found["scores"].numpy(),
        lo,
        hi,
        ok,
    )


def _cached_split(
    ds: Dataset, split: str, detector: TrainedDetector, progress: Progress | None
) -> pa.Table:
    """``split``'s detections, from the run's cache when its key matches, else detected and
    cached (atomically)."""
    key = json.dumps(_key(ds, detector), sort_keys=True)
    path = detector.run / CACHE / ds.manifest_sha256[:16] / f"{split}.parquet"
    if path.exists():
        try:
            table = pq.read_table(path)
            if (table.schema.metadata or {}).get(b"key", b"").decode() == key:
                return table
        except (OSError, pa.ArrowInvalid):
            pass  # unreadable: detect again and replace it
    table = _detect_split(ds, split, detector, progress)
    table = table.replace_schema_metadata({"key": key})
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_file(path) as tmp:
        pq.write_table(table, tmp)
    return table


def detections(
    ds: Dataset, split: str, detector: TrainedDetector, progress: Progress | None = None
) -> dict[str, ViewDetections]:
    """``split``'s detections by view (a view with none is absent), from the run's cache."""
    return _by_view(_cached_split(ds, split, detector, progress))


def _by_view(table: pa.Table) -> dict[str, ViewDetections]:
    """The cached detections grouped by view, best first within a view."""
    cols = {
        name: table.column(name).to_numpy(zero_copy_only=False)
        for name in ("obs_id", "label", "score", "lifted")
    }
    box2d = np.asarray(table.column("box2d").combine_chunks().flatten()).reshape(-1, 4)
    lo = np.asarray(table.column("box3d_min").combine_chunks().flatten()).reshape(-1, 3)
    hi = np.asarray(table.column("box3d_max").combine_chunks().flatten()).reshape(-1, 3)
    out: dict[str, ViewDetections] = {}
    ids = cols["obs_id"]
    order = np.lexsort((-cols["score"], ids)) if len(ids) else np.zeros(0, np.int64)
    starts = np.flatnonzero(np.r_[True, ids[order][1:] != ids[order][:-1]]) if len(ids) else []
    ends = [*starts[1:], len(order)] if len(ids) else []
    for s, e in zip(starts, ends, strict=True):
        k = order[s:e]
        out[str(ids[k[0]])] = ViewDetections(
            box2d[k].astype(np.float32),
            cols["label"][k].astype(np.int64) - 1,
            cols["score"][k],
            lo[k],
            hi[k],
            cols["lifted"][k].astype(bool),
        )
    return out


def _kept(found: ViewDetections, threshold: float) -> np.ndarray:
    """The detections a graph holds: scored at least ``threshold``, at least a pixel wide and
    high (a thinner box holds no pixel, and the box terms divide by its area)."""
    size = found.box2d[:, 2:] - found.box2d[:, :2]
    return (found.score >= threshold) & (size >= 1.0).all(axis=1)


def placed_detections(found: ViewDetections, threshold: float, slot_runs: np.ndarray) -> np.ndarray:
    """The detections a view's graph holds, as indices into ``found`` in instance order
    (instance k + 1 is detection ``[k]``): those :func:`_kept`, best first, while their class
    has a slot left (the best detection, the first slot)."""
    kept = np.flatnonzero(_kept(found, threshold))
    used: dict[int, int] = {}
    placed = []
    for k in kept.tolist():
        c = int(found.class_id[k])
        if used.get(c, 0) < int(slot_runs[c][1]):
            used[c] = used.get(c, 0) + 1
            placed.append(k)
    return np.array(placed, dtype=np.int64)


def view_graph(
    found: ViewDetections, threshold: float, slot_runs: np.ndarray
) -> tuple[ObjectColumns, RelationColumns]:
    """One view's graph from its detections above ``threshold``."""
    k = placed_detections(found, threshold, slot_runs)
    class_id, box2d, lo, hi, lifted = (
        found.class_id[k], found.box2d[k], found.box_min[k], found.box_max[k], found.lifted[k]
    )  # fmt: skip
    slot = np.empty(len(k), dtype=np.int64)
    used: dict[int, int] = {}
    for i, c in enumerate(class_id.tolist()):
        slot[i] = int(slot_runs[c][0]) + used.get(c, 0)
        used[c] = used.get(c, 0) + 1
    instance = np.arange(1, len(k) + 1, dtype=np.int64)
    support = infer_support(lo, hi, lifted)
    support_id = np.where(support >= 0, instance[np.maximum(support, 0)], -1)
    # an object with no depth takes part in no relation: its 3D box is unknown
    seen = lifted
    rel = compute_relations(instance[seen], lo[seen], hi[seen], support_id[seen])
    objects = (instance, class_id, slot, box2d)
    return objects, (rel.src, rel.dst, rel.type.astype(np.int64))


def match_boxes(
    boxes: np.ndarray, classes: np.ndarray, true_boxes: np.ndarray, true_classes: np.ndarray
) -> np.ndarray:
    """Per detection (best first), the index of the true box it matches, or -1: an unmatched
    true box of its class at IoU >= 0.5, the highest IoU taken (COCO's rule at AP50)."""
    from torchvision.ops import box_iou

    match = np.full(len(classes), -1, dtype=np.int64)
    if not len(classes) or not len(true_classes):
        return match
    iou = box_iou(
        torch.from_numpy(np.asarray(boxes, np.float64)),
        torch.from_numpy(np.asarray(true_boxes, np.float64)),
    ).numpy()
    iou[np.asarray(classes)[:, None] != np.asarray(true_classes)[None, :]] = 0
    taken = np.zeros(len(true_classes), dtype=bool)
    for i, row in enumerate(iou):
        row = np.where(taken, 0, row)
        j = int(row.argmax())
        if row[j] >= 0.5:
            taken[j] = True
            match[i] = j
    return match


def choose_threshold(
    found: dict[str, ViewDetections], truth: dict[str, tuple[np.ndarray, np.ndarray]]
) -> tuple[float, dict[float, float]]:
    """The score threshold of the best F1 on ``truth`` (per view: class ids and (n, 4)
    boxes), a detection matching an unmatched true box of its class at IoU >= 0.5, best
    score first; returns it and the F1 of every threshold tried."""
    curve = {}
    for t in THRESHOLDS:
        hits = predicted = actual = 0
        for obs_id, (classes, boxes) in truth.items():
            actual += len(classes)
            view = found.get(obs_id)
            if view is None:
                continue
            keep = _kept(view, t)
            predicted += int(keep.sum())
            hits += int(
                (match_boxes(view.box2d[keep], view.class_id[keep], boxes, classes) >= 0).sum()
            )
        f1 = 2 * hits / (predicted + actual) if predicted + actual else 0.0
        curve[t] = f1
    best = max(THRESHOLDS, key=lambda t: (curve[t], -t))
    return best, curve


def _truth(ds: Dataset, split: str) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    out = {}
    for shard in ds.observation_files(split):
        for row in read_table(
            shard, observations_schema(), columns=["obs_id", "objects"]
        ).to_pylist():
            objects = row["objects"] or []
            out[row["obs_id"]] = (
                np.array([o["class_id"] for o in objects], np.int64),
                np.array([o["box2d"] for o in objects], np.float64).reshape(-1, 4),
            )
    return out


def val_threshold(
    ds: Dataset, detector: TrainedDetector, found: dict[str, ViewDetections] | None = None
) -> float:
    """The threshold of the best F1 on the val views (:func:`choose_threshold`), its curve
    written beside the cache; ``found``: detections holding val's, else read from the cache."""
    found = found if found is not None else detections(ds, "val", detector)
    threshold, curve = choose_threshold(found, _truth(ds, "val"))
    atomic_write_text(
        detector.run / CACHE / ds.manifest_sha256[:16] / "threshold.json",
        json.dumps(
            {
                "threshold": threshold,
                "val_f1": {f"{t:g}": f for t, f in curve.items()},
                **_key(ds, detector),
            },
            indent=1,
        )
        + "\n",
    )
    return threshold


def detected_graphs(
    detector: TrainedDetector,
    data: DataSource,
    splits: Sequence[str],
    *,
    progress: Progress | None = None,
) -> DetectedGraphs:
    """The detected graphs of ``splits`` (val is always detected: the threshold is chosen
    there), with the chosen threshold and its val curve written beside the cache."""
    ds = open_dataset(data)
    missing = [s for s in ("val", *splits) if s not in ds.splits]
    if missing:
        raise DataError(
            f"{ds.root}: no split {missing[0]!r}; detected graphs need val and {', '.join(splits)}"
        )
    found: dict[str, ViewDetections] = {}
    for split in dict.fromkeys(("val", *splits)):
        found.update(detections(ds, split, detector, progress))
    threshold = val_threshold(ds, detector, found)
    slot_runs = np.array([(c.slot_start, c.slot_count) for c in ds.manifest.classes], np.int64)
    empty = ViewDetections.none()
    views = {}
    for split in dict.fromkeys(("val", *splits)):
        for shard in ds.observation_files(split):
            for obs_id in (
                read_table(shard, observations_schema(), columns=["obs_id"])
                .column("obs_id")
                .to_pylist()
            ):
                views[obs_id] = view_graph(found.get(obs_id, empty), threshold, slot_runs)
    return DetectedGraphs.of(views, detector.checkpoint_sha256, threshold)
