"""SeanNet end to end on CPU: shapes, per-view RoIAlign, slot scatter, batch checks."""

from __future__ import annotations

import io

import pytest
import torch
from torch.nn import functional as F

from seannet import DataError, ModelError, SceneBatch, SeanNet, build_model
from seannet.model.wordvectors import load_table
from sgdata.world.catalog import load_catalog

M = 256
SIZE = 112  # 112² input -> C4 7 x 7 (stride 16)


def _batch(n_objects: tuple[int, ...], *, seed: int = 0, num_classes: int = 102) -> SceneBatch:
    """Views with the given object counts: random images, boxes, classes, slots, graphs."""
    g = torch.Generator().manual_seed(seed)
    b = len(n_objects)
    boxes, views, classes, slots = [], [], [], []
    adjacency = torch.zeros(b, 3, M, M)
    for v, n in enumerate(n_objects):
        uv = torch.randint(0, SIZE // 2, (n, 2), generator=g).float()
        wh = torch.randint(8, SIZE // 2, (n, 2), generator=g).float()
        boxes.append(torch.cat((uv, uv + wh), 1))
        views.append(torch.full((n,), v, dtype=torch.long))
        classes.append(torch.randint(0, num_classes, (n,), generator=g))
        s = torch.randperm(M, generator=g)[:n]
        slots.append(s)
        for r in range(3):  # a random relation graph on the present nodes, row-normalised
            a = (torch.rand(n, n, generator=g) < 0.5).float() + torch.eye(n)
            adjacency[v, r][s.unsqueeze(1), s.unsqueeze(0)] = a / a.sum(1, keepdim=True)
    return SceneBatch(
        images=torch.randn(b, 3, SIZE, SIZE, generator=g),
        boxes=torch.cat(boxes),
        box_view=torch.cat(views),
        class_ids=torch.cat(classes),
        slots=torch.cat(slots),
        adjacency=adjacency,
    )


def _swap_views(batch: SceneBatch) -> SceneBatch:
    """The same two views in the other order (boxes keep their order, views are renamed)."""
    return SceneBatch(
        images=batch.images.flip(0),
        boxes=batch.boxes,
        box_view=1 - batch.box_view,
        class_ids=batch.class_ids,
        slots=batch.slots,
        adjacency=batch.adjacency.flip(0),
    )


@pytest.fixture(scope="module")
def model() -> SeanNet:
    torch.manual_seed(0)
    return build_model("seannet", depth=18, num_slots=M, roi_size=7).eval()


def test_shapes_through_the_network(model: SeanNet) -> None:
    batch = _batch((3, 0))
    with torch.no_grad():
        c4 = model.backbone(batch.images)
        assert c4.shape == (2, 256, 7, 7)  # ResNet-18 C4: 256 channels, 112 / 16 = 7
        assert model.head(c4).shape == (2, 512)
        x = model.object_features(c4, batch)
        assert x.shape == (3, 512)
        x0 = model.node_features(x, batch)
        assert x0.shape == (2, M, 512)
        out = model.embed(batch)
    assert out.shape == (2, 2048 + M * 64)  # the fused vector, then the 8 x 8 layout grids
    assert model.out_dim == out.shape[1]
    assert torch.isfinite(out).all()
    # objects land at (view, slot); every other row is zero, the empty view entirely
    assert torch.equal(x0[batch.box_view, batch.slots], x)
    mask = torch.zeros(2, M, dtype=torch.bool)
    mask[batch.box_view, batch.slots] = True
    assert not x0[~mask].any()
    assert not x0[1].any()


def test_object_fcn_widths_follow_depth() -> None:
    words = torch.randn(5, 300)
    r50 = SeanNet(words, depth=50, num_slots=8, graph_hidden_dim=16)
    assert r50.objects.in_dim == 2048 + 256 + 300  # 2604, paper §IV-B
    assert r50.objects.fcn[0].out_features == 1024 and r50.objects.out_dim == 512
    r18 = SeanNet(words, depth=18, num_slots=8, graph_hidden_dim=16)
    assert r18.objects.in_dim == 512 + 256 + 300
    assert r18.fusion.in_features == 512 + 2048


def test_roi_align_uses_each_views_own_map(model: SeanNet) -> None:
    batch = _batch((3, 2), seed=1)
    with torch.no_grad():
        out = model.embed(batch)
        swapped = model.embed(_swap_views(batch))
        # the authors' bug: every box pooled from the first image gives other features
        c4 = model.backbone(batch.images)
        own = model.object_features(c4, batch)
        first_only = SceneBatch(**{**vars(batch), "box_view": torch.zeros_like(batch.box_view)})
        wrong = model.object_features(c4, first_only)
    assert not torch.allclose(out[0], out[1], atol=1e-4)
    torch.testing.assert_close(swapped[0], out[1], rtol=1e-4, atol=1e-5)
    torch.testing.assert_close(swapped[1], out[0], rtol=1e-4, atol=1e-5)
    on_view1 = batch.box_view == 1
    torch.testing.assert_close(wrong[~on_view1], own[~on_view1])
    assert not torch.allclose(wrong[on_view1], own[on_view1])


def test_views_do_not_leak_into_each_other(model: SeanNet) -> None:
    batch = _batch((3, 0), seed=2)
    alone = SceneBatch(
        images=batch.images[:1],
        boxes=batch.boxes,
        box_view=batch.box_view,
        class_ids=batch.class_ids,
        slots=batch.slots,
        adjacency=batch.adjacency[:1],
    )
    with torch.no_grad():
        torch.testing.assert_close(model.embed(alone)[0], model.embed(batch)[0])


def test_training_step_reaches_every_part() -> None:
    torch.manual_seed(0)
    net = SeanNet(torch.randn(102, 300), depth=18, num_slots=M, roi_size=7, graph_hidden_dim=64)
    net.train()
    out = net.embed(_batch((3, 2), seed=3))
    # a fixed direction: the embedding's parts are unit vectors, their norms carry no gradient
    (out * torch.randn(out.shape, generator=torch.Generator().manual_seed(0))).sum().backward()
    assert net.layout_weight.grad is not None and net.layout_weight.grad != 0
    for name in ("backbone", "head", "objects", "gcn", "fusion", "layout"):
        for param_name, param in getattr(net, name).named_parameters():
            assert param.grad is not None, f"{name}.{param_name}"
            if param.ndim >= 2:  # every weight matrix and kernel learns, not just one of them
                assert param.grad.abs().sum() > 0, f"{name}.{param_name} has no gradient"
    assert not any(n.startswith("objects.word_vectors") for n, _ in net.named_parameters())


def test_state_dict_round_trip_keeps_the_gcn_fc_keys(model: SeanNet) -> None:
    """The GCN fc's first layer reads column runs; its parameters stay nn.Linear's."""
    state = model.state_dict()
    flat, hidden = 3 * M * 8, model.gcn.fc[2].in_features
    assert {k: tuple(v.shape) for k, v in state.items() if k.startswith("gcn.fc.")} == {
        "gcn.fc.0.weight": (hidden, flat),
        "gcn.fc.0.bias": (hidden,),
        "gcn.fc.2.weight": (model.gcn.out_dim, hidden),
        "gcn.fc.2.bias": (model.gcn.out_dim,),
    }
    buffer = io.BytesIO()
    torch.save(state, buffer)
    buffer.seek(0)
    torch.manual_seed(1)
    again = build_model("seannet", depth=18, num_slots=M, roi_size=7).eval()
    again.load_state_dict(torch.load(buffer, weights_only=True))
    batch = _batch((3, 0, 5), seed=4)
    with torch.no_grad():
        assert torch.equal(again.embed(batch), model.embed(batch))


def test_the_layout_pathway_sees_where_the_boxes_are(model: SeanNet) -> None:
    """The embedding's tail is the slot layout: it moves with the boxes, is a unit vector
    times lambda, and the cosine of two views mixes both parts as documented."""
    batch = _batch((3, 2), seed=5)
    moved = SceneBatch(**{**vars(batch), "boxes": batch.boxes + 20.0})
    d = model.embed_dim
    with torch.no_grad():
        a, b = model.embed(batch), model.embed(moved)
    torch.testing.assert_close(a[:, d:].norm(dim=1), model.layout_weight.detach().expand(2))
    assert (a[:, d:] * b[:, d:]).sum(1).max() < 0.99  # boxes 20 px away overlap less
    lam2 = float(model.layout_weight.detach()) ** 2
    mixed = (
        F.cosine_similarity(a[:, :d], b[:, :d]) + lam2 * F.cosine_similarity(a[:, d:], b[:, d:])
    ) / (1 + lam2)
    torch.testing.assert_close(F.cosine_similarity(a, b), mixed)


def test_without_the_layout_pathway_the_graph_branch_is_the_papers() -> None:
    from seannet.training.config import TrainConfig

    torch.manual_seed(0)
    net = build_model("seannet-nolayout", depth=18, num_slots=M, roi_size=7)
    assert net.layout is None and net.out_dim == net.embed_dim == 2048
    assert not any("layout" in n for n, _ in net.named_parameters())
    with torch.no_grad():
        assert net.embed(_batch((2,))).shape == (1, 2048)
    # checkpoints from before ModelConfig stored the model's fields flat, "model" its name;
    # those from before the layout pathway stored no layout_grid: they had none
    nested = TrainConfig().to_dict()
    flat = {**nested, **nested["model"], "model": nested["model"]["name"]}
    del flat["name"]
    legacy = {k: v for k, v in flat.items() if not k.startswith("layout_")}
    assert TrainConfig.from_dict(legacy).model.layout_grid == 0
    assert TrainConfig.from_dict(legacy).model.depth == TrainConfig().model.depth
    # those from before the sketch had an unsketched grid: they load as they were trained
    unsketched = {**flat, "layout_grid": 8}
    del unsketched["layout_sketch"]
    assert TrainConfig.from_dict(unsketched).model.layout_sketch == 0
    assert TrainConfig.from_dict(unsketched).model.layout_grid == 8
    assert TrainConfig.from_dict(TrainConfig().to_dict()) == TrainConfig()
    for field in ("layout_grid", "layout_sketch"):
        with pytest.raises(ModelError, match=field):
            TrainConfig().replace(**{field: -1})


def test_batch_checks(model: SeanNet) -> None:
    batch = _batch((3, 0))
    bad_slot = SceneBatch(**{**vars(batch), "slots": batch.slots.clone().fill_(M)})
    with pytest.raises(DataError, match="slots: value 256 out of range"):
        model.embed(bad_slot)
    same = batch.slots.clone()
    same[1] = same[0]
    with pytest.raises(DataError, match="share a GCN slot"):
        model.embed(SceneBatch(**{**vars(batch), "slots": same}))
    past_last = model.objects.num_classes  # one past the catalog's last class id
    bad_class = SceneBatch(**{**vars(batch), "class_ids": batch.class_ids.clone().fill_(past_last)})
    with pytest.raises(DataError, match="class_ids"):
        model.embed(bad_class)
    with pytest.raises(DataError, match="box_view: shape"):
        SceneBatch(**{**vars(batch), "box_view": batch.box_view[:2]})
    with pytest.raises(DataError, match="adjacency: shape"):
        SceneBatch(**{**vars(batch), "adjacency": batch.adjacency[:, :2]})
    small = SceneBatch(**{**vars(batch), "adjacency": batch.adjacency[:, :, :8, :8]})
    with pytest.raises(ModelError, match="M = 8"):
        model.embed(small)


def test_batch_to_device_keeps_values() -> None:
    batch = _batch((2, 1))
    moved = batch.to("cpu")
    assert moved is not batch
    for k, v in vars(batch).items():  # the tensors, and mean / std (None: float images)
        if isinstance(v, dict):  # the channels, by name (none asked here)
            assert getattr(moved, k).keys() == v.keys()
            assert all(torch.equal(getattr(moved, k)[c], v[c]) for c in v)
        else:
            assert torch.equal(getattr(moved, k), v) if v is not None else getattr(moved, k) is None


def test_factory_checks_names_and_word_vectors() -> None:
    with pytest.raises(ModelError, match="'seanet'.*expected one of seannet"):
        build_model("seanet")
    with pytest.raises(ModelError, match="depth 20"):
        build_model("seannet", depth=20)
    with pytest.raises(DataError, match="'Spaceship' is not in the word-vector table"):
        build_model("seannet", depth=18, class_names=["Mug", "Spaceship"])


def test_word_vectors_are_rows_in_class_id_order() -> None:
    table = load_table()
    names = load_catalog().names()
    net = SeanNet(table.matrix(names), depth=18, num_slots=8, graph_hidden_dim=16)
    assert net.num_classes == len(names)
    mug = names.index("Mug")
    raw = torch.from_numpy(table.vector("Mug"))
    # stored at unit length (raw GloVe norms of 4-8 would outweigh x_v and x_b)
    torch.testing.assert_close(net.objects.word_vectors[mug], raw / raw.norm())
    assert torch.allclose(net.objects.word_vectors.norm(dim=1), torch.ones(len(names)))


def test_layout_class_weights_start_from_the_dynamics_category() -> None:
    from seannet.model.factory import LAYOUT_PRIOR

    catalog = load_catalog()
    net = build_model("seannet", depth=18, num_slots=M, roi_size=7)
    weights = net.layout.class_weight.detach()
    for i, name in enumerate(catalog.names()):
        assert float(weights[i]) == LAYOUT_PRIOR[str(catalog.classes[name].dynamics)]
    assert {float(w) for w in weights} == {1.0, 0.25}  # static and low at 1, high at 0.25
    with pytest.raises(ModelError, match="class dynamics"):
        build_model("seannet", depth=18, class_names=["Cup"], class_dynamics=["low", "high"])
