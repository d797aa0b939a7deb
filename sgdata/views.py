"""One annotated view as a plain record, and the pipeline that makes it: render -> annotate ->
slots -> relations, with the renderer and the layout's object table kept alive between views.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .annotate import ObjectTable, annotate
from .errors import RenderError
from .meshes import SceneGeometry
from .relations import RelationRules, compute_relations
from .render import CameraConfig, Renderer
from .scene import Room
from .slots import SlotTable

__all__ = ["ViewPose", "ViewRecord", "ViewAnnotator"]


@dataclass(frozen=True)
class ViewPose:
    """Where a view is taken: grid cell, heading index, and the (possibly noisy) world pose."""

    x: float
    y: float
    theta: float  # radians
    grid_i: int
    grid_j: int
    heading: int  # 0..3 for 0/90/180/270 degrees


@dataclass
class ViewRecord:
    """One annotated view, Arrow-friendly: scalars, strings, lists and numpy arrays only.

    Objects are columns of equal length k (sorted by instance id); relations are columns of
    equal length E between instance ids (sorted by (src, dst)); type codes are
    :class:`sgdata.relations.RelationType`. ``obj_box2d`` is ``[u1, v1, u2, v2]`` pixels
    (u2, v2 exclusive, see :mod:`sgdata.annotate`); ``obj_obb`` rows are ``[cx, cy, cz, sx,
    sy, sz, yaw]``; ``obj_support`` is -1 for none.
    """

    room_id: str
    layout: int
    seed: int  # the view's own seed (pose noise, light jitter): re-render from it
    x: float
    y: float
    theta: float
    grid_i: int
    grid_j: int
    heading: int
    image_width: int
    image_height: int
    hfov_deg: float
    eye_height: float
    pitch_deg: float
    rgb: np.ndarray  # (H, W, 3) uint8
    obj_instance: np.ndarray  # (k,) int64
    obj_class: list[str]
    obj_slot: np.ndarray  # (k,) int64
    obj_dynamics: list[str]
    obj_box2d: np.ndarray  # (k, 4) int32
    obj_visible_pixels: np.ndarray  # (k,) int64
    obj_box3d_min: np.ndarray  # (k, 3) float64 world AABB
    obj_box3d_max: np.ndarray  # (k, 3)
    obj_obb: np.ndarray  # (k, 7)
    obj_support: np.ndarray  # (k,) int64
    rel_src: np.ndarray  # (E,) int64
    rel_dst: np.ndarray  # (E,) int64
    rel_type: np.ndarray  # (E,) int8
    dropped_objects: int = 0  # visible objects beyond their class's slot run
    depth: np.ndarray | None = field(default=None, repr=False)  # (H, W) float32 if kept

    @property
    def num_objects(self) -> int:
        return len(self.obj_instance)


class ViewAnnotator:
    """Turns poses of one layout at a time into :class:`ViewRecord` s.

    Args:
        renderer: a live renderer (one per worker, reused for every room).
        slots: the class slot runs.
        min_visible_pixels: fewer visible pixels and an object is not in the view.
        rules: relation rules.
        keep_depth: keep the depth image in the records.
    """

    def __init__(
        self,
        renderer: Renderer,
        slots: SlotTable,
        *,
        min_visible_pixels: int = 20,
        rules: RelationRules | None = None,
        keep_depth: bool = False,
    ) -> None:
        self.renderer = renderer
        self.slots = slots
        self.min_visible_pixels = int(min_visible_pixels)
        self.rules = rules or RelationRules()
        self.keep_depth = keep_depth
        self._room: Room | None = None
        self._layout = -1
        self._table: ObjectTable | None = None

    @property
    def camera(self) -> CameraConfig:
        return self.renderer.camera

    def set_layout(self, room: Room, geometry: SceneGeometry, layout: int) -> None:
        """Load a layout: moves the renderer's nodes (rebuilds only for a new room)."""
        if self._room is not None and self._room.room_id == room.room_id:
            self.renderer.update_poses(geometry)
        else:
            self.renderer.load(geometry)
        self._room, self._layout = room, int(layout)
        self._table = ObjectTable.from_scene(geometry, room)

    def view(self, pose: ViewPose, *, seed: int = 0, jitter_lights: bool = False) -> ViewRecord:
        """Render and annotate one view of the current layout.

        ``seed`` is stored in the record; with ``jitter_lights`` it also drives the light
        jitter, so the record can be re-rendered exactly.
        """
        if self._table is None or self._room is None:
            raise RenderError("no layout loaded: call ViewAnnotator.set_layout first")
        table, cam = self._table, self.camera
        rng = np.random.default_rng(seed) if jitter_lights else None
        rendered = self.renderer.render(pose.x, pose.y, pose.theta, rng=rng)
        ann = annotate(rendered, table, min_visible_pixels=self.min_visible_pixels)
        rows = ann.rows
        classes = [table.class_name[r] for r in rows]
        assignment = self.slots.assign(list(zip(ann.instance.tolist(), classes, strict=True)))
        keep = assignment.slots >= 0
        if not keep.all():
            rows, classes = rows[keep], [c for c, k in zip(classes, keep, strict=True) if k]
        box2d = ann.box2d[keep] if not keep.all() else ann.box2d
        visible = ann.visible_pixels[keep] if not keep.all() else ann.visible_pixels
        lo, hi, sup = table.aabb_min[rows], table.aabb_max[rows], table.support[rows]
        inst = table.instance[rows]
        rel = compute_relations(inst, lo, hi, sup, rules=self.rules)
        return ViewRecord(
            room_id=self._room.room_id,
            layout=self._layout,
            seed=int(seed),
            x=float(pose.x),
            y=float(pose.y),
            theta=float(pose.theta),
            grid_i=int(pose.grid_i),
            grid_j=int(pose.grid_j),
            heading=int(pose.heading),
            image_width=cam.width,
            image_height=cam.height,
            hfov_deg=cam.hfov_deg,
            eye_height=cam.eye_height,
            pitch_deg=cam.pitch_deg,
            rgb=rendered.rgb,
            obj_instance=inst,
            obj_class=classes,
            obj_slot=assignment.slots[keep],
            obj_dynamics=[table.dynamics[r] for r in rows],
            obj_box2d=box2d,
            obj_visible_pixels=visible,
            obj_box3d_min=lo,
            obj_box3d_max=hi,
            obj_obb=table.obb[rows],
            obj_support=sup,
            rel_src=rel.src,
            rel_dst=rel.dst,
            rel_type=rel.type,
            dropped_objects=assignment.dropped,
            depth=rendered.depth if self.keep_depth else None,
        )
