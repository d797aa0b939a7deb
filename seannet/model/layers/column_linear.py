"""A linear layer that can be given only the runs of input columns that are not zero."""

from __future__ import annotations

from collections.abc import Sequence

import torch
from torch import Tensor, nn
from torch.autograd.function import FunctionCtx, once_differentiable
from torch.nn import functional as F

from seannet.errors import ModelError

__all__ = ["ColumnLinear"]


class ColumnLinear(nn.Linear):
    r""":class:`torch.nn.Linear` that also takes its input as runs of columns, the rest zero.

    .. math::
        y = x W^T + b = \sum_{\text{runs } [s, s + l)} x_{:, s:s+l}\, W_{:, s:s+l}^T + b

    Called as ``layer(x)`` it is ``nn.Linear``. Called as ``layer(x, runs)``, ``runs`` lists
    ``(start, length)`` blocks of consecutive input columns, increasing and not overlapping;
    ``x`` holds only those blocks, side by side, and every other input column is zero. Each
    block is one matrix product on a strided view of ``weight`` (no copy); the backward writes
    the weight gradient into those columns of one zero tensor (zero elsewhere, as the full
    product's is there). Same parameters as ``nn.Linear``, so the same ``state_dict``.

    Why: SeanNet's GCN fc reads a (B, 6144) vector that is ~97 % zeros (slots without a node).
    On a CPU the full product and both products of its backward multiply every column; the
    runs multiply only the columns some view uses (``bench/gcn_fc.py`` times both). The whole
    weight gradient is still written, zeros included: that fresh 100 MB is most of what the
    layer costs in either form.

    Args: as :class:`torch.nn.Linear` (``in_features``, ``out_features``, ``bias``,
    ``device``, ``dtype``).

    Shapes:
        - **x**: :math:`(B, \text{in\_features})`, or :math:`(B, \sum l)` with ``runs``
        - **output**: :math:`(B, \text{out\_features})`
    """

    def forward(self, x: Tensor, runs: Sequence[tuple[int, int]] | None = None) -> Tensor:
        if runs is None:
            return F.linear(x, self.weight, self.bias)
        runs = tuple((int(start), int(length)) for start, length in runs)
        self._check_runs(x, runs)
        if runs == ((0, self.in_features),):  # the whole input: the plain product
            return F.linear(x, self.weight, self.bias)
        return _RunsProduct.apply(x, self.weight, self.bias, runs)

    def _check_runs(self, x: Tensor, runs: tuple[tuple[int, int], ...]) -> None:
        end = 0
        for start, length in runs:
            if start < end or length <= 0 or start + length > self.in_features:
                raise ModelError(
                    f"ColumnLinear runs {runs}: expected (start, length) blocks with length "
                    f">= 1, in increasing order, not overlapping, within {self.in_features} "
                    "columns"
                )
            end = start + length
        width = sum(length for _, length in runs)
        if x.dim() != 2 or x.shape[1] != width:
            raise ModelError(
                f"ColumnLinear input {tuple(x.shape)} with runs of {width} columns; expected "
                f"(B, {width}): the runs' columns side by side"
            )


class _RunsProduct(torch.autograd.Function):
    """x W^T + b over column runs; the backward reads the same runs of W and writes them."""

    @staticmethod
    def forward(
        ctx: FunctionCtx,
        x: Tensor,
        weight: Tensor,
        bias: Tensor | None,
        runs: tuple[tuple[int, int], ...],
    ) -> Tensor:
        ctx.runs = runs
        ctx.save_for_backward(x, weight)
        if bias is None:
            out = x.new_zeros(x.shape[0], weight.shape[0])
        else:
            out = bias.expand(x.shape[0], -1).clone()
        for (start, length), at in zip(runs, _offsets(runs), strict=True):
            out.addmm_(x[:, at : at + length], weight[:, start : start + length].t())
        return out

    @staticmethod
    @once_differentiable
    def backward(ctx: FunctionCtx, grad: Tensor) -> tuple[Tensor | None, ...]:
        x, weight = ctx.saved_tensors
        runs = ctx.runs
        grad_x = grad_weight = grad_bias = None
        if ctx.needs_input_grad[0]:
            parts = [grad @ weight[:, start : start + length] for start, length in runs]
            grad_x = torch.cat(parts, dim=1) if parts else torch.zeros_like(x)
        if ctx.needs_input_grad[1]:
            grad_weight = torch.zeros_like(weight)  # columns outside the runs: x is zero there
            for (start, length), at in zip(runs, _offsets(runs), strict=True):
                grad_weight[:, start : start + length].addmm_(grad.t(), x[:, at : at + length])
        if ctx.needs_input_grad[2]:
            grad_bias = grad.sum(0)
        return grad_x, grad_weight, grad_bias, None


def _offsets(runs: tuple[tuple[int, int], ...]) -> list[int]:
    """Where each run starts in the input that holds the runs side by side."""
    offsets, at = [], 0
    for _, length in runs:
        offsets.append(at)
        at += length
    return offsets
