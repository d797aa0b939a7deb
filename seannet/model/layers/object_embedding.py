"""The object feature embedding x_i = fcn([x_v; x_b; x_w]) (SeanNet paper §IV-B)."""

from __future__ import annotations

from collections.abc import Sequence

import torch
from torch import Tensor, nn

from seannet.errors import ModelError
from seannet.model.layers.box_encoding import BoxEncoding

__all__ = ["OBJECT_INPUTS", "ObjectEmbedding"]

OBJECT_INPUTS = ("visual", "box", "word")  # x_v, x_b, x_w


class ObjectEmbedding(nn.Module):
    r"""Embeds each detected object from its visual feature, box and class word vector.

    From "SeanNet" (https://arxiv.org/abs/2110.02276), §IV-B:

    .. math::
        x_i = \mathrm{fcn}([x_v;\; x_b;\; x_w]), \quad
        \mathrm{fcn}(z) = \mathrm{ReLU}(W_2\, \mathrm{ReLU}(W_1 z + b_1) + b_2)

    with :math:`x_v` the RoI feature after the ResNet head (computed by the caller),
    :math:`x_b` the :class:`BoxEncoding` of the box and :math:`x_w` the fixed word vector of
    the class (a buffer: word vectors are not trained, as in the paper). For ResNet-50 the
    fcn is 2048 + 256 + 300 = 2604 → 1024 → 512. Word vectors are scaled to unit length: raw
    GloVe rows have norms of 4-8 and would outweigh the other inputs at initialisation.

    ``inputs`` names the parts fed to the fcn (default all three); leaving one out is an
    ablation (the fcn's input shrinks accordingly).

    Args:
        word_vectors: :math:`(C, D_w)` float tensor, row c the word vector of class id c.
        visual_dim: width of :math:`x_v` (2048 for ResNet-50, 512 for ResNet-18/34).
        box_dim_per_coord: PE channels per box coordinate (default 64 → :math:`x_b` 256-d).
        hidden_dims: fcn widths after the input (default (1024, 512)).
        inputs: which of ``"visual"``, ``"box"``, ``"word"`` to feed (default all).

    Shapes:
        - **visual**: :math:`(K, D_v)`
        - **boxes**: :math:`(K, 4)` pixel boxes [u1, v1, u2, v2]
        - **class_ids**: :math:`(K,)` long in [0, C)
        - **output**: :math:`(K, \text{hidden\_dims}[-1])`
    """

    word_vectors: Tensor

    def __init__(
        self,
        word_vectors: Tensor,
        visual_dim: int,
        *,
        box_dim_per_coord: int = 64,
        hidden_dims: Sequence[int] = (1024, 512),
        inputs: Sequence[str] = OBJECT_INPUTS,
    ) -> None:
        super().__init__()
        inputs = tuple(inputs)
        if not inputs or any(i not in OBJECT_INPUTS for i in inputs):
            raise ModelError(
                f"object inputs {inputs}; expected a non-empty subset of {OBJECT_INPUTS}"
            )
        if word_vectors.dim() != 2 or word_vectors.shape[0] == 0:
            raise ModelError(
                f"word_vectors: shape {tuple(word_vectors.shape)}; expected (classes, dim)"
            )
        if visual_dim <= 0:
            raise ModelError(f"visual_dim={visual_dim}; expected a positive integer")
        hidden_dims = tuple(int(h) for h in hidden_dims)
        if not hidden_dims or min(hidden_dims) <= 0:
            raise ModelError(f"hidden_dims={hidden_dims}; expected positive widths")
        vectors = word_vectors.detach().to(torch.float32)
        unit = vectors / vectors.norm(dim=1, keepdim=True).clamp_min(1e-12)
        self.register_buffer("word_vectors", unit.clone())
        self.box_encoding = BoxEncoding(box_dim_per_coord)
        self.visual_dim = visual_dim
        self.inputs = inputs
        widths = {
            "visual": visual_dim,
            "box": self.box_encoding.out_dim,
            "word": word_vectors.shape[1],
        }
        self.in_dim = sum(widths[i] for i in inputs)
        layers: list[nn.Module] = []
        width = self.in_dim
        for h in hidden_dims:
            layers += [nn.Linear(width, h), nn.ReLU(inplace=True)]
            width = h
        self.fcn = nn.Sequential(*layers)
        self.out_dim = width

    @property
    def num_classes(self) -> int:
        return self.word_vectors.shape[0]

    def reset_parameters(self) -> None:
        for m in self.fcn:
            if isinstance(m, nn.Linear):
                m.reset_parameters()

    def forward(self, visual: Tensor, boxes: Tensor, class_ids: Tensor) -> Tensor:
        parts = []
        if "visual" in self.inputs:
            parts.append(visual)
        if "box" in self.inputs:
            parts.append(self.box_encoding(boxes))
        if "word" in self.inputs:
            parts.append(self.word_vectors[class_ids])
        return self.fcn(torch.cat(parts, dim=1))
