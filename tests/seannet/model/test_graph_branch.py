"""The scene-graph branch carries signal: every pathway sees its edges, gradients reach every
pathway, and a graph-only SeanNet learns."""

from __future__ import annotations

from pathlib import Path

import pytest
import torch

from seannet.data.batch import SceneBatch
from seannet.data.view_inputs import graph_tensors
from seannet.model.factory import build_model
from seannet.training.config import TrainConfig
from seannet.training.train import train

M = 16
SIZE = 64


def _view_with_one_edge(relation: int) -> SceneBatch:
    """Two objects (a mug on / in / beside a table) and exactly one edge of ``relation``."""
    objects = [
        {"instance": 1, "class_id": 3, "slot": 2, "box2d": [4, 30, 60, 60]},
        {"instance": 2, "class_id": 5, "slot": 7, "box2d": [20, 18, 32, 31]},
    ]
    edges = [{"src": 2, "dst": 1, "type": relation}]
    if relation == 2:  # proximity is stored both ways
        edges.append({"src": 1, "dst": 2, "type": relation})
    slots, class_ids, boxes, adjacency = graph_tensors(objects, edges, num_slots=M)
    g = torch.Generator().manual_seed(0)  # one image for every relation: only the edge differs
    return SceneBatch(
        images=torch.randn(1, 3, SIZE, SIZE, generator=g),
        boxes=boxes,
        box_view=torch.zeros(len(objects), dtype=torch.long),
        class_ids=class_ids,
        slots=slots,
        adjacency=adjacency.unsqueeze(0),
    )


@pytest.mark.parametrize("relation", [0, 1, 2], ids=["on", "in", "proximity"])
def test_every_pathway_has_output_and_gradient(relation: int) -> None:
    torch.manual_seed(0)
    model = build_model("seannet", depth=18, num_slots=M, roi_size=4, embed_dim=64)
    batch = _view_with_one_edge(relation)
    outputs = {}
    hooks = [
        p.register_forward_hook(lambda _m, _i, out, r=r: outputs.__setitem__(r, out))
        for r, p in enumerate(model.gcn.pathways)
    ]
    out = model.embed(batch)
    # a fixed direction, not the squared norm: the embedding's parts are unit vectors, whose
    # norms carry no gradient
    (out * torch.randn(out.shape, generator=torch.Generator().manual_seed(1))).sum().backward()
    for hook in hooks:
        hook.remove()
    for r, pathway in enumerate(model.gcn.pathways):
        assert outputs[r].abs().sum() > 0, f"pathway {r} outputs zero"
        for layer in pathway.layers:
            assert layer.weight.grad is not None and layer.weight.grad.abs().sum() > 0
    # the edge's own pathway differs from what self-loops alone give
    alone = _view_with_one_edge(3)  # a disjoint edge: not fed, self-loops only
    model.eval()
    with torch.no_grad():
        edge = model.gcn.pathways[relation](
            model.node_features(model.object_features(model.backbone(batch.images), batch), batch),
            batch.adjacency[:, relation],
        )
        loops = model.gcn.pathways[relation](
            model.node_features(model.object_features(model.backbone(alone.images), alone), alone),
            alone.adjacency[:, relation],
        )
    assert not torch.allclose(edge, loops)


@pytest.mark.slow  # two SeanNets trained until the graph branch alone tells views apart
@pytest.mark.parametrize("layout_grid", [8, 0], ids=["layout", "gcn-only"])
def test_graph_only_seannet_learns(tmp_path: Path, mini_dataset: Path, layout_grid: int) -> None:
    """Without the image vector in the fusion, SeanNet still learns the training triplets:
    the loss falls and accuracy ends above chance, with and without the layout pathway."""
    config = TrainConfig().replace(
        layout_grid=layout_grid,
        model="seannet-graph",
        graph_hidden=512,  # the cpu preset's GCN fc width: a step a third of the paper's 4,096
        depth=18,
        image_size=64,
        roi_size=4,
        visual_features="c5",
        embed_dim=128,
        epochs=6,
        batch_size=5,
        lr=0.02,
        max_train_batches=4,
        num_workers=0,
        decay_every=10,
    )
    results = train(config, mini_dataset, tmp_path / "graph")
    assert results[-1].train_loss < results[0].train_loss
    assert max(r.train_accuracy for r in results[-2:]) > 0.6


def test_graph_hidden_sets_the_fc_width_and_a_train_config_carries_it() -> None:
    from seannet.errors import ModelError
    from seannet.model.config import ModelConfig
    from seannet.training.config import TrainConfig, preset

    model = build_model(
        ModelConfig(depth=18, roi_size=4, embed_dim=64, graph_hidden=32), num_slots=M
    )
    first, last = model.gcn.fc[0], model.gcn.fc[2]
    assert (first.out_features, last.in_features, last.out_features) == (32, 32, 64)
    assert model.embed(_view_with_one_edge(0)).shape[0] == 1
    config = TrainConfig().replace(model="seannet", graph_hidden=1024)
    assert TrainConfig.from_dict(config.to_dict()).model.graph_hidden == 1024
    # the paper's 4,096 by default; the cpu preset's seannet-fc512 stores its own 512
    assert preset("paper").model.graph_hidden == 4096
    assert preset("cpu").model.graph_hidden == 512
    with pytest.raises(ModelError, match="graph_hidden"):
        ModelConfig(graph_hidden=0)
