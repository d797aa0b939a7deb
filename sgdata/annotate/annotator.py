"""The annotator: render -> visible objects and boxes -> slots -> relations, one view at a time.

It keeps the renderer and the layout's object table alive between views and returns
:class:`~sgdata.annotate.records.ViewRecord` s.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from sgdata.annotate.boxes import ObjectTable, annotate
from sgdata.annotate.records import MIN_VISIBLE_PIXELS, ViewPose, ViewRecord
from sgdata.annotate.relations import RelationRules, compute_relations, stored_precision
from sgdata.annotate.slots import SlotTable
from sgdata.errors import RenderError
from sgdata.render.camera import CameraConfig
from sgdata.render.renderer import Renderer
from sgdata.stage_clock import NO_CLOCK, Clock
from sgdata.usd.meshes import Lighting, SceneGeometry
from sgdata.usd.room_io import door_quad
from sgdata.world.scene import Room

__all__ = ["VIEW_STEPS", "ViewAnnotator"]

# The steps of a view a clock times (:mod:`sgdata.stage_clock`), in order.
VIEW_STEPS = ("render", "boxes", "slots", "relations")


class ViewAnnotator:
    """Turns poses of one layout at a time into :class:`ViewRecord` s.

    Args:
        renderer: a live renderer (one per worker, reused for every room).
        slots: the class slot runs.
        min_visible_pixels: fewer visible pixels and an object is not in the view.
        rules: relation rules.
        keep_depth: keep the depth image in the records (metres along the view axis).
        keep_instances: keep the instance mask in the records
            (:meth:`~sgdata.annotate.boxes.Annotation.instance_mask`).
        clock: times the steps of each view as :data:`VIEW_STEPS` (default: no clock); a
            profiled room task sets it for its views.
    """

    def __init__(
        self,
        renderer: Renderer,
        slots: SlotTable,
        *,
        min_visible_pixels: int = MIN_VISIBLE_PIXELS,
        rules: RelationRules | None = None,
        keep_depth: bool = False,
        keep_instances: bool = False,
        clock: Clock = NO_CLOCK,
    ) -> None:
        self.renderer = renderer
        self.clock = clock
        self.slots = slots
        self.min_visible_pixels = int(min_visible_pixels)
        self.rules = rules or RelationRules()
        self.keep_depth = keep_depth
        self.keep_instances = keep_instances
        self._room: Room | None = None
        self._layout = -1
        self._table: ObjectTable | None = None
        self._lighting = Lighting()
        self._textured = False

    @property
    def camera(self) -> CameraConfig:
        return self.renderer.camera

    def set_layout(self, room: Room, geometry: SceneGeometry, layout: int) -> None:
        """Load a layout: moves the renderer's nodes (rebuilds only for a new room); the id
        pass also draws the room's door opening (the structure mask's door)."""
        geometry = replace(geometry, door=door_quad(room))
        if self._room is not None and self._room.room_id == room.room_id:
            self.renderer.update_poses(geometry)
        else:
            self.renderer.load(geometry)
        self._room, self._layout = room, int(layout)
        self._table = ObjectTable.from_scene(geometry, room)
        self._lighting = geometry.lighting
        meshes = (*geometry.structure, *(o.mesh for o in geometry.objects))
        self._textured = self.renderer.textures and any(m.textured for m in meshes)

    def view(self, pose: ViewPose, *, seed: int = 0, jitter_lights: bool = False) -> ViewRecord:
        """Render and annotate one view of the current layout.

        ``seed`` is stored in the record; with ``jitter_lights`` it also drives the light
        jitter, so the record can be re-rendered exactly.
        """
        if self._table is None or self._room is None:
            raise RenderError("no layout loaded: call ViewAnnotator.set_layout first")
        table, cam = self._table, self.camera
        rng = np.random.default_rng(seed) if jitter_lights else None
        clock = self.clock
        with clock.stage("render"):
            rendered = self.renderer.render(
                pose.x, pose.y, pose.theta, rng=rng, depth=self.keep_depth
            )
        with clock.stage("boxes"):
            ann = annotate(rendered, table, min_visible_pixels=self.min_visible_pixels)
        rows = ann.rows
        classes = [table.class_name[r] for r in rows]
        with clock.stage("slots"):
            assignment = self.slots.assign(list(zip(ann.instance.tolist(), classes, strict=True)))
        keep = assignment.slots >= 0
        if not keep.all():
            rows, classes = rows[keep], [c for c, k in zip(classes, keep, strict=True) if k]
        box2d = ann.box2d[keep] if not keep.all() else ann.box2d
        visible = ann.visible_pixels[keep] if not keep.all() else ann.visible_pixels
        # Relations are decided on exactly the boxes the dataset stores (float32), so that
        # `sgdata validate` recomputes every pair with no allowance and agrees.
        with clock.stage("relations"):
            lo, hi = (stored_precision(b[rows]) for b in (table.aabb_min, table.aabb_max))
            sup = table.support[rows]
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
            textures=self._textured,
            light_intensity=self._lighting.intensity,
            light_temperature=self._lighting.temperature,
            depth=rendered.depth if self.keep_depth else None,
            instances=ann.instance_mask(keep) if self.keep_instances else None,
            structure=rendered.structure if self.keep_instances else None,
        )
