"""Sinusoidal positional encoding of bounding-box corners (x_b, SeanNet paper §IV-B.1)."""

from __future__ import annotations

import math

import torch
from torch import Tensor, nn

from seannet.errors import ModelError

__all__ = ["sinusoidal_encoding", "BoxEncoding"]


def sinusoidal_encoding(x: Tensor, dim: int, *, max_period: float = 10000.0) -> Tensor:
    r"""The Transformer position encoding of real scalars (Vaswani et al., arXiv 1706.03762).

    .. math::
        PE(p)_{2i} = \sin(p / T^{2i/d}), \quad PE(p)_{2i+1} = \cos(p / T^{2i/d})

    with :math:`T` = ``max_period`` and :math:`d` = ``dim`` (even).

    Shapes:
        - **x**: any shape :math:`(*)`
        - **output**: :math:`(*, d)`
    """
    if dim <= 0 or dim % 2:
        raise ModelError(f"encoding dim={dim}; expected a positive even number")
    i = torch.arange(dim // 2, device=x.device, dtype=torch.float32)
    freq = torch.exp(-math.log(max_period) * 2.0 * i / dim)  # 1 / T^(2i/d)
    angle = x.to(torch.float32).unsqueeze(-1) * freq
    # interleave sin/cos as in the paper: even channels sin, odd channels cos
    return torch.stack((angle.sin(), angle.cos()), dim=-1).flatten(-2)


class BoxEncoding(nn.Module):
    r"""The positional feature :math:`x_b` of a box: the PE of each of its 4 corner coordinates.

    From "SeanNet: Semantic Understanding Network for Localization Under Object Dynamics"
    (https://arxiv.org/abs/2110.02276), §IV-B.1:

    .. math::
        x_b = [PE(u_1)^T\; PE(v_1)^T\; PE(u_2)^T\; PE(v_2)^T]^T \in \mathbb{R}^{4d}

    Nearby corners give nearby codes because every channel is a smooth function of the pixel
    coordinate. The layer has no parameters.

    Args:
        dim_per_coord: :math:`d`, channels per coordinate (default 64, so :math:`x_b` is 256-d).
        max_period: :math:`T` of the encoding (default 10000, as in the Transformer).

    Shapes:
        - **boxes**: :math:`(K, 4)` pixel boxes [u1, v1, u2, v2]
        - **output**: :math:`(K, 4d)`
    """

    def __init__(self, dim_per_coord: int = 64, *, max_period: float = 10000.0) -> None:
        super().__init__()
        if dim_per_coord <= 0 or dim_per_coord % 2:
            raise ModelError(f"dim_per_coord={dim_per_coord}; expected a positive even number")
        if not max_period > 1.0:
            raise ModelError(f"max_period={max_period}; expected > 1")
        self.dim_per_coord = dim_per_coord
        self.max_period = max_period

    @property
    def out_dim(self) -> int:
        """Width of :math:`x_b`: 4 · ``dim_per_coord``."""
        return 4 * self.dim_per_coord

    def forward(self, boxes: Tensor) -> Tensor:
        if boxes.dim() != 2 or boxes.shape[-1] != 4:
            raise ModelError(f"boxes: shape {tuple(boxes.shape)}; expected (K, 4)")
        code = sinusoidal_encoding(boxes, self.dim_per_coord, max_period=self.max_period)
        return code.flatten(1)  # (K, 4, d) -> (K, 4d): u1, v1, u2, v2 in order

    def extra_repr(self) -> str:
        return f"dim_per_coord={self.dim_per_coord}, max_period={self.max_period:g}"
