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
(:func:`profile_step`): forward and backward of each top-level part of the model (image trunk,
head, object features and fcn, the GCN pathways, the GCN's fc, fusion, layout pathway), the
loss and the optimiser, with each part's parameter count. ``--batch-size`` overrides the
preset's batch (a quick look). Run it on a quiet machine.
"""

from __future__ import annotations

import argparse
import json
import time
from collections import defaultdict
from collections.abc import Callable, Iterator, Sequence
from contextlib import ExitStack, contextmanager
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


PROFILE_RANGE = "seannet-part:"  # prefix of the profiler ranges that mark a part's forward
# The parts of SeanNet's step, in the order the forward runs them: (key, label).
PARTS: tuple[tuple[str, str], ...] = (
    ("backbone", "image trunk to C4 (backbone)"),
    ("head", "5th stage + pool of the image (head)"),
    ("visual", "object visual features (object_features: RoIAlign{head_on_crops})"),
    ("objects", "object fcn: visual, box PE, word vector (objects)"),
    ("pathways", "GCN pathways on the present nodes (gcn.pathways)"),
    ("fc", "GCN fc {fc_dims} (gcn.fc)"),
    ("gcn", "GCN rest: edge lists, scatter to slots (gcn.forward_nodes)"),
    ("fusion", "fusion: LayerNorms + linear (image_norm, graph_norm, fusion)"),
    ("layout", "layout pathway (layout, layout_weight)"),
    ("rest", "rest of the forward: batch prepare / validate, concat, normalise"),
    ("loss", "triplet loss (TripletLoss)"),
    ("autograd", "autograd engine: gradient accumulation, unattributed"),
    ("optimiser", "optimiser: zero_grad + SGD step"),
)


class PartClock:
    """Exclusive forward time per part (a part's time less that of the parts inside it); each
    part's forward also opens a profiler range, which names the part of every autograd node
    created inside it (for the backward)."""

    def __init__(self) -> None:
        self.seconds: dict[str, float] = defaultdict(float)
        self.stack: list[list[Any]] = []  # [part, start, seconds of parts inside, range]

    def enter(self, part: str) -> None:
        span = torch.profiler.record_function(PROFILE_RANGE + part)
        span.__enter__()
        self.stack.append([part, time.perf_counter(), 0.0, span])

    def exit(self) -> None:
        part, start, inner, span = self.stack.pop()
        span.__exit__(None, None, None)
        elapsed = time.perf_counter() - start
        self.seconds[part] += elapsed - inner
        if self.stack:
            self.stack[-1][2] += elapsed

    def head_part(self) -> str:
        """The head runs on the image (its own part) and, with ``c4_head``, on every RoI crop
        (object visual features)."""
        return "visual" if any(frame[0] == "visual" for frame in self.stack) else "head"


@contextmanager
def timed_parts(model: SeanNet, loss_fn: torch.nn.Module, clock: PartClock) -> Iterator[None]:
    """SeanNet's parts timed by ``clock`` for the block: hooks on its modules, wrappers on the
    methods that are not module calls (``embed``, ``object_features``, ``forward_nodes``)."""
    modules: list[tuple[torch.nn.Module, Callable[[], str]]] = [
        (model.backbone, lambda: "backbone"),
        *((m, clock.head_part) for m in (model.head, *model.head)),  # head[1:] calls children
        (model.objects, lambda: "objects"),
        *((p, lambda: "pathways") for p in model.gcn.pathways),
        *((m, lambda: "fc") for m in model.gcn.fc),  # forward_nodes calls them one by one
        *((m, lambda: "fusion") for m in (model.image_norm, model.graph_norm, model.fusion)),
        (loss_fn, lambda: "loss"),
    ]
    if model.layout is not None:
        modules.append((model.layout, lambda: "layout"))
    methods = [(model, "embed", "rest"), (model, "object_features", "visual")]
    methods.append((model.gcn, "forward_nodes", "gcn"))
    with ExitStack() as stack:
        for module, part in modules:
            pre = module.register_forward_pre_hook(lambda m, a, part=part: clock.enter(part()))
            post = module.register_forward_hook(lambda m, a, o: clock.exit())
            stack.callback(pre.remove)
            stack.callback(post.remove)
        for owner, name, part in methods:
            method = getattr(owner, name)

            def timed(*args: Any, method: Callable = method, part: str = part, **kwargs: Any):  # noqa: ANN202
                clock.enter(part)
                try:
                    return method(*args, **kwargs)
                finally:
                    clock.exit()

            setattr(owner, name, timed)  # an instance attribute over the class's method
            stack.callback(delattr, owner, name)
        yield


def backward_seconds(events: Any) -> dict[str, float]:
    """Seconds of backward per part: each autograd node's evaluation, booked to the part whose
    forward created it (the same sequence number; the innermost part range around it)."""
    evaluate = "autograd::engine::evaluate_function: "
    part_of: dict[int, str] = {}
    events = sorted(events, key=lambda e: e.time_range.start)  # a node's forward comes first
    for event in events:
        if event.sequence_nr < 0 or event.name.startswith(evaluate) or event.sequence_nr in part_of:
            continue
        parent = event.cpu_parent
        while parent is not None and not parent.name.startswith(PROFILE_RANGE):
            parent = parent.cpu_parent
        part_of[event.sequence_nr] = parent.name[len(PROFILE_RANGE) :] if parent else "rest"
    seconds: dict[str, float] = defaultdict(float)
    for event in events:
        if event.name.startswith(evaluate) and event.sequence_nr in part_of:
            seconds[part_of[event.sequence_nr]] += event.cpu_time_total / 1e6
    return seconds


def parameters_by_part(model: SeanNet) -> dict[str, int]:
    def count(*modules: torch.nn.Module | None) -> int:
        return sum(p.numel() for m in modules if m is not None for p in m.parameters())

    layout = count(model.layout) + (model.layout_weight.numel() if model.layout is not None else 0)
    return {
        "backbone": count(model.backbone),
        "head": count(model.head),
        "objects": count(model.objects),
        "pathways": count(model.gcn.pathways),
        "fc": count(model.gcn.fc),
        "fusion": count(model.image_norm, model.graph_norm, model.fusion),
        "layout": layout,
    }


def profile_step(config: Any, data: Path, steps: int) -> dict:
    """SeanNet's training step (three embeddings, triplet loss, backward, SGD) on a real batch
    of ``data``'s train split, part by part: forward (perf_counter around each part, less the
    parts inside it) and backward (torch.profiler: each autograd node's evaluation booked to
    the part that created it), averaged over ``steps`` steps after one warm-up step."""
    model = build_for_dataset(config, data).train()
    transform = ImageTransform.for_model(config.model.image_size, config.model.image_family)
    triplets = TripletDataset(data, "train", transform=transform, cache=True)
    loader = DataLoader(triplets, batch_size=config.batch_size, collate_fn=collate_triplets)
    batch = next(iter(loader))[:3]
    optimiser = torch.optim.SGD(model.parameters(), lr=config.lr, momentum=config.momentum)
    loss_fn = TripletLoss(margin=config.margin)
    wall: dict[str, float] = defaultdict(float)

    def step(record: bool) -> None:
        start = time.perf_counter()
        loss = loss_fn(*(model.embed(views) for views in batch))
        forward = time.perf_counter()
        optimiser.zero_grad()
        zeroed = time.perf_counter()
        loss.backward()
        backward = time.perf_counter()
        optimiser.step()
        if record:
            wall["forward"] += forward - start
            wall["backward"] += backward - zeroed
            wall["optimiser"] += (zeroed - forward) + (time.perf_counter() - backward)

    step(False)  # warm-up: allocator, oneDNN kernels
    clock = PartClock()
    activities = [torch.profiler.ProfilerActivity.CPU]
    with timed_parts(model, loss_fn, clock), torch.profiler.profile(activities=activities) as prof:
        for _ in range(steps):
            step(True)
    forward = dict(clock.seconds)
    forward["rest"] = wall["forward"] - sum(v for k, v in forward.items() if k != "rest")
    backward = backward_seconds(prof.events())
    backward["autograd"] = wall["backward"] - sum(backward.values())
    params = parameters_by_part(model)
    fc = [m for m in model.gcn.fc if isinstance(m, torch.nn.Linear)]
    names = {
        "fc_dims": " -> ".join(
            f"{n:,}" for n in (fc[0].in_features, *(m.out_features for m in fc))
        ),
        "head_on_crops": ", head on every crop" if model.visual_features == "c4_head" else " on C5",
    }
    total = sum(wall.values())
    parts = []
    for key, label in PARTS:
        f = forward.get(key, 0.0) / steps
        b = backward.get(key, 0.0) / steps
        o = wall["optimiser"] / steps if key == "optimiser" else 0.0
        parts.append(
            {
                "part": key,
                "label": label.format(**names),
                "forward_s": f,
                "backward_s": b,
                "total_s": f + b + o,
                "share": (f + b + o) / (total / steps),
                "parameters": params.get(key, 0),
            }
        )
    attributed = sum(v for k, v in backward.items() if k != "autograd")
    return {
        "steps": steps,
        "batch_size": config.batch_size,
        "step_s": total / steps,
        "forward_s": wall["forward"] / steps,
        "backward_s": wall["backward"] / steps,
        "optimiser_s": wall["optimiser"] / steps,
        "backward_attributed": attributed / wall["backward"],
        "parameters": sum(p.numel() for p in model.parameters()),
        "parts": parts,
    }


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
