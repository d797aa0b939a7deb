"""SeanNet's training step part by part: forward and backward of each top-level part of the
model (image trunk, head, object features and fcn, the GCN pathways, the GCN's fc, fusion,
layout pathway), the loss and the optimiser, with each part's parameter count
(``bench/train_step.py --profile`` prints it). It knows the model's parts, so it lives beside
the model: a change of :class:`~seannet.model.seannet.SeanNet` that moves a part shows here."""

from __future__ import annotations

import time
from collections import defaultdict
from collections.abc import Callable, Iterator
from contextlib import ExitStack, contextmanager
from pathlib import Path
from typing import Any

import torch
from torch.utils.data import DataLoader

from seannet.data.datasets import ImageTransform, TripletDataset, collate_triplets
from seannet.model.loss import TripletLoss
from seannet.model.seannet import SeanNet
from seannet.training.config import TrainConfig
from seannet.training.runs import build_for_dataset

__all__ = ["PARTS", "PartClock", "profile_step"]

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


def profile_step(config: TrainConfig, data: Path, steps: int) -> dict[str, Any]:
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
