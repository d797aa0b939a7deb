"""Live views of a dataset's rooms: any grid pose of any layout rendered as the dataset would.

A dataset holds only the views its triplets referenced; maps, the navigator's training pairs
and the navigation test need the others. :class:`LiveRooms` renders them from the room's scene
files (``<dataset>/scenes/<room>/layout_<k>.usda``) with the dataset's own camera, pose grid,
annotation settings and class vocabulary (all read from ``dataset.json``), each view with the
seed ``sgdata generate`` would give it (:func:`sgdata.seeds.view_seed`), and its image passed
through the dataset's image format, so a view the dataset holds is rendered again as stored.

A ``regraph`` hook replaces each view's scene graph with another source's: a detector's
(:mod:`seannet.detection.live_graphs`), which reads the view's image and depth.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import torch

# Before any EGL context: Mesa's llvmpipe and triton (loaded by torch._dynamo, which
# torchvision's models import) each bring an LLVM, and loading triton after Mesa segfaults.
# This module is the only one of seannet that renders, so the order is kept here.
import torch._dynamo  # noqa: F401  isort: skip
from seannet.data.datasets import ImageTransform, ViewTensors
from seannet.data.opening import DataSource, open_dataset
from seannet.data.view_inputs import graph_from_columns
from seannet.errors import DataError
from sgdata.dataset import Dataset, decode_image
from sgdata.dataset.paths import scene_dir
from sgdata.dataset.rows import encode_image
from sgdata.errors import SgdataError
from sgdata.scene_files import layout_file
from sgdata.seeds import rng_for, view_seed

__all__ = [
    "LiveRooms",
    "Regraph",
    "RenderSettings",
    "layout_boxes",
    "view_tensors",
]


# (annotated view with depth, the camera) -> the view with another scene graph
Regraph = Callable[[Any, Any], Any]


@dataclass(frozen=True)
class RenderSettings:
    """How a dataset rendered its views, read back from its manifest (``config``)."""

    camera: dict[str, Any]  # CameraConfig fields
    cell: float  # pose grid cell d (m)
    robot_radius: float  # m
    noise: bool  # the authors' pose noise, drawn from each view's seed
    min_visible_pixels: int
    containment_tolerance: float  # relation rule
    image_format: str  # png | jpeg
    jpeg_quality: int

    @classmethod
    def of(cls, ds: Dataset) -> RenderSettings:
        """The settings of dataset ``ds``.

        Raises:
            DataError: the manifest's config lacks a section (a dataset of real photos).
        """
        config = ds.manifest.config
        try:
            poses, images = config["poses"], config["images"]
            return cls(
                camera=dict(config["camera"]),
                cell=float(poses["cell"]),
                robot_radius=float(poses["robot_radius"]),
                noise=bool(poses.get("noise", False)),
                min_visible_pixels=int(config["annotation"]["min_visible_pixels"]),
                containment_tolerance=float(
                    ds.manifest.relation_rules.get("containment_tolerance", 0.001)
                ),
                image_format=str(images["format"]),
                jpeg_quality=int(images.get("jpeg_quality", 92)),
            )
        except (KeyError, TypeError) as exc:
            raise DataError(
                f"{ds.root}/dataset.json: config lacks {exc}; live views need a generated dataset"
            ) from None


class LiveRooms:
    """A live renderer over a dataset's rooms: load a (room, layout), render grid poses.

    One renderer serves every room (rebuilt only when the room changes). Use as a context
    manager, or call :meth:`close`.

    Args:
        data: the dataset (made by ``sgdata generate``): opened already, or its root.
        regraph: gives each annotated view (its depth kept) another scene graph; None: the
            generator's.

    Raises:
        DataError: the dataset is missing or is not a generated one.
        RenderError: EGL cannot start.
    """

    def __init__(self, data: DataSource, *, regraph: Regraph | None = None) -> None:
        from sgdata.annotate.annotator import ViewAnnotator
        from sgdata.annotate.relations import RelationRules
        from sgdata.annotate.slots import SlotTable
        from sgdata.render.camera import CameraConfig
        from sgdata.render.renderer import Renderer
        from sgdata.world.poses import PosesConfig

        self.dataset = open_dataset(data)
        self.data = self.dataset.root
        self.settings = RenderSettings.of(self.dataset)
        m = self.dataset.manifest
        self.num_slots = int(m.num_slots)
        self.class_ids = {c.name: c.id for c in m.classes}
        slots = SlotTable({c.name: (c.slot_start, c.slot_count) for c in m.classes}, m.num_slots)
        self.poses = PosesConfig(
            cell=self.settings.cell, robot_radius=self.settings.robot_radius, noise=False
        )
        self.renderer = Renderer(CameraConfig(**self.settings.camera))
        self.annotator = ViewAnnotator(
            self.renderer,
            slots,
            min_visible_pixels=self.settings.min_visible_pixels,
            rules=RelationRules(containment_tolerance=self.settings.containment_tolerance),
            keep_depth=regraph is not None,
        )
        self.regraph = regraph
        self.room_id: str | None = None
        self.layout = -1
        self.grid: Any = None  # sgdata.world.poses.PoseGrid of the loaded layout
        self._room: Any = None

    # -- lifecycle ------------------------------------------------------------------------

    def close(self) -> None:
        """Release the renderer."""
        self.renderer.close()

    def __enter__(self) -> LiveRooms:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # -- layouts --------------------------------------------------------------------------

    def layouts(self, room_id: str) -> list[int]:
        """The layout indices of a room, ascending."""
        from sgdata.usd.scene_dirs import layout_indices

        return layout_indices(scene_dir(self.data, room_id))

    def load(self, room_id: str, layout: int) -> None:
        """Make ``layout`` of ``room_id`` the world the renderer shows.

        Raises:
            DataError: the room or layout has no scene file in the dataset.
        """
        if (room_id, layout) == (self.room_id, self.layout):
            return
        room, geometry = _read_layout(self.data, room_id, layout)
        self.annotator.set_layout(room, geometry, layout)
        self.room_id, self.layout, self._room = room_id, int(layout), room
        self.grid = self.poses.grid(room)

    def reachable(self, i: int, j: int) -> bool:
        """Whether cell (i, j) is on the loaded layout's reachable grid."""
        nx, ny = self.grid.shape
        return 0 <= i < nx and 0 <= j < ny and bool(self.grid.reachable[i, j])

    # -- views ----------------------------------------------------------------------------

    def _pose(self, i: int, j: int, heading: int) -> tuple[int, float, float, float]:
        if self._room is None:
            raise DataError("LiveRooms: no layout loaded; call load(room_id, layout) first")
        seed = view_seed(self._room.seed, self.layout, i, j, heading)
        noise = rng_for(seed) if self.settings.noise else None
        return (seed, *self.grid.pose_world(i, j, heading, rng=noise))

    def _stored(self, rgb: np.ndarray) -> np.ndarray:
        """The image as the dataset stores it (a JPEG dataset loses what JPEG loses)."""
        if self.settings.image_format == "png":
            return rgb
        data = encode_image(rgb, "jpeg", jpeg_quality=self.settings.jpeg_quality)
        return decode_image(data)

    def view(self, i: int, j: int, heading: int) -> Any:
        """The annotated view (:class:`sgdata.annotate.records.ViewRecord`) at a grid pose."""
        from sgdata.annotate.records import ViewPose

        seed, x, y, theta = self._pose(i, j, heading)
        record = self.annotator.view(ViewPose(x, y, theta, i, j, heading), seed=seed)
        record.rgb = self._stored(record.rgb)
        if self.regraph is not None:  # after storing: a detector sees the image as stored
            record = self.regraph(record, self.renderer.camera)
        return record

    def image(self, i: int, j: int, heading: int) -> np.ndarray:
        """The RGB image only, (H, W, 3) uint8 (no id pass: cheaper than :meth:`view`)."""
        _, x, y, theta = self._pose(i, j, heading)
        rgb, _ = self.renderer.render_rgb(x, y, theta, depth=False)
        return self._stored(rgb)

    def depth(self, i: int, j: int, heading: int) -> np.ndarray:
        """The view's forward depth (H, W) float32 in metres, 0 where nothing is drawn."""
        _, x, y, theta = self._pose(i, j, heading)
        _, metres = self.renderer.render_rgb(x, y, theta, depth=True)
        return metres

    def covisibility(
        self,
        a: tuple[np.ndarray, tuple[float, float, float]],
        b: tuple[np.ndarray, tuple[float, float, float]],
    ) -> float:
        """Covisibility of two views given as (depth, (x, y, theta)), with the dataset's
        camera (:func:`sgdata.render.covisibility.covisibility`)."""
        from sgdata.render.covisibility import covisibility

        return covisibility(self.renderer.camera, a[0], a[1], b[0], b[1])

    def tensors(self, record: Any, transform: ImageTransform) -> ViewTensors:
        """A rendered view as model input (see :func:`view_tensors`)."""
        return view_tensors(record, transform, self.class_ids, self.num_slots)


