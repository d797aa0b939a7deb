"""The model's input batch (DESIGN §8): a plain dataclass of tensors with ``to`` and ``prepare``."""

from __future__ import annotations

from dataclasses import dataclass, field, fields, replace
from typing import Any

import torch
from torch import Tensor

from seannet.errors import DataError

__all__ = ["SceneBatch", "NUM_RELATIONS", "normalise_pixels"]

NUM_RELATIONS = 3  # adjacency channels, in this order: on, in, proximity ('disjoint' is dropped)


def normalise_pixels(
    pixels: Tensor, mean: tuple[float, float, float], std: tuple[float, float, float]
) -> Tensor:
    """(..., 3, H, W) uint8 pixels as float32 ``(x / 255 - mean) / std``, on their device.

    One multiply and one add per value (two separately rounded float32 operations, never
    fused), with the per-channel factors ``1 / (255 std)`` and ``-mean / std`` computed in
    float64 and rounded to float32 once: what :class:`~seannet.data.view_inputs.ImageTransform`
    has always computed, now wherever the pixels are. The result is contiguous.
    """
    scale = torch.tensor([1.0 / (255.0 * s) for s in std], dtype=torch.float32)
    offset = torch.tensor([-m / s for m, s in zip(mean, std, strict=True)], dtype=torch.float32)
    x = pixels.to(torch.float32, memory_format=torch.contiguous_format)
    x.mul_(scale.to(x.device).view(3, 1, 1))
    x.add_(offset.to(x.device).view(3, 1, 1))
    return x


