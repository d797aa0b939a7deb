"""The training budget: how many batches per epoch a budget of seconds buys a network, timed so
that the machine's load does not change the answer.

A budget of ``S`` seconds means ``S`` seconds of *one CPU thread's* compute for the whole run
(every epoch's training steps, the loader's reads included). A step is timed with torch on one
thread and the thread's own CPU clock (:func:`time.thread_time`): other processes on the
machine take turns on the cores but never run on this thread's clock, and with one thread there
are no OpenMP workers to spin-wait and burn CPU without progress (the process-CPU clock divided
by torch's threads, used before, gave SeanNet 9 batches per epoch beside another job against 28
on a quiet machine). The same few batches are trained in several rounds; a step's cost is the
mean over the batches of each one's fastest round, and how far the rounds disagree (the
spread) is recorded, and ``compare`` warns when it is high. What load still does: a busy core
slows a thread through its caches even on the thread's own clock: beside two busy loops on
the two cores of the docs' machine the batches came out within 4 % of quiet when nothing else
ran, and 5 to 16 % fewer when several other jobs already shared the cores (the old clock:
a third to a quarter).
On a GPU the steps are timed on the wall clock (after a synchronise): the GPU is the load.

The seconds are one thread's, whatever threads the run itself will use: a run on two cores
trains its budget in about half the wall time. A budget buys far fewer batches than the same
number bought when the calibration divided process time by torch's threads: 300 s of one
thread bought seannet-fc512 7 batches per epoch on the docs' machine of 2026-12-02 (a step
7.5 s), where the old 150 had recorded 35. Seconds are the machine's own: on the machine of
2026-12-03 a step took 3.1 s and 300 s bought 19 batches, so runs on two machines are
compared by their recorded batches, not by their budgets (``seannet compare`` puts a network
timed on a later machine in the first machine's seconds: :meth:`Calibration.converted`).

The calibration is a measurement, so two on the same machine may differ by a few per cent:
what a run got is recorded (:meth:`Calibration.to_dict`, in ``selection.json``) and reused,
so a rerun trains exactly the same.
"""

from __future__ import annotations

import itertools
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import asdict, dataclass, replace
from typing import Any

import numpy as np
import torch
from torch.utils.data import DataLoader

from seannet.data.datasets import ImageTransform, TripletDataset, collate_triplets
from seannet.data.opening import DataSource, open_dataset
from seannet.errors import ModelError
from seannet.model.loss import TripletLoss
from seannet.training.config import TrainConfig
from seannet.training.loop import train_one_epoch, triplet_step
from seannet.training.runs import build_for_dataset, device_for_run
from seannet.training.train import param_groups

__all__ = [
    "CPU_CLOCK",
    "GPU_CLOCK",
    "SPREAD_WARNING",
    "Calibration",
    "calibrate",
    "calibrate_batches",
]

CPU_CLOCK = "thread-cpu, 1 torch thread"  # what a CPU calibration's seconds are
GPU_CLOCK = "wall, cuda synchronised"
SPREAD_WARNING = 0.25  # a spread above this: compare warns that the timing was disturbed
_BATCHES = 3  # distinct batches timed per round
_ROUNDS = 2  # rounds over the same batches; each batch's fastest counts


@dataclass(frozen=True)
class Calibration:
    """What a budget bought one network, and the measurement it rests on."""

    budget_s: float  # the run's budget: seconds of one thread's compute (GPU: wall seconds)
    batches: int  # per epoch
    examples: int  # training triplets over the run: batches x batch size x epochs
    step_s: float  # one step's cost (each batch's fastest round), the loader's read included
    steps_s: tuple[float, ...]  # every timed step, round after round
    spread: float  # how much slower the slowest round was than the fastest (0.1: 10 %)
    busy: float  # share of the steps' wall time spent on other work (0 on a quiet machine)
    clock: str  # CPU_CLOCK or GPU_CLOCK
    # when the step was timed on another machine than the runs' first calibration and put in
    # that machine's seconds (:meth:`converted`): the reference network's step there and here
    converted_by: dict[str, Any] | None = None

    @property
    def noisy(self) -> bool:
        """The rounds disagree by more than :data:`SPREAD_WARNING`: the timing was disturbed."""
        return self.spread > SPREAD_WARNING

    def to_dict(self) -> dict[str, Any]:
        """Plain form for ``selection.json``."""
        return {**asdict(self), "steps_s": list(self.steps_s)}

    def converted(
        self, reference: str, then_s: float, now_s: float, config: TrainConfig
    ) -> Calibration:
        """This calibration in the seconds of the machine where ``reference`` (a network the
        runs' budget was first timed for) took ``then_s`` a step; here it takes ``now_s``.
        Seconds are the machine's own (a step took 2.9 s on one session's machine and 4.4 s
        on the next's), so a network timed on a later machine gets the batches the first
        machine's seconds buy it: what its runs are compared with trained by that rule."""
        step = self.step_s * then_s / now_s
        per_epoch = _per_epoch(self.budget_s, config, step)
        return replace(
            self,
            batches=per_epoch,
            examples=per_epoch * config.batch_size * config.epochs,
            step_s=step,
            converted_by={
                "reference": reference,
                "reference_then_s": then_s,
                "reference_now_s": now_s,
                "timed_s": self.step_s,
            },
        )

    @classmethod
    def from_dict(cls, record: dict[str, Any]) -> Calibration:
        """The calibration :meth:`to_dict` wrote."""
        return cls(**{**record, "steps_s": tuple(record["steps_s"])})


