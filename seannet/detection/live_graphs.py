"""Scene graphs of live views from a trained detector: navigation with ``--graphs detected``.

The navigation test renders its views (:class:`seannet.data.live_views.LiveRooms`); with a
detector, each view's graph is what the detector finds on its image, lifted with its rendered
depth and the camera, its relations by the generator's rules, the score threshold the one
chosen on the dataset's val views for ``seannet eval --graphs detected``: the same graph a
stored view of that pose gets (:mod:`seannet.detection.graphs`).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import torch

from seannet.data.opening import DataSource, open_dataset
from seannet.detection.graphs import detected_graphs, lifted_detections, view_graph
from seannet.detection.train import TrainedDetector, load_detector

__all__ = ["LiveGraphs", "live_graphs"]


@dataclass(frozen=True)
class LiveGraphs:
    """Which detector gives the live views' graphs, and its threshold: what a navigation
    task keys on and a worker opens (:meth:`regraph`)."""

    run: str  # the detector's run directory
    detector: str  # its checkpoint's sha256
    threshold: float  # detections kept: score >= threshold

    @property
    def label(self) -> str:
        """As :meth:`seannet.detection.graphs.DetectedGraphs.label` names the stored views'."""
        return f"detected-{self.detector[:8]}-t{self.threshold:g}"

    def regraph(self, data: DataSource) -> _Regraph:
        """The hook :class:`~seannet.data.live_views.LiveRooms` calls on each view."""
        return _Regraph(load_detector(Path(self.run), data), self.threshold, open_dataset(data))


def live_graphs(run: Path, data: DataSource) -> LiveGraphs:
    """The detector of ``run`` with the threshold chosen on ``data``'s val views (detected
    once and cached under the run, as ``seannet eval --graphs detected`` does).

    Raises:
        CheckpointError: no detector in ``run``, or one of another vocabulary.
        DataError: the dataset has no val split or no depth.
    """
    detector = load_detector(run, data)
    chosen = detected_graphs(detector, data, ())
    return LiveGraphs(str(run), detector.checkpoint_sha256, chosen.threshold)


class _Regraph:
    """A view's generator graph replaced by the detector's; its 3D boxes are unknown (NaN)."""

    def __init__(self, detector: TrainedDetector, threshold: float, ds: Any) -> None:
        self.detector, self.threshold = detector, threshold
        classes = ds.manifest.classes
        self.names = [c.name for c in classes]
        self.dynamics = [c.dynamics for c in classes]
        self.slot_runs = np.array([(c.slot_start, c.slot_count) for c in classes], np.int64)

    @torch.no_grad()
    def __call__(self, record: Any, camera: Any) -> Any:
        image = torch.from_numpy(np.array(record.rgb, np.uint8)).permute(2, 0, 1).float() / 255
        found = self.detector.model([image])[0]
        order = torch.argsort(found["scores"], descending=True, stable=True)
        found = {k: v[order] for k, v in found.items()}  # best first: the best takes the slot
        views = lifted_detections(
            found,
            record.depth,
            np.asarray(camera.intrinsics),
            camera.camera_to_world(record.x, record.y, record.theta),
        )
        (instance, class_id, slot, box2d), (src, dst, kind) = view_graph(
            views, self.threshold, self.slot_runs
        )
        k = len(instance)
        area = (box2d[:, 2] - box2d[:, 0]) * (box2d[:, 3] - box2d[:, 1])
        return dataclasses.replace(
            record,
            obj_instance=instance,
            obj_class=[self.names[c] for c in class_id.tolist()],
            obj_slot=slot,
            obj_dynamics=[self.dynamics[c] for c in class_id.tolist()],
            obj_box2d=box2d,
            obj_visible_pixels=np.round(area).astype(np.int64),
            obj_box3d_min=np.full((k, 3), np.nan),
            obj_box3d_max=np.full((k, 3), np.nan),
            obj_obb=np.full((k, 7), np.nan),
            obj_support=np.full(k, -1, np.int64),
            rel_src=src,
            rel_dst=dst,
            rel_type=kind.astype(np.int8),
            dropped_objects=0,
            instances=None,
        )