def _read_layout(data: Path, room_id: str, layout: int) -> tuple[Any, Any]:
    """(Room, SceneGeometry) of a layout's scene file."""
    from sgdata.usd.room_io import read_scene

    path = layout_file(scene_dir(data, room_id), layout)
    if not path.is_file():
        raise DataError(f"{path}: no such layout of room {room_id!r} in {data}")
    try:
        return read_scene(path)
    except SgdataError as exc:
        raise DataError(f"{path}: {exc}") from None


def _boxes(room: Any, geometry: Any) -> dict[int, tuple[np.ndarray, np.ndarray]]:
    from sgdata.annotate.boxes import ObjectTable

    table = ObjectTable.from_scene(geometry, room)
    return {int(k): (table.aabb_min[n], table.aabb_max[n]) for n, k in enumerate(table.instance)}


def layout_boxes(data: Path, room_id: str, layout: int) -> dict[int, tuple[np.ndarray, np.ndarray]]:
    """Instance -> (world box min, max) of every object of a layout (no renderer needed).

    Raises:
        DataError: the room or layout has no scene file in the dataset.
    """
    return _boxes(*_read_layout(Path(data), room_id, layout))


def view_tensors(
    record: Any, transform: ImageTransform, class_ids: dict[str, int], num_slots: int
) -> ViewTensors:
    """A :class:`~sgdata.annotate.records.ViewRecord` as model input, exactly as
    :class:`seannet.data.datasets.ObservationDataset` builds one from the stored row.

    Raises:
        DataError: a class the dataset's vocabulary lacks.
    """
    try:
        classes = np.asarray([class_ids[c] for c in record.obj_class], dtype=np.int64)
    except KeyError as exc:
        raise DataError(f"rendered view: class {exc} is not in the dataset's vocabulary") from None
    slots, class_t, boxes, edge_index, edge_weight = graph_from_columns(
        np.asarray(record.obj_instance),
        classes,
        np.asarray(record.obj_slot),
        # float: the generator's integer boxes as stored, a detector's as found
        np.asarray(record.obj_box2d, dtype=np.float32).reshape(-1, 4),
        np.asarray(record.rel_src),
        np.asarray(record.rel_dst),
        np.asarray(record.rel_type),
        num_slots,
    )
    pixels, boxes = transform.resize(np.asarray(record.rgb), boxes.numpy())
    return ViewTensors(
        torch.tensor(pixels).permute(2, 0, 1),  # a copy: the record keeps its own pixels
        boxes,
        class_t,
        slots,
        edge_index,
        edge_weight.to(torch.float32),
        num_slots,
        mean=tuple(transform.mean),
        std=tuple(transform.std),
    )
