"""SeanNet's layers: box positional encoding, GCN layer / pathway / multi-pathway, object fcn,
slot layout."""

from __future__ import annotations

import pytest
import torch
from torch.nn import functional as F

from seannet import ModelError
from seannet.model.layers import (
    BoxEncoding,
    ColumnLinear,
    GCNLayer,
    GCNPathway,
    MultiPathwayGCN,
    ObjectEmbedding,
    SlotLayout,
    box_coverage,
    sinusoidal_encoding,
)


def test_sinusoidal_encoding_matches_the_transformer_formula() -> None:
    pos = torch.tensor([0.0, 3.0, 117.5])
    code = sinusoidal_encoding(pos, 64)
    assert code.shape == (3, 64)
    i = torch.arange(32, dtype=torch.float32)
    angle = pos[:, None] / 10000 ** (2 * i / 64)
    torch.testing.assert_close(code[:, 0::2], angle.sin())
    torch.testing.assert_close(code[:, 1::2], angle.cos())
    assert torch.equal(code[0, 0::2], torch.zeros(32)) and torch.equal(
        code[0, 1::2], torch.ones(32)
    )


def test_box_encoding_dims_and_corner_order() -> None:
    enc = BoxEncoding()
    boxes = torch.tensor([[10.0, 20.0, 30.0, 40.0], [0.0, 0.0, 224.0, 224.0]])
    code = enc(boxes)
    assert enc.out_dim == 256 and code.shape == (2, 256)
    for j in range(4):  # x_b = [PE(u1); PE(v1); PE(u2); PE(v2)]
        torch.testing.assert_close(
            code[:, 64 * j : 64 * (j + 1)], sinusoidal_encoding(boxes[:, j], 64)
        )
    assert not any(True for _ in enc.parameters())


def test_similar_boxes_get_similar_codes() -> None:
    enc = BoxEncoding()
    base = torch.tensor([[40.0, 60.0, 120.0, 150.0]])
    shifts = torch.tensor([0.0, 1.0, 4.0, 30.0, 100.0])
    boxes = base + shifts[:, None]
    sim = F.cosine_similarity(enc(base), enc(boxes), dim=1)
    assert sim[0] == pytest.approx(1.0)
    assert sim[1] > 0.8
    assert torch.all(sim[:3] > sim[1:4])  # less similar as the corners move away ...
    assert sim[-1] < sim[2]  # ... and far boxes (100 px) stay far below near ones (4 px)


@pytest.mark.parametrize("dim", [0, 7, -2])
def test_encoding_rejects_odd_or_empty_dims(dim: int) -> None:
    with pytest.raises(ModelError, match=f"dim_per_coord={dim}"):
        BoxEncoding(dim)


def _row_normalised(a: torch.Tensor) -> torch.Tensor:
    rows = a.sum(-1, keepdim=True)
    return torch.where(rows > 0, a / rows.clamp(min=1e-12), torch.zeros_like(a))


def test_gcn_layer_is_a_hat_x_w() -> None:
    torch.manual_seed(0)
    layer = GCNLayer(5, 3)
    x = torch.randn(2, 4, 5)
    a = _row_normalised(torch.rand(2, 4, 4))
    ref = torch.stack([a[i] @ x[i] @ layer.weight for i in range(2)])
    torch.testing.assert_close(layer(x, a), ref)
    assert layer.bias is None


def test_gcn_keeps_absent_nodes_zero_and_adjacency_unchanged() -> None:
    torch.manual_seed(0)
    m, present = 10, torch.tensor([1, 4, 7])
    x = torch.zeros(1, m, 16)
    x[0, present] = torch.randn(3, 16)
    a = torch.zeros(1, m, m)
    a[0][present.unsqueeze(1), present.unsqueeze(0)] = torch.rand(3, 3) + 0.1
    a = _row_normalised(a)
    a_before = a.clone()
    pathway = GCNPathway((16, 8, 4, 2), dropout=0.2).eval()
    out = pathway(x, a)
    assert out.shape == (1, m, 2)
    absent = torch.ones(m, dtype=torch.bool)
    absent[present] = False
    assert not out[0, absent].any()
    assert torch.equal(a, a_before)  # the GCN reads Â, never renormalises it in place
    torch.testing.assert_close(a.sum(-1)[0, present], torch.ones(3))


