"""What one training step costs: SeanNet against its image baseline, and the GCN's two forms.

    python bench/train_step.py DATA [--preset cpu] [--steps 6]

Times, on real triplet batches of DATA's train split (image cache on), a whole training step
(three embeddings, triplet loss, backward, SGD) of ``seannet`` and ``resnet18``, then the
scene-graph branch alone (forward + backward on the batch's object features): the paper's
dense form over B x M slots (``MultiPathwayGCN.forward``) against the present nodes only
(``forward_nodes``, what SeanNet runs). Run it on a quiet machine; figures in
docs/benchmarks.md.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import torch
from torch.utils.data import DataLoader

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from seannet.data.datasets import ImageTransform, TripletDataset, collate_triplets  # noqa: E402
from seannet.model.loss import TripletLoss  # noqa: E402
from seannet.model.seannet import SeanNet  # noqa: E402
from seannet.training.config import preset  # noqa: E402
from seannet.training.runs import build_for_dataset  # noqa: E402


def seconds_per_call(fn, calls: int) -> float:
    fn()  # warm-up: allocator, oneDNN kernels
    start = time.perf_counter()
    for _ in range(calls):
        fn()
    return (time.perf_counter() - start) / calls


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("data", type=Path)
    parser.add_argument("--preset", default="cpu")
    parser.add_argument("--steps", type=int, default=6)
    args = parser.parse_args()
    torch.manual_seed(0)
    figures = {}
    for name in ("resnet18", "seannet"):
        config = preset(args.preset).replace(model=name)
        model = build_for_dataset(config, args.data).train()
        transform = ImageTransform.for_model(config.model.image_size, config.model.image_family)
        triplets = TripletDataset(args.data, "train", transform=transform, cache=True)
        loader = DataLoader(triplets, batch_size=config.batch_size, collate_fn=collate_triplets)
        batches = [next(iter(loader))[:3]]
        optimiser = torch.optim.SGD(model.parameters(), lr=config.lr, momentum=config.momentum)
        loss_fn = TripletLoss(margin=config.margin)

        def step(model=model, batch=batches[0], optimiser=optimiser, loss_fn=loss_fn) -> None:
            loss = loss_fn(*(model.embed(views) for views in batch))
            optimiser.zero_grad()
            loss.backward()
            optimiser.step()

        figures[name] = seconds_per_call(step, args.steps)
        print(f"{name:9s} training step, batch {config.batch_size}: {figures[name]:.3f} s")
        if isinstance(model, SeanNet):
            graph_forms(model, batches[0][0], args.steps)
            with dense_gcn(model):
                dense_step = seconds_per_call(step, args.steps)
            print(
                f"  the same step with the dense GCN: {dense_step:.3f} s "
                f"({dense_step / figures[name]:.2f}x the present-nodes step)"
            )
    print(f"seannet / resnet18 step: {figures['seannet'] / figures['resnet18']:.2f}x")


@contextmanager
def dense_gcn(model: SeanNet) -> Iterator[None]:
    """SeanNet's steps with the paper's dense GCN form (B x M slots) in place of the nodes'."""
    gcn = model.gcn

    def dense(x, box_view, slots, adjacency, *, num_views):
        grid = x.new_zeros(num_views, gcn.num_slots, x.shape[1]).index_put((box_view, slots), x)
        return gcn(grid, adjacency.to_dense() if adjacency.is_sparse else adjacency)

    gcn.forward_nodes = dense
    try:
        yield
    finally:
        del gcn.forward_nodes


def graph_forms(model: SeanNet, views, calls: int) -> None:
    """The GCN branch on one batch of views, dense against present nodes (forward+backward)."""
    compact_adjacency = views.adjacency
    batch = views.prepare()
    with torch.no_grad():
        c4 = model.backbone(batch.images)
        x = model.object_features(c4, batch)
    x.requires_grad_(True)
    dense_x = model.node_features(x, batch)

    def dense() -> None:
        model.gcn(dense_x, batch.adjacency).sum().backward(retain_graph=True)

    def nodes() -> None:
        model.gcn.forward_nodes(
            x, batch.box_view, batch.slots, compact_adjacency, num_views=batch.num_views
        ).sum().backward()

    slow, fast = seconds_per_call(dense, calls), seconds_per_call(nodes, calls)
    print(
        f"  GCN branch, {batch.num_views} views, {x.shape[0]} nodes of "
        f"{batch.num_views * model.num_slots} slots: dense {slow * 1000:.0f} ms, "
        f"present nodes {fast * 1000:.0f} ms ({slow / fast:.1f}x)"
    )


if __name__ == "__main__":
    main()
