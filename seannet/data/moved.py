"""Which objects moved between two views or layouts, and the bins figures are reported by.

An object moved when its 3D box shifted by more than :data:`MOVE_TOLERANCE` between the two
layouts; for a same-pose pair an object seen in only one of the two views moved as well (the
camera did not). Reads only the dataset (3D boxes), no renderer.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from seannet.data.opening import DataSource, open_dataset

__all__ = [
    "BIN_NAMES",
    "MOVED_BINS",
    "MOVE_TOLERANCE",
    "box_moved",
    "moved_bin",
    "moved_instances",
    "moved_objects",
]

MOVED_BINS = ((0, 0), (1, 2), (3, 5), (6, None))  # inclusive ranges of moved objects in view
MOVE_TOLERANCE = 0.01  # metres: a box corner that shifted more than this moved


def _bin_name(lo: int, hi: int | None) -> str:
    return f"{lo}" if lo == hi else (f"{lo}-{hi}" if hi is not None else f"{lo}+")


BIN_NAMES = tuple(_bin_name(lo, hi) for lo, hi in MOVED_BINS)  # 0, 1-2, 3-5, 6+


def moved_bin(count: int) -> str:
    """The bin (of :data:`MOVED_BINS`) of a number of moved objects."""
    for (lo, hi), name in zip(MOVED_BINS, BIN_NAMES, strict=True):
        if count >= lo and (hi is None or count <= hi):
            return name
    raise ValueError(f"moved object count {count} < 0")


def box_moved(before: np.ndarray, after: np.ndarray) -> bool:
    """Whether one object's box (corners, any layout of numbers) moved between two views."""
    return bool(
        before.shape == after.shape
        and before.size
        and np.abs(before - after).max() > MOVE_TOLERANCE
    )


def moved_instances(
    before: dict[int, tuple[np.ndarray, np.ndarray]],
    after: dict[int, tuple[np.ndarray, np.ndarray]],
) -> set[int]:
    """Instances whose 3D box differs (by more than :data:`MOVE_TOLERANCE`) between layouts."""
    moved = set()
    for inst in set(before) | set(after):
        if inst not in before or inst not in after:
            moved.add(inst)
            continue
        if box_moved(np.concatenate(before[inst]), np.concatenate(after[inst])):
            moved.add(inst)
    return moved


def moved_objects(
    data: DataSource, split: str, triplets: Sequence[tuple[str, str, str]]
) -> np.ndarray:
    """(T,) number of moved objects in view between each triplet's anchor and positive
    (``data``: an opened dataset, or its root)."""
    table = open_dataset(data).observations(split, columns=["obs_id", "layout", "objects"])
    ids = table.column("obs_id").to_pylist()
    layouts = table.column("layout").to_pylist()
    boxes: dict[str, dict[int, np.ndarray]] = {}
    for obs, objects in zip(ids, table.column("objects").to_pylist(), strict=True):
        boxes[obs] = {
            o["instance"]: np.array([*(o["box3d_min"] or ()), *(o["box3d_max"] or ())])
            for o in objects
        }
    layout_of = dict(zip(ids, layouts, strict=True))
    pose_of = {o: o.split("/")[2:] for o in ids}
    counts = np.zeros(len(triplets), dtype=np.int64)
    for t, (anchor, positive, _) in enumerate(triplets):
        a, p = boxes[anchor], boxes[positive]
        if layout_of[anchor] == layout_of[positive]:
            continue  # one layout: nothing moved between the two views
        both = a.keys() & p.keys()
        moved = sum(1 for k in both if box_moved(a[k], p[k]))
        if pose_of[anchor] == pose_of[positive]:
            moved += len(a.keys() ^ p.keys())
        counts[t] = moved
    return counts