@dataclass
class SceneBatch:
    """B views with their scene graphs, objects of all views concatenated.

    A batch comes in one of two forms. The loaders (:func:`seannet.data.datasets.collate_triplets`,
    :func:`~seannet.data.datasets.collate_views`) give the *compact* form: uint8 pixels and a sparse
    adjacency, what the image cache and the scene graph hold, with nothing converted or
    densified on the CPU (a 224 px view travels as 150 KB instead of 600 KB of float32, its
    graph as a few hundred cells instead of 786 KB of dense adjacency at M = 256). The models
    consume the *prepared* form (float32 normalised images, dense adjacency) and call
    :meth:`prepare` first, so after ``batch.to(device)`` the conversion runs on the model's
    device. Both forms give the model the same numbers, bit for bit.

    Shapes are checked on construction (cheap, no device sync); index ranges are checked by
    :meth:`validate`, which the models call before using the indices.

    Shapes:
        ====================  =====================  ===========================================
        field                 shape                  compact (loaders) / prepared (models)
        ====================  =====================  ===========================================
        ``images``            (B, 3, H, W)           uint8, any strides / float32, contiguous
        ``boxes``             (K, 4)                 float32, both
        ``box_view``          (K,)                   long, both
        ``class_ids``         (K,)                   long, both
        ``slots``             (K,)                   long, both
        ``adjacency``         (B, 3, M, M)           sparse COO float32 / dense float32
        ``mean``, ``std``     3 floats each          the transform's / None
        ``channels[name]``    (B, H, W)              as the loader gives them, both
        ====================  =====================  ===========================================

    Attributes:
        images: (B, 3, H, W), either float, normalised (prepared), or uint8 pixels 0..255
            (compact; any strides: the loaders give a channels-last view of a (B, H, W, 3)
            array) that :meth:`prepare` normalises with ``mean`` and ``std``.
        boxes: (K, 4) float pixel boxes [u1, v1, u2, v2] of every object of every view;
            u2 and v2 are exclusive, so a box covers the continuous range [u1, u2) x [v1, v2).
        box_view: (K,) long, the view (row of ``images``) each box belongs to.
        class_ids: (K,) long, class index in catalog order (``load_catalog().names()``).
        slots: (K,) long, GCN node slot in [0, M) (``sgdata.slots.SlotTable``).
        adjacency: (B, 3, M, M) float, row-normalised adjacency for on / in / proximity;
            absent nodes have zero rows. Dense (prepared) or a sparse COO tensor (compact:
            indices (4, E) [view, relation, row slot, column slot] of the E non-zero cells;
            a view without objects has none).
        mean: per-channel mean (RGB, on [0, 1] pixels) that ``prepare`` normalises uint8
            ``images`` with (the :class:`~seannet.data.view_inputs.ImageTransform`'s);
            None for float.
        std: per-channel std, as ``mean``.
        channels: the per-view channels asked of the dataset, name -> (B, H, W) tensor in
            the images' frame (``depth`` float32 metres, ``instances`` / ``classes`` int64:
            :mod:`seannet.data.view_channels`); empty unless asked for. The models ignore them.
    """

    images: Tensor
    boxes: Tensor
    box_view: Tensor
    class_ids: Tensor
    slots: Tensor
    adjacency: Tensor
    mean: tuple[float, float, float] | None = None
    std: tuple[float, float, float] | None = None
    channels: dict[str, Tensor] = field(default_factory=dict)

    def __post_init__(self) -> None:
        b = self.images.shape[0] if self.images.dim() == 4 else -1
        if self.images.dim() != 4 or self.images.shape[1] != 3:
            raise DataError(f"images: shape {tuple(self.images.shape)}; expected (B, 3, H, W)")
        if self.images.dtype == torch.uint8:
            if self.mean is None or self.std is None:
                raise DataError("images: uint8 pixels without mean / std; pass the transform's")
        elif not self.images.is_floating_point():
            raise DataError(f"images: dtype {self.images.dtype}; expected a float or uint8")
        elif self.mean is not None or self.std is not None:
            raise DataError("images: float images are normalised already; pass no mean / std")
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
        if a.layout not in (torch.strided, torch.sparse_coo):
            raise DataError(f"adjacency: layout {a.layout}; expected dense or sparse COO")
        frame = (b, *self.images.shape[2:])
        for name, t in self.channels.items():
            if tuple(t.shape) != frame:
                raise DataError(f"channel {name}: shape {tuple(t.shape)}; expected {frame}")

    def __getstate__(self) -> dict[str, Any]:
        # a sparse adjacency travels as its parts (DataLoader workers pickle batches): torch
        # would rebuild it with its index check implicitly off, and warn about that
        state = dict(self.__dict__)
        a = self.adjacency
        if a.layout == torch.sparse_coo:
            state["adjacency"] = (a._indices(), a._values(), tuple(a.shape), a.is_coalesced())
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        if isinstance(state["adjacency"], tuple):
            indices, values, shape, coalesced = state["adjacency"]
            state["adjacency"] = torch.sparse_coo_tensor(
                indices, values, shape, is_coalesced=coalesced, check_invariants=False
            )  # it was checked (or built in range) where it was made
        self.__dict__.update(state)

    @property
    def num_views(self) -> int:
        """B, the number of views (images) in the batch."""
        return self.images.shape[0]

    @property
    def num_slots(self) -> int:
        """M, the number of GCN node slots."""
        return self.adjacency.shape[-1]

    @property
    def prepared(self) -> bool:
        """True when the batch is in the form the models consume (float images, dense graph)."""
        return self.images.dtype != torch.uint8 and self.adjacency.layout == torch.strided

    def to(self, device: torch.device | str, *, non_blocking: bool = False) -> SceneBatch:
        """A copy with every tensor moved to ``device`` (in its form: compact stays compact)."""
        moved = {}
        for f in fields(self):
            value = getattr(self, f.name)
            if isinstance(value, Tensor):
                value = value.to(device, non_blocking=non_blocking)
            elif f.name == "channels":
                value = {k: t.to(device, non_blocking=non_blocking) for k, t in value.items()}
            moved[f.name] = value
        return SceneBatch(**moved)

    def normalised_images(self) -> Tensor:
        """(B, 3, H, W) float32 normalised images, computed on the images' device if uint8."""
        if self.images.dtype != torch.uint8:
            return self.images
        assert self.mean is not None and self.std is not None  # checked on construction
        return normalise_pixels(self.images, self.mean, self.std)

    def prepare(
        self, device: torch.device | str | None = None, *, dense_adjacency: bool = True
    ) -> SceneBatch:
        """The batch as the models consume it: normalised float32 images, dense adjacency.

        Moves the batch to ``device`` first (default: where it is), so the conversion runs
        there (on the GPU when training on one); a prepared batch is returned as it is.
        ``dense_adjacency=False`` leaves a sparse adjacency sparse (SeanNet reads its edges:
        densifying would fill B x 3 x M x M cells for nothing).
        """
        batch = self if device is None else self.to(device)
        adjacency = batch.adjacency
        if dense_adjacency and adjacency.layout == torch.sparse_coo:
            adjacency = adjacency.to_dense()
        if batch.images.dtype != torch.uint8 and adjacency is batch.adjacency:
            return batch
        return replace(
            batch, images=batch.normalised_images(), adjacency=adjacency, mean=None, std=None
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