def test_row_normalised_adjacency_averages_neighbours() -> None:
    layer = GCNLayer(3, 3)
    with torch.no_grad():
        layer.weight.copy_(torch.eye(3))
    x = torch.tensor([[[1.0, 0, 0], [0, 2.0, 0], [0, 0, 3.0]]])
    a = _row_normalised(torch.ones(1, 3, 3))
    torch.testing.assert_close(
        layer(x, a), torch.full((1, 3, 3), 1 / 3) * torch.tensor([1, 2, 3.0])
    )


def test_multi_pathway_gcn_shapes_and_paper_widths() -> None:
    gcn = MultiPathwayGCN(num_slots=12, dims=(32, 16, 8, 4), hidden_dim=20, out_dim=10).eval()
    x = torch.randn(2, 12, 32)
    a = _row_normalised(torch.rand(2, 3, 12, 12))
    assert gcn(x, a).shape == (2, 10)
    assert gcn.fc[0].in_features == 3 * 12 * 4
    paper = MultiPathwayGCN(hidden_dim=8)  # M = 256, 512 -> 256 -> 64 -> 8: 3 x 2048 = 6144
    assert paper.fc[0].in_features == 6144 and paper.out_dim == 2048
    assert [layer.out_dim for layer in paper.pathways[0].layers] == [256, 64, 8]
    with pytest.raises(ModelError, match="expected"):
        gcn(x, a[:, :2])


def test_gcn_dropout_only_in_training() -> None:
    torch.manual_seed(0)
    pathway = GCNPathway((8, 8), dropout=0.5)
    x = torch.rand(1, 6, 8) + 1
    a = _row_normalised(torch.ones(1, 6, 6))
    pathway.eval()
    assert torch.equal(pathway(x, a), pathway(x, a))
    pathway.train()
    assert not torch.equal(pathway(x, a), pathway(x, a))
    with pytest.raises(ModelError, match="dropout=1.0"):
        GCNPathway(dropout=1.0)


def test_object_embedding_widths_and_fixed_word_vectors() -> None:
    words = torch.randn(4, 300)
    emb = ObjectEmbedding(words, 2048)
    assert emb.in_dim == 2604 and emb.out_dim == 512
    out = emb(torch.randn(3, 2048), torch.tensor([[0.0, 0, 5, 5]] * 3), torch.tensor([0, 3, 3]))
    assert out.shape == (3, 512) and (out >= 0).all()  # ReLU after the last layer too
    assert "word_vectors" in dict(emb.named_buffers())
    assert "word_vectors" not in dict(emb.named_parameters())
    with pytest.raises(ModelError, match="word_vectors: shape"):
        ObjectEmbedding(torch.randn(300), 2048)


# ------------------------------------------------------------------------------ slot layout


def test_box_coverage_is_the_share_of_each_cell() -> None:
    boxes = torch.tensor(
        [
            [0.0, 0.0, 16.0, 16.0],  # exactly the top-left cell of a 4 x 4 grid on 64 px
            [0.0, 0.0, 64.0, 64.0],  # the whole image
            [40.0, 8.0, 56.0, 24.0],  # half of each of 4 cells across and down: 1/4 each
        ]
    )
    cells = box_coverage(boxes, 64, 64, 4).view(3, 4, 4)
    assert torch.equal(cells[0], F.one_hot(torch.tensor(0), 16).view(4, 4).float())
    assert torch.equal(cells[1], torch.ones(4, 4))
    expected = torch.zeros(4, 4)
    expected[0:2, 2:4] = 0.25
    torch.testing.assert_close(cells[2], expected)
    # a non-square frame: u is scaled by the width, v by the height
    wide = box_coverage(torch.tensor([[0.0, 0.0, 32.0, 16.0]]), 64, 128, 4).view(4, 4)
    assert torch.equal(wide, F.one_hot(torch.tensor(0), 16).view(4, 4).float())


