"""How far a detector's scene graphs are from the generator's on a split, in the three places
a graph can go wrong: objects missed or invented, boxes lifted to 3D with depth, and the
relations inferred from those boxes (``seannet detector graphs``; docs/detector.md).

Each view's graph is the one a localizer gets (:func:`seannet.detection.graphs.view_graph` at
the threshold chosen on val). Its objects match the true ones as COCO's AP50 does
(:func:`~seannet.detection.graphs.match_boxes`); on the matched objects, the lifted 3D boxes
are compared with the true ones and every true relation is looked up between the matched
pair: a relation is *kept* when the detected graph holds the same type from the same object
to the same object.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from seannet.data.opening import DataSource, open_dataset
from seannet.detection.graphs import (
    ViewDetections,
    detections,
    match_boxes,
    placed_detections,
    val_threshold,
    view_graph,
)
from seannet.detection.train import TrainedDetector
from sgdata.annotate.relations import RelationType
from sgdata.dataset import observations_schema, read_table

__all__ = ["SIZES", "ViewTally", "graph_fidelity", "summary", "tally_view"]

# COCO's object areas (px²): small below 32², medium below 96², large above
SIZES = (("small", 32.0**2), ("medium", 96.0**2), ("large", float("inf")))
NEAR_M = 0.25  # a lifted box "near" the truth: centres within this (metres)


@dataclass
class ViewTally:
    """Counts over views, added view by view (:func:`tally_view`)."""

    true_objects: Counter = field(default_factory=Counter)  # by "size:<bin>", "dynamics:<d>"
    found_objects: Counter = field(default_factory=Counter)  # matched, same keys
    graph_objects: int = 0  # objects in the detected graphs
    graph_matched: int = 0
    centre_error_m: list[float] = field(default_factory=list)  # matched, lifted, true 3D box
    size_error_m: list[float] = field(default_factory=list)  # mean |extent difference|
    unlifted: int = 0  # matched objects without depth under their box: no 3D box, no relation
    true_relations: Counter = field(default_factory=Counter)  # by type name
    with_ends: Counter = field(default_factory=Counter)  # both objects found
    kept: Counter = field(default_factory=Counter)  # and the same relation between them


def _size(box2d: list[int]) -> str:
    area = max(0, box2d[2] - box2d[0]) * max(0, box2d[3] - box2d[1])
    return next(name for name, below in SIZES if area < below)


def tally_view(
    tally: ViewTally,
    found: ViewDetections,
    threshold: float,
    slot_runs: np.ndarray,
    objects: list[dict[str, Any]],
    relations: list[dict[str, Any]],
) -> None:
    """Add one view: its detections (best first) against its true objects and relations (the
    dataset's ``objects`` and ``relations`` rows)."""
    placed = placed_detections(found, threshold, slot_runs)
    (instance, class_id, _, box2d), (src, dst, kind) = view_graph(found, threshold, slot_runs)
    true_boxes = np.array([o["box2d"] for o in objects], np.float64).reshape(-1, 4)
    true_classes = np.array([o["class_id"] for o in objects], np.int64)
    match = match_boxes(box2d, class_id, true_boxes, true_classes)
    tally.graph_objects += len(instance)
    tally.graph_matched += int((match >= 0).sum())
    detected_of = {}  # true instance -> detected instance
    for k, j in enumerate(match.tolist()):
        if j < 0:
            continue
        truth = objects[j]
        detected_of[truth["instance"]] = int(instance[k])
        if not found.lifted[placed[k]]:
            tally.unlifted += 1
        elif truth["box3d_min"] is not None and truth["box3d_max"] is not None:
            lo, hi = found.box_min[placed[k]], found.box_max[placed[k]]
            t_lo, t_hi = np.asarray(truth["box3d_min"]), np.asarray(truth["box3d_max"])
            tally.centre_error_m.append(float(np.linalg.norm((lo + hi - t_lo - t_hi) / 2)))
            tally.size_error_m.append(float(np.abs((hi - lo) - (t_hi - t_lo)).mean()))
    for j, truth in enumerate(objects):
        keys = (f"size:{_size(truth['box2d'])}", f"dynamics:{truth['dynamics']}")
        tally.true_objects.update(keys)
        if j in set(match.tolist()):
            tally.found_objects.update(keys)
    detected = {(int(a), int(b)): int(t) for a, b, t in zip(src, dst, kind, strict=True)}
    for rel in relations:
        name = RelationType(rel["type"]).name.lower()
        tally.true_relations[name] += 1
        a, b = detected_of.get(rel["src"]), detected_of.get(rel["dst"])
        if a is None or b is None:
            continue
        tally.with_ends[name] += 1
        if detected.get((a, b)) == rel["type"]:
            tally.kept[name] += 1


def _share(part: float, whole: float) -> float | None:
    return part / whole if whole else None


def _spread(values: list[float]) -> dict[str, float | None]:
    if not values:
        return {"median": None, "p90": None, f"within_{NEAR_M:g}": None}
    array = np.asarray(values)
    return {
        "median": float(np.median(array)),
        "p90": float(np.percentile(array, 90)),
        f"within_{NEAR_M:g}": float((array <= NEAR_M).mean()),
    }


def summary(tally: ViewTally) -> dict[str, Any]:
    """The tally as shares: object recall (by size and by dynamics) and precision, the
    lifting errors, and relations kept (all, and by type)."""
    groups: dict[str, dict[str, Any]] = {}
    for key, n in sorted(tally.true_objects.items()):
        group, name = key.split(":")
        found = tally.found_objects[key]
        groups.setdefault(group, {})[name] = {"true": n, "recall": _share(found, n)}
    true_total = sum(v for k, v in tally.true_objects.items() if k.startswith("size:"))
    found_total = sum(v for k, v in tally.found_objects.items() if k.startswith("size:"))
    relation_types = sorted(tally.true_relations)
    return {
        "objects": {
            "true": true_total,
            "recall": _share(found_total, true_total),
            "in_graphs": tally.graph_objects,
            "precision": _share(tally.graph_matched, tally.graph_objects),
            "by_size": groups.get("size", {}),
            "by_dynamics": groups.get("dynamics", {}),
        },
        "lifting": {
            "matched": tally.graph_matched,
            "unlifted": tally.unlifted,
            "centre_error_m": _spread(tally.centre_error_m),
            "size_error_m": _spread(tally.size_error_m),
        },
        "relations": {
            "true": sum(tally.true_relations.values()),
            "with_both_ends": _share(sum(tally.with_ends.values()),
                                     sum(tally.true_relations.values())),
            "kept_of_those": _share(sum(tally.kept.values()), sum(tally.with_ends.values())),
            "by_type": {
                name: {
                    "true": tally.true_relations[name],
                    "with_both_ends": _share(tally.with_ends[name], tally.true_relations[name]),
                    "kept_of_those": _share(tally.kept[name], tally.with_ends[name]),
                }
                for name in relation_types
            },
        },
    }  # fmt: skip


def graph_fidelity(detector: TrainedDetector, data: DataSource, split: str) -> dict[str, Any]:
    """The detected graphs of ``split`` against the generator's (:func:`summary`), at the
    threshold chosen on val (:func:`~seannet.detection.graphs.val_threshold`)."""
    ds = open_dataset(data)
    threshold = val_threshold(ds, detector)
    found = detections(ds, split, detector)
    slot_runs = np.array([(c.slot_start, c.slot_count) for c in ds.manifest.classes], np.int64)
    tally = ViewTally()
    views = 0
    for shard in ds.observation_files(split):
        rows = read_table(
            shard, observations_schema(), columns=["obs_id", "objects", "relations"]
        ).to_pylist()
        for row in rows:
            view = found.get(row["obs_id"], ViewDetections.none())
            tally_view(tally, view, threshold, slot_runs, row["objects"] or [],
                       row["relations"] or [])  # fmt: skip
            views += 1
    return {"split": split, "views": views, "threshold": threshold, **summary(tally)}
