"""What one training step costs each network, timed by the training budget's own rule.

    python bench/train_step.py DATA [--models resnet18,seannet] [--budget 1200] [--json]
    python bench/train_step.py DATA --gcn-forms [--steps 6]  # SeanNet's GCN: dense vs nodes
    python bench/train_step.py DATA --profile [--steps 3]    # where SeanNet's step goes

By default, every network that docs/results.md trains (the protocol's networks,
:data:`seannet.protocol.design.DESIGN`; ``--models`` names others) is timed by
:func:`seannet.training.budget.calibrate`, the function that sets a run's batches: torch on one
thread, the thread's own CPU clock, each batch's fastest of two rounds, on real triplet batches
of DATA's train split. Each network's step, the rounds' spread, the share of wall time that
went to other work, the batches per epoch ``--budget`` seconds buy it, and its step against
the first network's: the same figures a comparison's budget table prints, so the two cannot
disagree (a wall-clock timing on all threads once said seannet-fc512's step was 1.19x
ResNet-18's where the calibration gave 1.8x).

``--gcn-forms`` times SeanNet's step on the wall clock (torch's threads), then its scene-graph
branch alone (forward + backward on the batch's object features): the paper's dense form over
B x M slots (``MultiPathwayGCN.forward``) against the present nodes only (``forward_nodes``,
what SeanNet runs). ``--profile`` instead times SeanNet's step part by part
(:func:`seannet.training.step_profile.profile_step`): forward and backward of each top-level
part of the model, the loss and the optimiser, with each part's parameter count.
``--batch-size`` overrides the preset's batch (a quick look). Run it on a quiet machine.
"""

from __future__ import annotations

import argparse
import json
import time
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import torch
from torch.utils.data import DataLoader

from seannet.data.datasets import ImageTransform, TripletDataset, collate_triplets
from seannet.errors import ModelError
from seannet.evaluation.compare import model_spec
from seannet.model.loss import TripletLoss
from seannet.model.seannet import SeanNet
from seannet.protocol.design import DESIGN, network_of
from seannet.training.budget import calibrate
from seannet.training.config import DEFAULT_PRESET, TrainConfig, preset
from seannet.training.loop import train_one_epoch, triplet_step
from seannet.training.runs import build_for_dataset
from seannet.training.step_profile import profile_step
from seannet.training.step_table import step_table
from sgdata.markdown import table

# the networks docs/results.md trains (a scene term adds no training step), ResNet-18 first
RESULTS_NETWORKS = tuple(
    dict.fromkeys(
        ["resnet18", *(n for n in (network_of(r.method) for r in DESIGN.rows) if n is not None)]
    )
)


def seconds_per_call(fn, calls: int) -> float:
    fn()  # warm-up: allocator, oneDNN kernels
    start = time.perf_counter()
    for _ in range(calls):
        fn()
    return (time.perf_counter() - start) / calls


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("data", type=Path)
    parser.add_argument("--preset", default=DEFAULT_PRESET)
    parser.add_argument(
        "--models",
        type=lambda text: text.split(","),
        default=list(RESULTS_NETWORKS),
        help="comma-separated networks, the first the others are measured against",
    )
    parser.add_argument("--budget", type=float, default=1200.0, help="seconds of one thread")
    parser.add_argument("--json", action="store_true", help="the figures as one JSON line")
    parser.add_argument("--steps", type=int, default=6, help="--gcn-forms, --profile: steps")
    parser.add_argument("--gcn-forms", action="store_true", help="SeanNet's GCN, dense vs nodes")
    parser.add_argument("--profile", action="store_true", help="SeanNet's step, part by part")
    parser.add_argument("--batch-size", type=int, help="triplets a batch (default: the preset's)")
    args = parser.parse_args()
    torch.manual_seed(0)
    base = preset(args.preset)
    if args.batch_size:
        base = base.replace(batch_size=args.batch_size)
    if args.profile:
        seannet = base.replace(model="seannet")
        print(profile_report(profile_step(seannet, args.data, args.steps), seannet))
    elif args.gcn_forms:
        gcn_forms(base.replace(model="seannet"), args.data, args.steps)
    else:
        try:
            figures = step_costs(args.data, args.models, base, args.budget)
        except ModelError as error:  # an unknown network: the registry's choices, one line
            raise SystemExit(f"--models: {error}") from None
        print(json.dumps(figures) if args.json else step_report(figures))