def test_slot_layout_compares_the_same_objects_boxes() -> None:
    """Same box in the same slot: the class weight squared; a shifted box less; another slot
    or an absent object nothing; and the weights learn."""
    layout = SlotLayout(num_slots=6, num_classes=3, grid=4)
    boxes = torch.tensor(
        [[0.0, 0.0, 32.0, 32.0], [0.0, 0.0, 32.0, 32.0], [8.0, 0.0, 40.0, 32.0], [0, 0, 32, 32]]
    )
    out = layout(
        boxes,
        box_view=torch.tensor([0, 1, 2, 3]),
        slots=torch.tensor([2, 2, 2, 4]),
        class_ids=torch.tensor([1, 1, 1, 1]),
        num_views=5,
        height=64,
        width=64,
    )
    assert out.shape == (5, layout.out_dim) and layout.out_dim == 6 * 16
    same, shifted, other_slot = out[0] @ out[1], out[0] @ out[2], out[0] @ out[3]
    torch.testing.assert_close(same, torch.tensor(1.0))
    assert 0.0 < shifted < same and other_slot == 0.0
    assert torch.equal(out[4], torch.zeros(layout.out_dim))  # a view with no objects
    same.backward()
    grad = layout.class_weight.grad
    assert grad[1] > 0 and grad[0] == 0 and grad[2] == 0  # only the class in view learns
    with pytest.raises(ModelError, match="grid=0"):
        SlotLayout(4, 2, grid=0)


def test_sketched_slot_layout_keeps_the_dot_products() -> None:
    """The count sketch keeps every pair's similarity within its standard error, draws the
    same hash every time and saves it with the model."""
    g = torch.Generator().manual_seed(0)
    views, per_view, dim = 40, 12, 4096
    corner = torch.rand(10, per_view, 2, generator=g) * 48  # 10 scenes, each seen 4 times
    size = 4 + torch.rand(10, per_view, 2, generator=g) * 12
    jitter = torch.rand(views, per_view, 2, generator=g) * 4
    corner = corner.repeat(4, 1, 1) + jitter
    boxes = torch.cat((corner, corner + size.repeat(4, 1, 1)), 2).flatten(0, 1)
    args = dict(
        box_view=torch.arange(views).repeat_interleave(per_view),
        slots=torch.cat([torch.randperm(20, generator=g)[:per_view] for _ in range(10)] * 4),
        class_ids=torch.zeros(views * per_view, dtype=torch.long),
        num_views=views,
        height=64,
        width=64,
    )
    exact = F.normalize(SlotLayout(20, 1, grid=16)(boxes, **args), dim=1)
    sketch = SlotLayout(20, 1, grid=16, sketch_dim=dim)
    approx = F.normalize(sketch(boxes, **args), dim=1)
    assert approx.shape == (views, dim) and sketch.out_dim == dim
    error = (approx @ approx.T - exact @ exact.T).abs()
    assert error.mean() < (2 / dim) ** 0.5 and error.max() < 5 * (2 / dim) ** 0.5
    assert (exact @ exact.T).fill_diagonal_(0).max() > 0.5  # the views do share boxes
    again = SlotLayout(20, 1, grid=16, sketch_dim=dim)
    assert torch.equal(again.sketch_bucket, sketch.sketch_bucket)
    assert {"sketch_bucket", "sketch_sign"} <= set(sketch.state_dict())
    with pytest.raises(ModelError, match="sketch_dim=-1"):
        SlotLayout(4, 2, sketch_dim=-1)


def _graph_batch(seed: int) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor, torch.Tensor]:
    """Present nodes (box_view, slots), their features and a row-normalised (B, 3, M, M)
    adjacency with edges among each view's present nodes only."""
    g = torch.Generator().manual_seed(seed)
    b, m = 3, 12
    box_view = torch.tensor([0, 0, 0, 1, 1, 2, 2, 2, 2])
    slots = torch.tensor([1, 4, 7, 0, 11, 2, 3, 5, 9])
    x = torch.randn(len(slots), 32, generator=g)
    a = torch.zeros(b, 3, m, m)
    for v in range(b):
        s = slots[box_view == v]
        mask = torch.rand(3, len(s), len(s), generator=g) < 0.5
        a[v][:, s.unsqueeze(1), s.unsqueeze(0)] = mask * (torch.rand(mask.shape, generator=g) + 0.1)
    return box_view, slots, x, _row_normalised(a)


