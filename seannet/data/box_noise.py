"""Boxes as a labeler or a detector gives them: jittered corners, dropped objects, false ones.

Evaluation under :class:`BoxNoise` asks how much of a model's accuracy survives boxes that
are not the generator's exact ones (DESIGN §12). Each view's noise is drawn from its own
seeded stream (:func:`seannet.seeds.box_noise_seed` of the noise seed and the view's id), so a
view is perturbed the same way whatever batch or order it is read in, and every model
evaluated under one noise sees the same perturbed boxes.

- **jitter** ``S``: each box corner moves by a normal draw of standard deviation ``S`` times
  the box's width (u) or height (v); the box is clipped to the image and kept >= 1 px wide.
- **drop** ``P``: each object is left out with probability ``P``, with its relations.
- **spurious** ``Q``: ``Poisson(Q * K)`` false objects for a view of ``K`` objects, each of a
  uniformly drawn class in that class's first free slot (none when its run is full), with a
  box of 5-40 % of the image side at a uniform place, and no relation.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from seannet.errors import DataError
from seannet.seeds import box_noise_seed
from sgdata.seeds import rng_for

__all__ = ["BoxNoise", "ObjectColumns"]

# (instance, class_id, slot, box2d (K, 4)) and (src, dst, type) of one view
ObjectColumns = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]
RelationColumns = tuple[np.ndarray, np.ndarray, np.ndarray]


@dataclass(frozen=True)
class BoxNoise:
    """How far a view's boxes are from the generator's (all zero: exact boxes)."""

    jitter: float = 0.0  # S: corner noise std, in units of the box's side
    drop: float = 0.0  # P: probability an object is missed
    spurious: float = 0.0  # Q: false objects per true object, on average
    seed: int = 0  # the noise stream's seed

    def __post_init__(self) -> None:
        if not 0.0 <= self.jitter <= 1.0:
            raise DataError(f"box noise jitter {self.jitter}: expected 0 <= S <= 1 (box sides)")
        if not 0.0 <= self.drop < 1.0:
            raise DataError(f"box noise drop {self.drop}: expected 0 <= P < 1")
        if not 0.0 <= self.spurious <= 5.0:
            raise DataError(f"box noise spurious {self.spurious}: expected 0 <= Q <= 5")

    @property
    def active(self) -> bool:
        """Whether any box changes."""
        return bool(self.jitter or self.drop or self.spurious)

    def label(self) -> str:
        """A file-name-safe name of this noise (``S0.05-P0.1-Q0``)."""
        return f"S{self.jitter:g}-P{self.drop:g}-Q{self.spurious:g}"

    def apply(
        self,
        obs_id: str,
        objects: ObjectColumns,
        relations: RelationColumns,
        *,
        slot_runs: np.ndarray,
        image_hw: tuple[int, int],
    ) -> tuple[ObjectColumns, RelationColumns]:
        """One view's objects and relations under this noise.

        Args:
            slot_runs: (C, 2) int64 per class id: first slot and run length (the manifest's).
            image_hw: the stored image's (height, width): boxes are in its pixels.
        """
        if not self.active:
            return objects, relations
        rng = rng_for(box_noise_seed(self.seed, obs_id))
        instance, class_id, slot, box = (np.asarray(x) for x in objects)
        box = np.asarray(box, dtype=np.float64).reshape(-1, 4)
        src, dst, kind = (np.asarray(x) for x in relations)
        height, width = image_hw
        # draws in a fixed order and count, so S, P and Q do not shift each other's draws
        corner = rng.standard_normal((len(box), 4))
        keep = rng.random(len(box)) >= self.drop
        extra = int(rng.poisson(self.spurious * len(box))) if self.spurious else 0
        if self.jitter:
            w, h = box[:, 2] - box[:, 0], box[:, 3] - box[:, 1]
            side = np.stack((w, h, w, h), axis=1)
            box = _clip(box + self.jitter * side * corner, width, height)
        instance, class_id, slot, box = instance[keep], class_id[keep], slot[keep], box[keep]
        kept = set(instance.tolist())
        linked = np.array([s in kept and d in kept for s, d in zip(src, dst, strict=True)], bool)
        src, dst, kind = src[linked], dst[linked], kind[linked]
        if extra:
            instance, class_id, slot, box = _add_false_objects(
                rng, extra, (instance, class_id, slot, box), slot_runs, width, height
            )
        objects_out = (
            instance.astype(np.int64),
            class_id.astype(np.int64),
            slot.astype(np.int64),
            box.astype(np.float32),
        )
        return objects_out, (src, dst, kind)


def _clip(box: np.ndarray, width: int, height: int) -> np.ndarray:
    lo = np.minimum(box[:, :2], box[:, 2:])
    hi = np.maximum(box[:, :2], box[:, 2:])
    lo = np.clip(lo, 0, [width - 1, height - 1])
    hi = np.clip(np.maximum(hi, lo + 1), 1, [width, height])
    return np.concatenate((lo, hi), axis=1)


def _add_false_objects(
    rng: np.random.Generator,
    count: int,
    objects: ObjectColumns,
    slot_runs: np.ndarray,
    width: int,
    height: int,
) -> ObjectColumns:
    instance, class_id, slot, box = objects
    used = set(slot.tolist())
    next_instance = int(instance.max()) + 1 if len(instance) else 0
    classes = rng.integers(0, len(slot_runs), size=count)
    sizes = rng.uniform(0.05, 0.40, size=(count, 2)) * [width, height]
    places = rng.random((count, 2))
    new = []
    for c, size, place in zip(classes.tolist(), sizes, places, strict=True):
        start, run = (int(x) for x in slot_runs[c])
        free = [s for s in range(start, start + run) if s not in used]
        if not free:
            continue
        used.add(free[0])
        lo = place * ([width, height] - size)
        new.append((next_instance, c, free[0], [*lo, *(lo + size)]))
        next_instance += 1
    if not new:
        return instance, class_id, slot, box
    add_i, add_c, add_s, add_b = zip(*new, strict=True)
    return (
        np.concatenate((instance, add_i)),
        np.concatenate((class_id, add_c)),
        np.concatenate((slot, add_s)),
        np.concatenate((box, np.asarray(add_b, dtype=np.float64))),
    )
