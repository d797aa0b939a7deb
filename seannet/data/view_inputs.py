"""Per-view model inputs: the image transform and the scene-graph tensors (DESIGN §8)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pyarrow as pa
import torch
from PIL import Image
from torch import Tensor

from seannet.data.batch import NUM_RELATIONS, normalise_pixels
from seannet.errors import DataError
from seannet.weights import IMAGE_SIZE, IMAGENET_MEAN, IMAGENET_STD, normalisation
from sgdata.annotate.relations import RelationType

__all__ = [
    "ImageTransform",
    "dense_adjacency",
    "graph_from_columns",
    "graph_tensors",
    "struct_columns",
]

# ---------------------------------------------------------------------------------- images


@dataclass(frozen=True)
class ImageTransform:
    """Resize a view to ``size`` x ``size`` and normalise it the torchvision way.

    The image is resized with Pillow's bilinear filter (antialiased when shrinking), converted
    to float32 CHW on [0, 1], then normalised per channel as ``(x - mean) / std`` with the
    ImageNet statistics by default (what torchvision's pretrained ResNet expects). Boxes are
    scaled by the same factors ``size / width`` and ``size / height``, so they stay in the
    pixel frame of the resized image (continuous edges, u2 and v2 exclusive). A view already
    at ``size`` is not resampled.
    """

    size: int = IMAGE_SIZE  # output height and width in pixels (a CPU preset: 112)
    mean: tuple[float, float, float] = IMAGENET_MEAN  # per-channel mean, RGB, [0, 1] scale
    std: tuple[float, float, float] = IMAGENET_STD  # per-channel std, RGB, [0, 1] scale

    def __post_init__(self) -> None:
        if not isinstance(self.size, int) or self.size < 1:
            raise DataError(f"ImageTransform size={self.size!r}; expected a positive integer")
        if len(self.mean) != 3 or len(self.std) != 3:
            raise DataError(f"ImageTransform mean/std {self.mean}/{self.std}; expected 3 each")
        if min(self.std) <= 0:
            raise DataError(f"ImageTransform std={self.std}; expected positive values")

    @classmethod
    def for_model(cls, image_size: int, backbone: str = "resnet") -> ImageTransform:
        """The transform a model expects: its input size and its backbone's normalisation."""
        mean, std = normalisation(backbone)
        return cls(size=image_size, mean=mean, std=std)

    def __call__(self, rgb: np.ndarray, boxes: np.ndarray) -> tuple[Tensor, Tensor]:
        """Transform one view.

        Args:
            rgb: (H, W, 3) uint8 image.
            boxes: (K, 4) pixel boxes [u1, v1, u2, v2] in the frame of ``rgb``.

        Returns:
            ``(image, boxes)``: (3, size, size) float32 and (K, 4) float32 in the new frame.
        """
        pixels, boxes_out = self.resize(rgb, boxes)
        image = normalise_pixels(torch.tensor(pixels).permute(2, 0, 1), self.mean, self.std)
        return image, boxes_out

    def resize(self, rgb: np.ndarray, boxes: np.ndarray) -> tuple[np.ndarray, Tensor]:
        """The first half of :meth:`__call__`: resize only, the pixels left as uint8.

        The loaders carry these pixels (and :meth:`scale_boxes`'s boxes) to the model's
        device, where :func:`~seannet.data.batch.normalise_pixels` with this transform's mean and
        std finishes the job (``SceneBatch.prepare``): the same numbers as :meth:`__call__`.

        Returns:
            ``(pixels, boxes)``: (size, size, 3) uint8 (``rgb`` itself when already at size)
            and (K, 4) float32 in the new frame.
        """
        h, w = rgb.shape[:2]
        s = self.size
        if (h, w) != (s, s):
            rgb = np.asarray(Image.fromarray(rgb).resize((s, s), Image.Resampling.BILINEAR))
        return rgb, torch.from_numpy(self.scale_boxes(boxes, np.asarray([[h, w]])))

    def scale_boxes(self, boxes: np.ndarray, source_hw: np.ndarray) -> np.ndarray:
        """(K, 4) boxes from frames of ``source_hw`` (K, 2) (or (1, 2) for all) to size x size.

        In float32, by ``size / width`` and ``size / height`` rounded to float32 once.
        """
        hw = np.asarray(source_hw, dtype=np.float64).reshape(-1, 2)
        s = float(self.size)
        scale = np.stack((s / hw[:, 1], s / hw[:, 0]), axis=1)[:, [0, 1, 0, 1]].astype(np.float32)
        return np.asarray(boxes, dtype=np.float32).reshape(-1, 4) * scale


# ---------------------------------------------------------------------------------- graphs


def struct_columns(rows: Any, names: Sequence[str]) -> dict[str, np.ndarray]:
    """Columns ``names`` of a list of structs, as pyarrow gives it (or as ``to_pylist``)."""
    if isinstance(rows, pa.ListScalar):
        rows = rows.values if rows.is_valid else pa.array([], type=rows.type.value_type)
    if rows is None:
        rows = []
    if isinstance(rows, pa.ChunkedArray):
        rows = rows.combine_chunks()
    if isinstance(rows, pa.StructArray):
        children = dict(zip([f.name for f in rows.type], rows.flatten(), strict=True))
        out = {}
        for n in names:
            child = children[n]
            if pa.types.is_fixed_size_list(child.type):
                width = child.type.list_size
                out[n] = child.flatten().to_numpy(zero_copy_only=False).reshape(-1, width)
            else:
                out[n] = child.to_numpy(zero_copy_only=False)
        return out
    rows = list(rows)
    return {n: np.asarray([r[n] for r in rows]) for n in names}


def graph_tensors(
    objects: Any, relations: Any, *, num_slots: int
) -> tuple[Tensor, Tensor, Tensor, Tensor]:
    """The per-view graph tensors of one observation row.

    Args:
        objects: the row's ``objects`` list of structs — a ``pyarrow.ListScalar`` (a cell of the
            column), its ``StructArray`` of values, or the ``to_pylist()`` list of dicts.
        relations: the row's ``relations`` list of structs, in any of the same forms.
        num_slots: M, the GCN node slots (the manifest's ``num_slots``).

    Returns:
        ``(slots, class_ids, boxes, adjacency)``: (K,) long, (K,) long, (K, 4) float32 pixel
        boxes in the image's own frame (objects in row order), and (3, M, M) float32.

    Adjacency: channel r of ``on``, ``in``, ``proximity`` (relation type codes 0, 1, 2 of the
    manifest's ``relation_types``; ``disjoint`` (3) is not fed), oriented as in the paper
    (§IV-A: ``A(o_i, o_j) = on`` means o_j is on o_i): the stored edge ``mug -> table`` (the
    mug rests on the table) sets ``A[on, slot(table), slot(mug)]``, so a support gathers what
    it carries; proximity is symmetric. Every present object also gets a self-loop in every
    channel (Kipf & Welling's A + I; the authors' code sets ``A[i, i] = 1`` for each present
    object): without it a node's feature survives a layer only through an edge of that type,
    and since ``on`` / ``in`` never chain three deep, those pathways output exactly zero after
    three layers. Each row is then divided by its sum; rows of absent slots stay zero.

    Raises:
        DataError: a slot outside [0, M), two objects sharing a slot, or a relation naming
            an instance that is not among the row's objects.
    """
    obj = struct_columns(objects, ("instance", "class_id", "slot", "box2d"))
    rel = struct_columns(relations, ("src", "dst", "type"))
    slots, class_ids, boxes, edge_index, edge_weight = graph_from_columns(
        obj["instance"],
        obj["class_id"],
        obj["slot"],
        obj["box2d"],
        rel["src"],
        rel["dst"],
        rel["type"],
        num_slots,
    )
    return slots, class_ids, boxes, dense_adjacency(edge_index, edge_weight, num_slots)


def dense_adjacency(edge_index: Tensor, edge_weight: Tensor, num_slots: int) -> Tensor:
    """(3, M, M) adjacency from (3, E) [relation, src slot, dst slot] and (E,) weights."""
    adjacency = torch.zeros((NUM_RELATIONS, num_slots, num_slots), dtype=torch.float32)
    adjacency[edge_index[0], edge_index[1], edge_index[2]] = edge_weight
    return adjacency


def graph_from_columns(
    instance: np.ndarray,
    class_id: np.ndarray,
    slot: np.ndarray,
    box2d: np.ndarray,
    src: np.ndarray,
    dst: np.ndarray,
    rtype: np.ndarray,
    num_slots: int,
) -> tuple[Tensor, Tensor, Tensor, Tensor, Tensor]:
    """:func:`graph_tensors` on numpy columns, the adjacency as a sparse edge list.

    Returns:
        ``(slots, class_ids, boxes, edge_index, edge_weight)``: edge_index (3, E) long holds
        [relation, row slot, column slot] of each non-zero cell (edges oriented as in
        :func:`graph_tensors`, and self-loops), edge_weight (E,) float32 its row-normalised
        value (1 / degree of the row in that relation).
    """
    m = num_slots
    slot = np.asarray(slot, dtype=np.int64)
    if slot.size and (slot.min() < 0 or slot.max() >= m):
        bad = int(slot.min()) if slot.min() < 0 else int(slot.max())
        raise DataError(f"object slot {bad} out of range; expected 0 <= slot < {m}")
    if np.unique(slot).size != slot.size:
        raise DataError("two objects of one view share a GCN slot; slots must be unique")
    rtype = np.asarray(rtype, dtype=np.int64)
    fed = rtype < NUM_RELATIONS  # 'disjoint' and any later type are not GCN pathways
    edge_index = np.zeros((3, 0), dtype=np.int64)
    edge_weight = np.zeros(0, dtype=np.float32)
    cells: list[np.ndarray] = []
    if fed.any():
        instance = np.asarray(instance, dtype=np.int64)
        order = np.argsort(instance, kind="stable")
        keys = instance[order]
        ends = np.concatenate((np.asarray(src)[fed], np.asarray(dst)[fed])).astype(np.int64)
        pos = np.searchsorted(keys, ends)
        pos_ok = np.minimum(pos, max(keys.size - 1, 0))
        found = (pos < keys.size) & (keys[pos_ok] == ends) if keys.size else pos < 0
        if not found.all():
            missing = int(ends[~found][0])
            raise DataError(f"a relation names instance {missing}, not among the row's objects")
        ends_slot = slot[order][pos]
        n = int(fed.sum())
        kind = rtype[fed]
        # on / in point from the object on top (inside) to its support (container): the
        # paper's row is the support, so those edges are transposed
        flip = (kind == RelationType.ON) | (kind == RelationType.IN)
        row_slot = np.where(flip, ends_slot[n:], ends_slot[:n])
        col_slot = np.where(flip, ends_slot[:n], ends_slot[n:])
        cells.append((kind * m + row_slot) * m + col_slot)
    if slot.size:  # a self-loop for every present object, in every channel
        loops = np.arange(NUM_RELATIONS, dtype=np.int64)[:, None] * m + slot[None, :]
        cells.append((loops * m + slot[None, :]).ravel())
    if cells:
        # distinct (relation, row, col) cells, then 1 / degree per (relation, row)
        cell = np.unique(np.concatenate(cells))
        row = cell // m
        _, inverse, degree = np.unique(row, return_inverse=True, return_counts=True)
        edge_index = np.stack((row // m, row % m, cell % m))
        edge_weight = (1.0 / degree[inverse]).astype(np.float32)
    return (
        torch.from_numpy(slot),
        torch.from_numpy(np.asarray(class_id, dtype=np.int64)),
        torch.from_numpy(np.asarray(box2d, dtype=np.float32).reshape(-1, 4)),
        torch.from_numpy(edge_index),
        torch.from_numpy(edge_weight),
    )


# ---------------------------------------------------------------------------------- items
