"""What a method sees: a batch of :class:`Views` (never the pose), a split to fit on
(:class:`SplitData`) and a training :class:`Budget`."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from torch import Tensor

from seannet.data.batch import SceneBatch
from seannet.errors import MethodError
from seannet.training.config import DEFAULT_PRESET

if TYPE_CHECKING:
    from sgdata.dataset import Dataset

__all__ = ["HIDDEN_FIELDS", "Budget", "SplitData", "Views"]

# what a view's row holds that a localizer must not read: its pose, and the ids that spell it
HIDDEN_FIELDS = frozenset(
    {"pose", "x", "y", "theta", "grid_i", "grid_j", "heading", "layout", "obs_id", "obs_ids"}
)


class Views:
    """N views as a method sees them: images and the visible objects, never the pose.

    Attributes:
        images: (N, 3, H, W) uint8 pixels (the method's ``image_size``).
        normalised: (N, 3, H, W) float32, normalised for the method's image network
            (``network`` attribute; default ImageNet statistics).
        boxes: (K, 4) float pixel boxes [u1, v1, u2, v2] of every visible object of every view.
        box_view: (K,) long, the view each box belongs to.
        class_ids: (K,) long, class ids in the dataset's vocabulary order.
        slots: (K,) long, instance slots in [0, M) (a class owns a run of slots).
        relations: (N, 3, M, M) adjacency of on / in / proximity (sparse COO, row-normalised).
        batch: the same as a :class:`~seannet.data.batch.SceneBatch` (the bundled networks').

    Reading ``pose``, ``grid_i``, ``obs_id`` or any other field of :data:`HIDDEN_FIELDS` raises
    a :class:`~seannet.errors.MethodError` naming the method: a localizer that saw where the
    camera stood would grade its own answer. The read is remembered (:attr:`hidden_reads`),
    so a method that catches the error is refused all the same.
    """

    __slots__ = ("_batch", "_method", "_hidden_reads")

    def __init__(self, batch: SceneBatch, *, method: str = "?") -> None:
        object.__setattr__(self, "_batch", batch)
        object.__setattr__(self, "_method", method)
        object.__setattr__(self, "_hidden_reads", [])

    def __len__(self) -> int:
        return self._batch.num_views

    def __getattr__(self, name: str) -> object:
        if name in HIDDEN_FIELDS:
            self._hidden_reads.append(name)
            raise MethodError(
                f"method {self._method!r} read views.{name}: a method never sees the pose "
                "(check: no pose)"
            )
        raise AttributeError(f"Views has no field {name!r}")

    def __setattr__(self, name: str, value: object) -> None:
        raise AttributeError("Views are read-only")

    @property
    def hidden_reads(self) -> tuple[str, ...]:
        """The hidden fields a method tried to read from these views, in order."""
        return tuple(self._hidden_reads)

    @property
    def batch(self) -> SceneBatch:
        return self._batch

    @property
    def images(self) -> Tensor:
        return self._batch.images

    @property
    def normalised(self) -> Tensor:
        return self._batch.normalised_images()

    @property
    def boxes(self) -> Tensor:
        return self._batch.boxes

    @property
    def box_view(self) -> Tensor:
        return self._batch.box_view

    @property
    def class_ids(self) -> Tensor:
        return self._batch.class_ids

    @property
    def slots(self) -> Tensor:
        return self._batch.slots

    @property
    def relations(self) -> Tensor:
        return self._batch.adjacency

    @property
    def num_slots(self) -> int:
        """M, the dataset's instance slots."""
        return self._batch.num_slots

    def slot_boxes(self) -> Tensor:
        """(N, M, 4) float32 boxes by slot, divided by the image side; NaN where empty."""
        import torch

        n, m = len(self), self.num_slots
        side = float(self.images.shape[-1])
        out = torch.full((n, m, 4), float("nan"))
        out[self.box_view, self.slots] = self.boxes.float() / side
        return out


@dataclass(frozen=True)
class Budget:
    """How much training a trainable method may do, and its seed."""

    seed: int = 0
    preset: str = DEFAULT_PRESET  # the bundled networks' training preset (PRESETS)
    batches: int | None = None  # batches per epoch (None: the preset's)
    epochs: int | None = None  # epochs (None: the preset's)
    lrs: tuple[float, ...] = ()  # learning rates to choose from on val (empty: the preset's)
    work: Path | None = None  # a directory the method may keep its runs in


@dataclass(frozen=True)
class SplitData:
    """One split of the dataset for ``fit``: its views in batches and its triplets.

    ``triplets`` index :meth:`views`' order. ``dataset`` is the dataset the benchmark opened
    (its directory ``dataset.root``), for trainers that read it their own way (the bundled
    networks): they take the handle rather than reading its ``dataset.json`` again. The views
    and triplets are all a method needs.
    """

    name: str
    dataset: Dataset
    triplets: np.ndarray  # (T, 3) int64: anchor, positive, negative view indices
    tiers: np.ndarray  # (T,) int64
    count: int  # views in the split
    _views: Callable[[int], Iterator[SceneBatch]]  # batch_size -> the split's batches
    method: str = "?"

    def views(self, batch_size: int = 32) -> Iterator[Views]:
        """The split's views in order, ``batch_size`` at a time."""
        for batch in self._views(batch_size):
            yield Views(batch, method=self.method)
