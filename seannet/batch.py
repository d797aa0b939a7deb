"""The model's input batch (DESIGN §8): a plain dataclass of tensors with ``to(device)``."""

from __future__ import annotations

from dataclasses import dataclass, fields

import torch
from torch import Tensor

from seannet.errors import DataError

__all__ = ["SceneBatch", "NUM_RELATIONS"]

NUM_RELATIONS = 3  # adjacency channels, in this order: on, in, proximity ('disjoint' is dropped)


@dataclass
class SceneBatch:
    """B views with their scene graphs, objects of all views concatenated.

    Shapes are checked on construction (cheap, no device sync); index ranges are checked by
    :meth:`validate`, which the models call before using the indices.

    Attributes:
        images: (B, 3, H, W) float, normalised the torchvision way (ImageNet mean/std).
        boxes: (K, 4) float pixel boxes [u1, v1, u2, v2] of every object of every view;
            u2 and v2 are exclusive, so a box covers the continuous range [u1, u2) x [v1, v2).
        box_view: (K,) long, the view (row of ``images``) each box belongs to.
        class_ids: (K,) long, class index in catalog order (``load_catalog().names()``).
        slots: (K,) long, GCN node slot in [0, M) (``sgdata.slots.SlotTable``).
        adjacency: (B, 3, M, M) float, row-normalised adjacency for on / in / proximity;
            absent nodes have zero rows.
    """

    images: Tensor
    boxes: Tensor
    box_view: Tensor
    class_ids: Tensor
    slots: Tensor
    adjacency: Tensor

    def __post_init__(self) -> None:
        b = self.images.shape[0] if self.images.dim() == 4 else -1
        if self.images.dim() != 4 or self.images.shape[1] != 3:
            raise DataError(f"images: shape {tuple(self.images.shape)}; expected (B, 3, H, W)")
        if self.boxes.dim() != 2 or self.boxes.shape[1] != 4:
            raise DataError(f"boxes: shape {tuple(self.boxes.shape)}; expected (K, 4)")
        k = self.boxes.shape[0]
        for name in ("box_view", "class_ids", "slots"):
            t = getattr(self, name)
            if t.shape != (k,):
                raise DataError(f"{name}: shape {tuple(t.shape)}; expected ({k},) like boxes")
            if t.dtype != torch.long:
                raise DataError(f"{name}: dtype {t.dtype}; expected torch.long")
        a = self.adjacency
        if (
            a.dim() != 4
            or a.shape[0] != b
            or a.shape[1] != NUM_RELATIONS
            or a.shape[2] != a.shape[3]
        ):
            raise DataError(
                f"adjacency: shape {tuple(a.shape)}; expected ({b}, {NUM_RELATIONS}, M, M)"
            )

    @property
    def num_views(self) -> int:
        """B, the number of views (images) in the batch."""
        return self.images.shape[0]

    @property
    def num_slots(self) -> int:
        """M, the number of GCN node slots."""
        return self.adjacency.shape[-1]

    def to(self, device: torch.device | str, *, non_blocking: bool = False) -> SceneBatch:
        """A copy with every tensor moved to ``device``."""
        return SceneBatch(
            **{
                f.name: getattr(self, f.name).to(device, non_blocking=non_blocking)
                for f in fields(self)
            }
        )

    def validate(self, *, num_classes: int | None = None) -> None:
        """Check index ranges and that no two boxes share a (view, slot) node.

        Raises:
            DataError: naming the first bad value.
        """
        if self.boxes.shape[0] == 0:
            return
        b, m = self.num_views, self.num_slots
        checks = [("box_view", self.box_view, b), ("slots", self.slots, m)]
        if num_classes is not None:
            checks.append(("class_ids", self.class_ids, num_classes))
        for name, t, hi in checks:
            lo_v, hi_v = int(t.min()), int(t.max())
            if lo_v < 0 or hi_v >= hi:
                bad = lo_v if lo_v < 0 else hi_v
                raise DataError(f"{name}: value {bad} out of range; expected 0 <= {name} < {hi}")
        node = self.box_view * m + self.slots
        if torch.unique(node).numel() != node.numel():
            raise DataError("two boxes of one view share a GCN slot; slots must be unique per view")
        if not bool(torch.isfinite(self.boxes).all()):
            raise DataError("boxes: contains a non-finite coordinate")
