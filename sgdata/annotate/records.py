"""The annotated-view contract: :class:`ViewPose` and :class:`ViewRecord`, plain data only.

Written by the annotator, read by the dataset writer and the pictures; importing it loads no
renderer.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["MIN_VISIBLE_PIXELS", "ViewPose", "ViewRecord"]

# A view record lists the objects with at least this many visible pixels (the default of
# [annotation] min_visible_pixels): fewer, and the object is not in the view.
MIN_VISIBLE_PIXELS = 20


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
    (u2, v2 exclusive, see :mod:`sgdata.annotate.boxes`); ``obj_obb`` rows are ``[cx, cy, cz, sx,
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
    textures: bool | None = None  # whether surfaces were drawn textured (None: unknown)
    light_intensity: float | None = None  # scale of the default lights (the stage's light)
    light_temperature: float | None = None  # Kelvin; None: the default white light
    depth: np.ndarray | None = field(default=None, repr=False)  # (H, W) float32 if kept
    # (H, W) uint16 if kept: 0 background, k where the k-th object of the obj_* columns is seen
    instances: np.ndarray | None = field(default=None, repr=False)
    # (H, W) uint8 if kept, with instances: the structure part seen (dataset.channels)
    structure: np.ndarray | None = field(default=None, repr=False)

    @property
    def num_objects(self) -> int:
        return len(self.obj_instance)