def step_costs(
    data: Path, models: Sequence[str], base: TrainConfig, budget_s: float
) -> dict[str, Any]:
    """Each network's step as the budget times it, and what ``budget_s`` buys it."""
    configs = [model_spec(spec, base).config for spec in models]  # a bad name before timing
    timed = [calibrate(config, data, budget_s) for config in configs]
    rows = [
        {
            "network": spec,
            "step_s": got.step_s,
            "spread": got.spread,
            "busy": got.busy,
            "batches": got.batches,
            "examples": got.examples,
            "step_ratio": got.step_s / timed[0].step_s,
        }
        for spec, got in zip(models, timed, strict=True)
    ]
    return {
        "budget_s": budget_s,
        "batch_size": base.batch_size,
        "epochs": base.epochs,
        "clock": timed[0].clock,
        "networks": rows,
    }


def step_report(figures: dict[str, Any]) -> str:
    """:func:`step_costs` as a markdown table."""
    lines = [
        f"A training step of {figures['batch_size']} triplets, timed by the budget's rule "
        f"({figures['clock']}); batches per epoch that {figures['budget_s']:g} s buy over "
        f"{figures['epochs']} epochs",
        "",
        *step_table(figures["networks"]),
    ]
    return "\n".join(lines)


def gcn_forms(config: TrainConfig, data: Path, steps: int) -> None:
    """SeanNet's step on the wall clock, and with the dense GCN; its GCN branch alone."""
    model = build_for_dataset(config, data).train()
    transform = ImageTransform.for_model(config.model.image_size, config.model.image_family)
    triplets = TripletDataset(data, "train", transform=transform, cache=True)
    loader = DataLoader(triplets, batch_size=config.batch_size, collate_fn=collate_triplets)
    batches = [next(iter(loader))]
    optimiser = torch.optim.SGD(model.parameters(), lr=config.lr, momentum=config.momentum)
    triplets_step = triplet_step(model, TripletLoss(margin=config.margin), torch.device("cpu"))

    def step() -> None:
        train_one_epoch(model, batches, triplets_step, optimiser)  # the step every run trains by

    nodes_step = seconds_per_call(step, steps)
    with dense_gcn(model):
        dense_step = seconds_per_call(step, steps)
    print(
        f"seannet training step, batch {config.batch_size}: {nodes_step:.3f} s; with the dense "
        f"GCN {dense_step:.3f} s ({dense_step / nodes_step:.2f}x the present-nodes step)"
    )
    graph_forms(model, batches[0][0], steps)


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


def profile_report(result: dict, config: Any) -> str:
    """The profile as a markdown table, one row per part, and the step's totals."""
    m = config.model
    lines = [
        f"SeanNet training step, part by part: ResNet-{m.depth}, {m.image_size} px, "
        f"visual features {m.visual_features}, batch {result['batch_size']} triplets, "
        f"mean of {result['steps']} step(s): {result['step_s']:.3f} s (forward "
        f"{result['forward_s']:.3f} s, backward {result['backward_s']:.3f} s, optimiser "
        f"{result['optimiser_s']:.3f} s)",
        "",
    ]
    rows = [
        (
            p["label"],
            f"{1000 * p['forward_s']:.1f}",
            f"{1000 * p['backward_s']:.1f}",
            f"{1000 * p['total_s']:.1f}",
            f"{100 * p['share']:.1f} %",
            f"{p['parameters']:,}",
        )
        for p in result["parts"]
    ]
    step = (
        "**step**",
        f"**{1000 * result['forward_s']:.1f}**",
        f"**{1000 * result['backward_s']:.1f}**",
        f"**{1000 * result['step_s']:.1f}**",
        "100 %",
        f"**{result['parameters']:,}**",
    )
    header = ("part", "forward ms", "backward ms", "total ms", "share", "parameters")
    lines += [
        *table(header, [*rows, step]),
        "",
        f"backward booked to a part: {100 * result['backward_attributed']:.1f} % (the rest: the "
        "autograd engine, gradient accumulation); times under torch.profiler, which adds a "
        "little to every op",
    ]
    return "\n".join(lines)


if __name__ == "__main__":
    main()
