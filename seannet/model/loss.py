"""Cosine similarity of scene embeddings and the triplet loss (SeanNet paper §IV-D, §IV-E)."""

from __future__ import annotations

import math

import torch
from torch import Tensor, nn
from torch.nn import functional as F

from seannet.errors import ModelError

__all__ = ["similarity", "TripletLoss"]


def similarity(a: Tensor, b: Tensor, *, eps: float = 1e-8) -> Tensor:
    r"""Cosine similarity :math:`S(a, b) = a \cdot b / (\|a\|_2 \|b\|_2)` along the last dim.

    Shapes:
        - **a**, **b**: :math:`(*, D)` (broadcastable)
        - **output**: :math:`(*)`
    """
    return F.cosine_similarity(a, b, dim=-1, eps=eps)


class TripletLoss(nn.Module):
    r"""The triplet loss on cosine similarity (paper §IV-E, after FaceNet arXiv 1503.03832):

    .. math::
        \ell(A, P, N) = \max\{0,\; S(A, N) + \alpha - S(A, P)\}

    averaged over the batch. Arguments come in the order (anchor, positive, negative): the
    authors' baseline code fed (A, N, P), which trains the network the wrong way round.

    Args:
        margin: :math:`\alpha` (default 0.1, paper §V-B).
        reduction: ``"mean"`` (default), ``"sum"`` or ``"none"``.

    Shapes:
        - **anchor**, **positive**, **negative**: :math:`(B, D)` embeddings
        - **output**: scalar, or :math:`(B,)` with ``reduction="none"``
    """

    def __init__(self, margin: float = 0.1, *, reduction: str = "mean") -> None:
        super().__init__()
        if not (math.isfinite(margin) and margin >= 0.0):
            raise ModelError(f"triplet margin={margin}; expected a finite number >= 0")
        if reduction not in ("mean", "sum", "none"):
            raise ModelError(f"reduction={reduction!r}; expected 'mean', 'sum' or 'none'")
        self.margin = float(margin)
        self.reduction = reduction

    def forward(self, anchor: Tensor, positive: Tensor, negative: Tensor) -> Tensor:
        if not anchor.shape == positive.shape == negative.shape:
            raise ModelError(
                f"triplet shapes differ: anchor {tuple(anchor.shape)}, positive "
                f"{tuple(positive.shape)}, negative {tuple(negative.shape)}"
            )
        gap = similarity(anchor, negative) + self.margin - similarity(anchor, positive)
        loss = torch.clamp(gap, min=0.0)
        if self.reduction == "mean":
            return loss.mean()
        if self.reduction == "sum":
            return loss.sum()
        return loss

    def extra_repr(self) -> str:
        return f"margin={self.margin:g}"