@pytest.mark.parametrize("sparse", [False, True])
def test_gcn_on_present_nodes_equals_the_dense_form(sparse: bool) -> None:
    torch.manual_seed(0)
    gcn = MultiPathwayGCN(num_slots=12, dims=(32, 16, 8, 4), hidden_dim=20, out_dim=10).eval()
    box_view, slots, x, a = _graph_batch(0)
    dense_x = torch.zeros(3, 12, 32).index_put((box_view, slots), x)
    adjacency = a.to_sparse() if sparse else a
    out = gcn.forward_nodes(x, box_view, slots, adjacency, num_views=3)
    torch.testing.assert_close(out, gcn(dense_x, a))
    assert out.abs().sum() > 0


def test_gcn_on_present_nodes_learns_every_pathway() -> None:
    torch.manual_seed(0)
    gcn = MultiPathwayGCN(num_slots=12, dims=(32, 16, 8, 4), hidden_dim=20, out_dim=10).train()
    box_view, slots, x, a = _graph_batch(1)
    x.requires_grad_(True)
    gcn.forward_nodes(x, box_view, slots, a, num_views=3).sum().backward()
    assert x.grad is not None and x.grad.abs().sum() > 0
    for pathway in gcn.pathways:
        assert all(layer.weight.grad.abs().sum() > 0 for layer in pathway.layers)


def test_gcn_on_present_nodes_ignores_edges_of_empty_slots_and_checks_shapes() -> None:
    gcn = MultiPathwayGCN(num_slots=12, dims=(32, 16, 8, 4), hidden_dim=20, out_dim=10).eval()
    box_view, slots, x, a = _graph_batch(2)
    stray = a.clone()
    stray[0, 2, 1, 6] = 0.5  # slot 6 of view 0 holds no node
    torch.testing.assert_close(
        gcn.forward_nodes(x, box_view, slots, stray, num_views=3),
        gcn.forward_nodes(x, box_view, slots, a, num_views=3),
    )
    with pytest.raises(ModelError, match="expected"):
        gcn.forward_nodes(x, box_view, slots, a[:, :2], num_views=3)


def _views(
    box_view: list[int], slots: list[int], num_views: int, seed: int
) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor, torch.Tensor]:
    """The given nodes, random features and a row-normalised (B, 3, 12, 12) adjacency with
    edges among each view's present nodes only."""
    g = torch.Generator().manual_seed(seed)
    view, slot = torch.tensor(box_view, dtype=torch.long), torch.tensor(slots, dtype=torch.long)
    a = torch.zeros(num_views, 3, 12, 12)
    for v in range(num_views):
        s = slot[view == v]
        mask = torch.rand(3, len(s), len(s), generator=g) < 0.5
        a[v][:, s.unsqueeze(1), s.unsqueeze(0)] = mask * (torch.rand(mask.shape, generator=g) + 0.1)
    return view, slot, torch.randn(len(slot), 32, generator=g), _row_normalised(a)


FC_CASES = {  # (box_view, slots, B) of M = 12; runs of used slots with gaps above RUN_GAP
    "empty views": ([1, 1, 1, 3, 3], [0, 5, 6, 5, 11], 4),
    "a view with every slot": ([0] * 12 + [1], [*range(12), 3], 3),
    "repeated slots across views": (
        [0, 0, 0, 1, 1, 1, 1, 2, 2, 2],
        [2, 7, 8, 0, 2, 7, 8] + [2, 7, 8],
        3,
    ),
    "no node at all": ([], [], 2),
}


@pytest.mark.parametrize("case", FC_CASES)
@pytest.mark.parametrize("sparse", [False, True])
def test_gcn_fc_on_used_slots_equals_the_dense_form_with_its_gradients(
    case: str, sparse: bool
) -> None:
    torch.manual_seed(0)
    gcn = MultiPathwayGCN(num_slots=12, dims=(32, 16, 8, 4), hidden_dim=20, out_dim=10).eval()
    box_view, slots, x, a = _views(*FC_CASES[case], seed=3)
    first = gcn.fc[0]
    grads = []
    for form in ("dense", "nodes"):
        gcn.zero_grad(set_to_none=True)
        nodes = x.clone().requires_grad_(True)
        if form == "dense":
            grid = nodes.new_zeros(a.shape[0], 12, 32).index_put((box_view, slots), nodes)
            out = gcn(grid, a)
        else:
            adjacency = a.to_sparse() if sparse else a
            out = gcn.forward_nodes(nodes, box_view, slots, adjacency, num_views=a.shape[0])
        (out * torch.linspace(-1, 1, out.numel()).view(out.shape)).sum().backward()
        grads.append((out.detach(), first.weight.grad, first.bias.grad, nodes.grad))
    (dense, *dense_grads), (got, *got_grads) = grads
    torch.testing.assert_close(got, dense, rtol=1e-5, atol=1e-6)
    for name, g, ref in zip(("W1", "b1", "node features"), got_grads, dense_grads, strict=True):
        assert g is not None and ref is not None, name
        torch.testing.assert_close(g, ref, rtol=1e-5, atol=1e-6, msg=lambda m, n=name: f"{n}: {m}")
    assert dense.abs().sum() > 0
    assert (first.weight.grad.abs().sum() > 0) == (len(slots) > 0)