@contextmanager
def _one_thread() -> Iterator[None]:
    """torch on one thread (the caller's) for the duration; the thread count is restored."""
    threads = torch.get_num_threads()
    torch.set_num_threads(1)
    try:
        yield
    finally:
        torch.set_num_threads(threads)


def calibrate(
    config: TrainConfig,
    data: DataSource,
    budget_s: float,
    *,
    batches: int = _BATCHES,
    rounds: int = _ROUNDS,
) -> Calibration:
    """Batches per epoch that fill ``budget_s`` seconds of one thread's compute.

    The first ``batches`` batches of ``data``'s train triplets (in the split's order) are
    trained ``rounds`` times over, after one untimed warm-up step; a step's cost is the mean
    over the batches of each batch's fastest round. Every round does the same work, so the
    rounds differ only by what the machine did meanwhile, and the fastest is the one least
    disturbed. The model starts from a fixed seed; the caller's torch threads are restored
    afterwards.

    Raises:
        ModelError: ``budget_s``, ``batches`` or ``rounds`` not positive.
    """
    if budget_s <= 0 or batches < 1 or rounds < 1:
        raise ModelError(
            f"calibration: budget_s > 0, batches >= 1 and rounds >= 1, got {budget_s}, "
            f"{batches} and {rounds}"
        )
    torch.manual_seed(0)
    device = device_for_run()
    gpu = device.type == "cuda"
    clock = time.perf_counter if gpu else time.thread_time
    marks: list[tuple[float, float]] = []

    def mark(*_args: Any) -> None:
        if gpu:
            torch.cuda.synchronize()  # kernels run asynchronously: time them, not the launch
        marks.append((clock(), time.perf_counter()))

    with _one_thread():
        dataset = open_dataset(data)
        model = build_for_dataset(config, dataset).to(device)
        optimizer = torch.optim.SGD(param_groups(model, config), lr=config.lr, momentum=0.9)
        triplets = TripletDataset(
            dataset,
            "train",
            transform=ImageTransform.for_model(config.model.image_size, config.model.image_family),
        )
        loader = DataLoader(triplets, batch_size=config.batch_size, collate_fn=collate_triplets)
        step = triplet_step(model, TripletLoss(margin=config.margin), device)
        train_one_epoch(model, itertools.islice(loader, 1), step, optimizer)  # warm-up
        timed = []
        for _ in range(rounds):
            # each round reads its batches again (the loader's read counts: a run pays for
            # it too) and times each step from the mark before it
            marks.clear()
            mark()
            train_one_epoch(
                model, itertools.islice(loader, batches), step, optimizer, progress=mark
            )
            timed.append(np.diff(np.array(marks), axis=0))
    steps = np.stack(timed)  # (rounds, batches, [clock, wall])
    # each batch's fastest round: the same work, least disturbed by the machine's other work
    cost = float(steps[:, :, 0].min(axis=0).mean())
    per_round = steps[:, :, 0].mean(axis=1)
    per_epoch = _per_epoch(budget_s, config, cost)
    return Calibration(
        budget_s=float(budget_s),
        batches=per_epoch,
        examples=per_epoch * config.batch_size * config.epochs,
        step_s=cost,
        steps_s=tuple(float(s) for s in steps[:, :, 0].ravel()),
        spread=float((per_round.max() - per_round.min()) / per_round.min()),
        busy=0.0 if gpu else float(max(0.0, 1.0 - steps[..., 0].sum() / steps[..., 1].sum())),
        clock=GPU_CLOCK if gpu else CPU_CLOCK,
    )


def _per_epoch(budget_s: float, config: TrainConfig, step_s: float) -> int:
    """Batches per epoch whose steps fill ``budget_s`` over the run's epochs (at least one)."""
    return max(1, int(budget_s / config.epochs / step_s))


def calibrate_batches(config: TrainConfig, data: DataSource, budget_s: float) -> int:
    """Batches per epoch that fill ``budget_s`` (:func:`calibrate`'s ``batches``)."""
    return calibrate(config, data, budget_s).batches
