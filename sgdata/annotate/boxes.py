"""Annotation of a rendered view: visible objects, their 2D pixel boxes and their 3D boxes.

Pixel boxes are ``[u1, v1, u2, v2]`` in continuous pixel coordinates (u = column, v = row,
origin at the top-left corner of the image): pixel (u, v) covers [u, u + 1) x [v, v + 1), so
a box spans the visible pixels' area, ``u1 = min column``, ``u2 = max column + 1`` (u2, v2
exclusive as indices). This is the convention RoIAlign expects (``aligned=True``) and what
projecting geometry gives (:meth:`sgdata.render.CameraConfig.project`).

Per layout, :class:`ObjectTable` gathers every object's 3D data once; per view,
:func:`annotate` only does vectorised pixel work (bincount and one scatter per axis).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cache

import numpy as np

from sgdata.annotate.records import MIN_VISIBLE_PIXELS
from sgdata.errors import RenderError
from sgdata.render.renderer import RenderedView
from sgdata.usd.meshes import SceneGeometry
from sgdata.world.scene import Room

__all__ = ["ObjectTable", "Annotation", "annotate"]


@dataclass(frozen=True)
class ObjectTable:
    """Per-object data of one layout, rows in ``SceneGeometry.objects`` order.

    ``obb`` rows are ``[cx, cy, cz, sx, sy, sz, yaw]``: the centre of the object's oriented
    box in world space, its size (width, depth, height) and yaw (rad) from the placement.
    """

    instance: np.ndarray  # (n,) int64
    class_name: tuple[str, ...]
    dynamics: tuple[str, ...]  # static | low | high ("" when no Room was given)
    support: np.ndarray  # (n,) int64 instance it rests on, -1 for none
    aabb_min: np.ndarray  # (n, 3) world axis-aligned box of the transformed mesh vertices
    aabb_max: np.ndarray  # (n, 3)
    obb: np.ndarray  # (n, 7)

    def __len__(self) -> int:
        return len(self.instance)

    @classmethod
    def from_scene(cls, geometry: SceneGeometry, room: Room | None = None) -> ObjectTable:
        """Build the table; ``room`` supplies supports, dynamics and placements.

        Without a room (a stage authored elsewhere), supports are -1 and the oriented box is
        the mesh's local bounds under its transform.

        Raises:
            RenderError: the room lacks an instance the geometry has.
        """
        n = len(geometry.objects)
        inst = np.array([o.instance for o in geometry.objects], dtype=np.int64)
        lo, hi = np.zeros((n, 3)), np.zeros((n, 3))
        obb = np.zeros((n, 7))
        support = np.full(n, -1, dtype=np.int64)
        dynamics = [""] * n
        by_inst = room.by_instance() if room is not None else {}
        for k, og in enumerate(geometry.objects):
            m = np.asarray(og.matrix, dtype=np.float64)
            v = np.asarray(og.mesh.vertices, dtype=np.float64)
            w = v @ m[:3, :3].T + m[:3, 3]
            lo[k], hi[k] = w.min(axis=0), w.max(axis=0)
            if room is None:
                llo, lhi = v.min(axis=0), v.max(axis=0)
                centre = m[:3, :3] @ ((llo + lhi) / 2) + m[:3, 3]
                yaw = math.atan2(m[1, 0], m[0, 0])
                obb[k] = (*centre, *(lhi - llo), yaw)
                continue
            obj = by_inst.get(og.instance)
            if obj is None:
                raise RenderError(
                    f"instance {og.instance} ({og.class_name}) is in the geometry but not in "
                    f"room {room.room_id}: pass the Room of the same layout"
                )
            p = obj.placement
            # the local origin is the bottom centre and the yaw turns about +Z through it
            obb[k] = (p.x, p.y, p.z + obj.size[2] / 2, *obj.size, p.yaw)
            support[k] = -1 if obj.support is None else obj.support
            dynamics[k] = str(obj.dynamics)
        return cls(
            instance=inst,
            class_name=tuple(o.class_name for o in geometry.objects),
            dynamics=tuple(dynamics),
            support=support,
            aabb_min=lo,
            aabb_max=hi,
            obb=obb,
        )


@dataclass(frozen=True)
class Annotation:
    """The visible objects of one view, sorted by instance id ascending."""

    rows: np.ndarray  # (k,) int64 rows into the ObjectTable
    instance: np.ndarray  # (k,) int64
    box2d: np.ndarray  # (k, 4) int32 [u1, v1, u2, v2], u2/v2 exclusive
    visible_pixels: np.ndarray  # (k,) int64
    # (H, W) int64 per pixel: 0 background or structure, else the ObjectTable row + 1 of the
    # object seen there (visible or not): the mask channels are drawn from it
    label: np.ndarray | None = None

    def __len__(self) -> int:
        return len(self.rows)

    def instance_mask(self, keep: np.ndarray | None = None) -> np.ndarray:
        """(H, W) uint16 mask: 0 background, ``k`` where the k-th listed object is seen
        (1-based, in ``rows`` order, after ``keep`` selects the rows that are kept); pixels
        of objects not listed are 0.

        Raises:
            RenderError: the annotation holds no label image, or more than 65,535 objects.
        """
        if self.label is None:
            raise RenderError("this annotation kept no label image: annotate() sets it")
        rows = self.rows if keep is None else self.rows[keep]
        if len(rows) > np.iinfo(np.uint16).max:
            raise RenderError(f"{len(rows)} visible objects: a uint16 mask holds at most 65535")
        lut = np.zeros(int(self.label.max(initial=0)) + 1, dtype=np.uint16)
        lut[rows + 1] = np.arange(1, len(rows) + 1, dtype=np.uint16)
        return lut[self.label]


def annotate(
    view: RenderedView, table: ObjectTable, *, min_visible_pixels: int = MIN_VISIBLE_PIXELS
) -> Annotation:
    """Visible objects (at least ``min_visible_pixels`` pixels) with their tight pixel boxes.

    Raises:
        RenderError: the instance image holds an id the table does not know.
    """
    ids = view.instance
    h, w = ids.shape
    n = len(table)
    # dense label per pixel: 0 = background, row + 1 otherwise
    inst = table.instance
    order = np.argsort(inst, kind="stable")
    sorted_inst = inst[order]
    flat = ids.reshape(-1).astype(np.int64)
    fg = flat >= 0
    pos = np.searchsorted(sorted_inst, flat[fg])
    pos_c = np.minimum(pos, max(n - 1, 0))
    if n == 0 or not np.array_equal(sorted_inst[pos_c], flat[fg]):
        if fg.any():
            raise RenderError("instance image holds ids that are not objects of the loaded scene")
    label = np.zeros(h * w, dtype=np.int64)
    if n:
        label[fg] = order[pos_c] + 1
    counts = np.bincount(label, minlength=n + 1)
    # one scatter per axis: which columns / rows each label touches
    cols = np.zeros((n + 1, w), dtype=bool)
    rows = np.zeros((n + 1, h), dtype=bool)
    col_of, row_of = _pixel_coords(h, w)
    cols[label, col_of] = True
    rows[label, row_of] = True
    u1 = cols.argmax(axis=1)
    u2 = w - cols[:, ::-1].argmax(axis=1)
    v1 = rows.argmax(axis=1)
    v2 = h - rows[:, ::-1].argmax(axis=1)
    visible = np.nonzero(counts[1:] >= max(1, min_visible_pixels))[0]
    visible = visible[np.argsort(inst[visible], kind="stable")]
    lab = visible + 1
    box = np.stack([u1[lab], v1[lab], u2[lab], v2[lab]], axis=1).astype(np.int32)
    return Annotation(
        rows=visible.astype(np.int64),
        instance=inst[visible],
        box2d=box.reshape(-1, 4),
        visible_pixels=counts[lab].astype(np.int64),
        label=label.reshape(h, w),
    )


@cache
def _pixel_coords(h: int, w: int) -> tuple[np.ndarray, np.ndarray]:
    """Column and row index of every pixel in row-major order (cached per image size)."""
    col = np.tile(np.arange(w), h)
    row = np.repeat(np.arange(h), w)
    col.flags.writeable = False
    row.flags.writeable = False
    return col, row
