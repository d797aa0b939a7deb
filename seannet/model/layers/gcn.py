"""The multi-pathway GCN (SeanNet paper §IV-C): one GCN pathway per relation type."""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from typing import NamedTuple

import torch
from torch import Tensor, nn

from seannet.errors import ModelError
from seannet.model.layers.column_linear import ColumnLinear
from sgdata.annotate.slots import NUM_SLOTS

__all__ = ["GCNLayer", "GCNPathway", "MultiPathwayGCN", "NodeEdges"]

# Used (relation, slot) units with at most this many empty ones between them share one run of
# the fc's input, the empty ones multiplied as zeros: one more matrix product per run costs
# about what a few slots' 8 columns do (bench/gcn_fc.py, 2 and 16 views).
RUN_GAP = 3


class NodeEdges(NamedTuple):
    r"""One relation's normalised adjacency as an edge list over present nodes.

    ``weight[e]`` is :math:`\hat{A}_{ij}` for the edge from node ``target[e]`` (i, the row)
    to ``source[e]`` (j); node ids index the (K, F) list of present nodes.
    """

    target: Tensor
    source: Tensor
    weight: Tensor


class GCNLayer(nn.Module):
    r"""One graph-convolution layer on a given normalised adjacency (Kipf & Welling,
    https://arxiv.org/abs/1609.02907), batched over graphs:

    .. math::
        X' = \hat{A} X W

    :math:`\hat{A}` is used as given (row-normalised by the data pipeline; no self-loops
    are added here). There is no bias by default: a node with a zero row in :math:`\hat{A}`
    (an empty slot) then gets a zero output, so empty slots stay zero through a pathway and the
    flattened pathway output depends on present nodes only.

    Args:
        in_dim: input node-feature width.
        out_dim: output node-feature width.
        bias: add a learned bias (default ``False``, see above).

    Shapes:
        - **x**: :math:`(B, M, F_{in})` node features
        - **adjacency**: :math:`(B, M, M)` normalised adjacency :math:`\hat{A}`
        - **output**: :math:`(B, M, F_{out})`

        or, on present nodes only: **x** :math:`(K, F_{in})`, **adjacency** a
        :class:`NodeEdges`, **output** :math:`(K, F_{out})`.
    """

    def __init__(self, in_dim: int, out_dim: int, *, bias: bool = False) -> None:
        super().__init__()
        if in_dim <= 0 or out_dim <= 0:
            raise ModelError(f"GCNLayer({in_dim}, {out_dim}): widths must be positive")
        self.in_dim = in_dim
        self.out_dim = out_dim
        self.weight = nn.Parameter(torch.empty(in_dim, out_dim))
        self.bias = nn.Parameter(torch.empty(out_dim)) if bias else None
        self.reset_parameters()

    def reset_parameters(self) -> None:
        # Glorot uniform, as in Kipf & Welling's reference implementation
        nn.init.xavier_uniform_(self.weight)
        if self.bias is not None:
            nn.init.zeros_(self.bias)

    def forward(self, x: Tensor, adjacency: Tensor | NodeEdges) -> Tensor:
        # (A X) W or A (X W): multiply by W first, it shrinks the width (512 -> 256 -> 64 -> 8)
        h = x @ self.weight
        if isinstance(adjacency, NodeEdges):  # present nodes only: (K, F) and an edge list
            out = h.new_zeros(h.shape).index_add_(
                0, adjacency.target, h[adjacency.source] * adjacency.weight.unsqueeze(1)
            )
        else:
            out = adjacency @ h
        if self.bias is not None:
            out = out + self.bias
        return out

    def extra_repr(self) -> str:
        return f"{self.in_dim}, {self.out_dim}, bias={self.bias is not None}"


class GCNPathway(nn.Module):
    r"""A stack of GCN layers on one relation's adjacency :math:`\hat{A}_r`:

    .. math::
        X_r^{(i)} = \mathrm{ReLU}(\hat{A}_r\, \mathrm{Dropout}(X_r^{(i-1)})\, W^{(i)}),
        \quad i = 1 \dots L

    Dropout is applied to each layer's input, as in Kipf & Welling's GCN.

    Args:
        dims: node widths from input to output (default (512, 256, 64, 8): 3 layers).
        dropout: dropout probability (default 0.2, paper §V-B).

    Shapes:
        - **x**: :math:`(B, M, \text{dims}[0])`
        - **adjacency**: :math:`(B, M, M)`
        - **output**: :math:`(B, M, \text{dims}[-1])`

        or (K, dims[0]) present nodes with a :class:`NodeEdges` -> (K, dims[-1]).
    """

    def __init__(self, dims: Sequence[int] = (512, 256, 64, 8), *, dropout: float = 0.2) -> None:
        super().__init__()
        dims = tuple(int(d) for d in dims)
        if len(dims) < 2:
            raise ModelError(f"GCN pathway dims={dims}; expected at least (in, out)")
        if not 0.0 <= dropout < 1.0:
            raise ModelError(f"dropout={dropout}; expected 0 <= dropout < 1")
        self.dims = dims
        self.layers = nn.ModuleList(GCNLayer(a, b) for a, b in itertools.pairwise(dims))
        self.dropout = nn.Dropout(dropout)

    def reset_parameters(self) -> None:
        for layer in self.layers:
            layer.reset_parameters()

    def forward(self, x: Tensor, adjacency: Tensor | NodeEdges) -> Tensor:
        for layer in self.layers:
            x = torch.relu(layer(self.dropout(x), adjacency))
        return x


