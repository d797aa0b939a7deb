"""The layout pathway of the scene-graph branch: where each node's box lies, slot by slot."""

from __future__ import annotations

import torch
from torch import Tensor, nn

from seannet.errors import ModelError

__all__ = ["SKETCH_SEED", "SlotLayout", "box_coverage"]

SKETCH_SEED = 20211005  # the count sketch's hash; any fixed value, saved with each model


def box_coverage(boxes: Tensor, height: int, width: int, grid: int) -> Tensor:
    """The share of each cell of a ``grid`` x ``grid`` partition of the image that each box
    covers, row-major: (K, 4) pixel boxes [u1, v1, u2, v2] -> (K, grid * grid) in [0, 1].

    The dot product of two boxes' rows is their overlap (in cell units), exact where the
    boxes meet cell edges and a smoothed overlap elsewhere, so a box that slides by a few
    pixels changes its row a little, not all at once.
    """
    # in cell units: cell c spans [c, c + 1)
    scale = boxes.new_tensor([width, height, width, height], dtype=torch.float32) / grid
    u1, v1, u2, v2 = (boxes.to(torch.float32) / scale).split(1, dim=1)  # (K, 1) each
    lo = torch.arange(grid, device=boxes.device, dtype=torch.float32)
    hi = lo + 1.0
    across = (torch.minimum(u2, hi) - torch.maximum(u1, lo)).clamp(0.0, 1.0)  # (K, G)
    down = (torch.minimum(v2, hi) - torch.maximum(v1, lo)).clamp(0.0, 1.0)  # (K, G)
    return (down.unsqueeze(2) * across.unsqueeze(1)).flatten(1)


class SlotLayout(nn.Module):
    r"""Each present node's box as a coarse occupancy grid in its slot, weighted by class.

    The row of node i is :math:`w_{c_i}\, r_i / \|r_i\|`, with :math:`r_i` the
    :func:`box_coverage` of its box and :math:`w_c` a learned weight per class
    (``initial_weights``, default 1);
    rows are scattered to (view, slot) and flattened, slot order kept, like the GCN's
    outputs: (B, M · grid²). The dot product of two views' vectors is then
    :math:`\sum_s w_{c_s}^2 \cos(r_s^A, r_s^B)` over the slots present in both: how far the
    same objects' boxes overlap, the weights learning which classes are reliable landmarks
    (the static ones) and which are noise (those people move).

    Why: a triplet is decided by how the boxes of the *same* objects shifted between two
    views. The GCN pathways squeeze a node to 8 numbers mixed with its neighbours before an
    fc sees any slot, and on `medium` they learned next to nothing of it (a graph-only SeanNet
    stayed near 60 % triplet accuracy), while the same objects' box overlap, computed by
    hand, ranks most triplets right on its own and lifts a trained ResNet-18 when added to
    its similarity (``resnet18+boxes``, :mod:`seannet.evaluation.box_overlap`; figures in
    docs/results.md).

    Args:
        num_slots: M.
        num_classes: C, one weight per class.
        grid: cells per side (default 8: 64 cells, 14 px at 112 px).
        initial_weights: :math:`(C,)` starting :math:`w_c` (default all 1).
        sketch_dim: 0 (default) keeps every (slot, cell) coordinate; D > 0 folds the
            M · grid² coordinates into D by a count sketch (each coordinate added, with a
            random sign, to one of D buckets; the hash is drawn once from a fixed seed and
            saved with the model): dot products are kept in expectation with a standard
            error of at most :math:`\sqrt{2/D}` for unit vectors (0.011 at D = 16,384), so a
            fine grid costs D numbers per view instead of M · grid².

    Shapes:
        - **boxes**: :math:`(K, 4)` pixel boxes in the frame of an ``height`` x ``width`` image
        - **box_view**, **slots**, **class_ids**: :math:`(K,)` long
        - **output**: :math:`(B, M \cdot \text{grid}^2)`, or :math:`(B, D)` sketched
    """

    def __init__(
        self,
        num_slots: int,
        num_classes: int,
        *,
        grid: int = 8,
        initial_weights: Tensor | None = None,
        sketch_dim: int = 0,
    ) -> None:
        super().__init__()
        for name, value in (("num_slots", num_slots), ("num_classes", num_classes), ("grid", grid)):
            if value <= 0:
                raise ModelError(f"SlotLayout {name}={value}; expected a positive integer")
        if sketch_dim < 0:
            raise ModelError(f"SlotLayout sketch_dim={sketch_dim}; expected 0 (off) or positive")
        self.num_slots = num_slots
        self.grid = grid
        self.sketch_dim = sketch_dim
        if sketch_dim:
            coordinates = num_slots * grid * grid
            draw = torch.Generator().manual_seed(SKETCH_SEED)
            bucket = torch.randint(sketch_dim, (coordinates,), generator=draw)
            sign = torch.randint(2, (coordinates,), generator=draw).to(torch.float32) * 2 - 1
            self.register_buffer("sketch_bucket", bucket)
            self.register_buffer("sketch_sign", sign)
        if initial_weights is None:
            initial_weights = torch.ones(num_classes)
        if tuple(initial_weights.shape) != (num_classes,):
            raise ModelError(
                f"SlotLayout initial_weights: shape {tuple(initial_weights.shape)}; "
                f"expected ({num_classes},)"
            )
        self.class_weight = nn.Parameter(initial_weights.detach().to(torch.float32).clone())

    @property
    def out_dim(self) -> int:
        return self.sketch_dim or self.num_slots * self.grid * self.grid

    def forward(
        self,
        boxes: Tensor,
        box_view: Tensor,
        slots: Tensor,
        class_ids: Tensor,
        *,
        num_views: int,
        height: int,
        width: int,
    ) -> Tensor:
        cells = box_coverage(boxes, height, width, self.grid)
        rows = cells / cells.norm(dim=1, keepdim=True).clamp_min(1e-12)
        rows = rows * self.class_weight[class_ids].unsqueeze(1)
        if not self.sketch_dim:
            out = rows.new_zeros(num_views, self.num_slots, self.grid * self.grid)
            return out.index_put((box_view, slots), rows).flatten(1)
        per_slot = rows.shape[1]
        coordinate = slots.unsqueeze(1) * per_slot + torch.arange(per_slot, device=rows.device)
        target = box_view.unsqueeze(1) * self.sketch_dim + self.sketch_bucket[coordinate]
        out = rows.new_zeros(num_views * self.sketch_dim)
        out = out.index_add(0, target.flatten(), (rows * self.sketch_sign[coordinate]).flatten())
        return out.view(num_views, self.sketch_dim)

    def extra_repr(self) -> str:
        return f"num_slots={self.num_slots}, grid={self.grid}, sketch_dim={self.sketch_dim}"