def test_gcn_fc_is_bit_reproducible() -> None:
    gcn = MultiPathwayGCN(num_slots=12, dims=(32, 16, 8, 4), hidden_dim=20, out_dim=10).train()
    box_view, slots, x, a = _views(*FC_CASES["empty views"], seed=4)
    runs = []
    for _ in range(2):
        torch.manual_seed(1)  # dropout
        gcn.zero_grad(set_to_none=True)
        out = gcn.forward_nodes(x, box_view, slots, a, num_views=4)
        out.sum().backward()
        runs.append((out.detach(), gcn.fc[0].weight.grad))
    assert all(torch.equal(u, v) for u, v in zip(*runs, strict=True))


def test_gcn_state_dict_is_the_nn_linear_one() -> None:
    """Checkpoints written before the fc read column runs load unchanged."""
    torch.manual_seed(0)
    gcn = MultiPathwayGCN(num_slots=12, dims=(32, 16, 8, 4), hidden_dim=20, out_dim=10).eval()
    old_fc = torch.nn.Sequential(
        torch.nn.Linear(3 * 12 * 4, 20), torch.nn.ReLU(), torch.nn.Linear(20, 10), torch.nn.ReLU()
    )
    assert {k: v.shape for k, v in gcn.fc.state_dict().items()} == {
        k: v.shape for k, v in old_fc.state_dict().items()
    }
    gcn.fc.load_state_dict(old_fc.state_dict())
    box_view, slots, x, a = _views(*FC_CASES["empty views"], seed=5)
    grid = torch.zeros(4, 12, 32).index_put((box_view, slots), x)
    flat = torch.cat([p(grid, a[:, r]).flatten(1) for r, p in enumerate(gcn.pathways)], 1)
    torch.testing.assert_close(
        gcn.forward_nodes(x, box_view, slots, a, num_views=4), old_fc(flat), rtol=1e-5, atol=1e-6
    )


@pytest.mark.parametrize("bias", [True, False])
def test_column_linear_on_runs_is_the_linear_of_the_zero_filled_input(bias: bool) -> None:
    torch.manual_seed(0)
    layer = ColumnLinear(10, 6, bias=bias)
    runs, columns = [(1, 2), (3, 1), (7, 3)], torch.tensor([1, 2, 3, 7, 8, 9])
    g = torch.randn(4, 6)
    results = []
    for form in ("runs", "full"):
        layer.zero_grad(set_to_none=True)
        x = torch.randn(4, 6, generator=torch.Generator().manual_seed(1)).requires_grad_(True)
        if form == "runs":
            out = layer(x, runs)
        else:
            out = layer(torch.zeros(4, 10).index_copy(1, columns, x))
        (out * g).sum().backward()
        bias_grad = layer.bias.grad if bias else None
        results.append((out.detach(), x.grad, layer.weight.grad, bias_grad))
    for got, ref in zip(*results, strict=True):
        torch.testing.assert_close(got, ref)
    assert not results[0][2][:, [0, 4, 5, 6]].any()  # columns outside the runs: zero gradient


def test_column_linear_checks_runs() -> None:
    layer = ColumnLinear(10, 6)
    empty = layer(torch.zeros(3, 0), [])
    torch.testing.assert_close(empty, layer.bias.expand(3, 6))
    for runs in ([(2, 3), (4, 1)], [(8, 3)], [(1, 0)], [(-1, 2)]):
        with pytest.raises(ModelError, match="runs"):
            layer(torch.zeros(3, sum(n for _, n in runs)), runs)
    with pytest.raises(ModelError, match=r"expected \(B, 3\)"):
        layer(torch.zeros(3, 4), [(0, 3)])