class MultiPathwayGCN(nn.Module):
    r"""The scene-graph branch of SeanNet (https://arxiv.org/abs/2110.02276, §IV-C, Fig. 3).

    One :class:`GCNPathway` per relation type r (on, in, proximity; 'disjoint' carries no
    information and is dropped), each on its own :math:`\hat{A}_r` and the shared
    :math:`X^{(0)}`. The M × 8 outputs are flattened (M·8 = 2048 for M = 256), concatenated
    (6144) and mapped by an fcn to the scene-graph embedding:

    .. math::
        g = \mathrm{ReLU}(W_2\, \mathrm{ReLU}(W_1 [\mathrm{vec}(X_{on});
            \mathrm{vec}(X_{in}); \mathrm{vec}(X_{prox})] + b_1) + b_2)

    Flattening keeps the slot order, so position in the vector means class (DESIGN §8).

    Args:
        num_slots: M, node slots per graph (default 256).
        dims: pathway widths (default (512, 256, 64, 8)).
        num_relations: pathways (default 3).
        hidden_dim: width of the fcn's hidden layer (default 4096).
        out_dim: width of the scene-graph embedding (default 2048).
        dropout: GCN dropout (default 0.2).

    Shapes:
        - **x**: :math:`(B, M, \text{dims}[0])` node features :math:`X^{(0)}`
        - **adjacency**: :math:`(B, R, M, M)`, R = ``num_relations``
        - **output**: :math:`(B, \text{out\_dim})`
    """

    def __init__(
        self,
        num_slots: int = NUM_SLOTS,
        dims: Sequence[int] = (512, 256, 64, 8),
        *,
        num_relations: int = 3,
        hidden_dim: int = 4096,
        out_dim: int = 2048,
        dropout: float = 0.2,
    ) -> None:
        super().__init__()
        for name, value in (
            ("num_slots", num_slots),
            ("num_relations", num_relations),
            ("hidden_dim", hidden_dim),
            ("out_dim", out_dim),
        ):
            if value <= 0:
                raise ModelError(f"{name}={value}; expected a positive integer")
        self.num_slots = num_slots
        self.num_relations = num_relations
        self.pathways = nn.ModuleList(
            GCNPathway(dims, dropout=dropout) for _ in range(num_relations)
        )
        flat = num_relations * num_slots * self.pathways[0].dims[-1]
        self.fc = nn.Sequential(
            ColumnLinear(flat, hidden_dim),  # forward_nodes gives it the used slots' columns
            nn.ReLU(inplace=True),
            nn.Linear(hidden_dim, out_dim),
            nn.ReLU(inplace=True),
        )
        self.out_dim = out_dim

    def reset_parameters(self) -> None:
        for p in self.pathways:
            p.reset_parameters()
        for m in self.fc:
            if isinstance(m, nn.Linear):
                m.reset_parameters()

    def forward(self, x: Tensor, adjacency: Tensor) -> Tensor:
        b, r, m = adjacency.shape[0], adjacency.shape[1], adjacency.shape[-1]
        if r != self.num_relations or m != self.num_slots or x.shape[:2] != (b, m):
            raise ModelError(
                f"GCN input x {tuple(x.shape)}, adjacency {tuple(adjacency.shape)}; expected "
                f"(B, {self.num_slots}, F) and (B, {self.num_relations}, "
                f"{self.num_slots}, {self.num_slots})"
            )
        flat = [p(x, adjacency[:, i]).flatten(1) for i, p in enumerate(self.pathways)]
        return self.fc(torch.cat(flat, dim=1))

    def forward_nodes(
        self, x: Tensor, box_view: Tensor, slots: Tensor, adjacency: Tensor, *, num_views: int
    ) -> Tensor:
        r""":meth:`forward` computed on the present nodes only, the same function.

        A view fills ~10-30 of its M slots: the dense form multiplies and drops out
        B x M rows that stay zero (two thirds of a CPU SeanNet step at M = 256); here the
        pathways run on the K present nodes and the adjacency's edges between them. On a CPU
        the fc's first layer then reads only the columns of the slots some view fills (runs of
        slots, :class:`ColumnLinear`), not the (B, R·M·8) vector that is ~97 % zeros; on
        another device the outputs fill that whole vector, one product.

        Args:
            x: (K, dims[0]) features of the present nodes.
            box_view, slots: (K,) long, each node's view and slot.
            adjacency: (B, R, M, M) dense or sparse COO :math:`\hat{A}`; edges from or to a
                slot with no node are ignored (the data pipeline makes none).
            num_views: B.

        Returns:
            (B, out_dim).
        """
        m = self.num_slots
        if adjacency.shape[1:] != (self.num_relations, m, m) or x.shape[0] != slots.shape[0]:
            raise ModelError(
                f"GCN nodes {tuple(x.shape)}, adjacency {tuple(adjacency.shape)}; expected "
                f"(K, F) and (B, {self.num_relations}, {m}, {m})"
            )
        edges = self._node_edges(box_view, slots, adjacency, num_views)
        out = torch.cat([p(x, e) for p, e in zip(self.pathways, edges, strict=True)])
        first, *rest = self.fc
        h = first(*self.fc_input(out, box_view, slots, num_views=num_views))
        for layer in rest:
            h = layer(h)
        return h

    def fc_input(
        self, out: Tensor, box_view: Tensor, slots: Tensor, *, num_views: int
    ) -> tuple[Tensor, list[tuple[int, int]]]:
        """The fc's input from the pathways' outputs on the present nodes, as the
        :class:`ColumnLinear` ``(x, runs)`` of :meth:`forward_nodes`.

        Args:
            out: (R·K, dims[-1]) the pathways' outputs, relation-major: relation r's K rows
                are ``out[r * K : (r + 1) * K]``.
            box_view, slots: (K,) long, each node's view and slot.
            num_views: B.

        Returns:
            x (B, width) and the runs ``(start, length)`` of the flattened
            [vec(X_on); vec(X_in); vec(X_prox)] it holds, side by side.
        """
        m, c = self.num_slots, out.shape[1]
        # unit r·M + slot: one (relation, slot) of the flattened vector, c columns wide
        units = (torch.arange(self.num_relations, device=slots.device) * m).unsqueeze(1)
        runs, position, width = self._unit_runs((units + slots).flatten())
        x = out.new_zeros(num_views, width, c)
        x = x.index_put((box_view.repeat(self.num_relations), position), out)
        return x.flatten(1), [(start * c, length * c) for start, length in runs]

    def _unit_runs(self, units: Tensor) -> tuple[list[tuple[int, int]], Tensor, int]:
        """The fc's input as runs of (relation, slot) units: the runs ``(start, length)``,
        each of ``units``' position in the runs laid side by side, and their total length.

        On a CPU: the used units, runs at most :data:`RUN_GAP` empty units apart merged. On
        another device: one run of all R·M units, the dense vector (no host sync, one
        product)."""
        total = self.num_relations * self.num_slots
        if units.device.type != "cpu":
            return [(0, total)], units, total
        used = torch.zeros(total, dtype=torch.bool)
        used[units] = True
        ids = used.nonzero().flatten()  # sorted
        apart = ids.diff() > RUN_GAP + 1
        starts = torch.cat((ids[:1], ids[1:][apart]))
        lengths = torch.cat((ids[:-1][apart], ids[-1:])) + 1 - starts
        offsets = lengths.cumsum(0) - lengths  # where each run starts, side by side
        width = int(lengths.sum())
        span = torch.repeat_interleave(starts - offsets, lengths) + torch.arange(width)
        position = torch.full((total,), -1, dtype=torch.long)
        position[span] = torch.arange(width)
        return list(zip(starts.tolist(), lengths.tolist(), strict=True)), position[units], width

    def _node_edges(
        self, box_view: Tensor, slots: Tensor, adjacency: Tensor, num_views: int
    ) -> list[NodeEdges]:
        """Each relation's edges between present nodes, as node ids."""
        if adjacency.layout == torch.sparse_coo:
            adjacency = adjacency.coalesce()
            (view, rel, row, col), weight = adjacency.indices(), adjacency.values()
        else:
            view, rel, row, col = adjacency.nonzero(as_tuple=True)
            weight = adjacency[view, rel, row, col]
        node = torch.full((num_views, self.num_slots), -1, dtype=torch.long, device=slots.device)
        node[box_view, slots] = torch.arange(slots.shape[0], device=slots.device)
        target, source = node[view, row], node[view, col]
        keep = (target >= 0) & (source >= 0)
        return [
            NodeEdges(target[sel], source[sel], weight[sel])
            for sel in (keep & (rel == r) for r in range(self.num_relations))
        ]
