"""The training budget: the same batches on a busy machine as on a quiet one."""

from __future__ import annotations

import subprocess
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest
import torch

from seannet.errors import ModelError
from seannet.training.budget import CPU_CLOCK, calibrate, calibrate_batches
from seannet.training.config import TrainConfig

# ResNet-18 at 64 px, batches of 4: a step in a fraction of a second on one thread
TINY = TrainConfig().replace(
    model="resnet18",
    image_size=64,
    embed_dim=64,
    epochs=2,
    batch_size=4,
    num_workers=0,
)
HOGS = 2  # busy-loop processes beside the calibration: as many as the test machine's cores


@contextmanager
def _busy_machine(processes: int) -> Iterator[None]:
    """``processes`` real busy loops for the duration, killed after."""
    hogs = [subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range(processes)]
    try:
        time.sleep(0.5)  # let them start spinning
        yield
    finally:
        for hog in hogs:
            hog.kill()
        for hog in hogs:
            hog.wait()


def test_a_busy_machine_buys_the_same_batches(mini_dataset: Path) -> None:
    # a budget that buys some tens of batches, so that 10 % is a few of them
    quiet = calibrate(TINY, mini_dataset, 20.0, batches=3, rounds=3)
    threads = torch.get_num_threads()
    with _busy_machine(HOGS):
        busy = calibrate(TINY, mini_dataset, 20.0, batches=3, rounds=3)
    assert torch.get_num_threads() == threads  # the caller's threads are restored
    assert quiet.batches >= 20 and quiet.clock == CPU_CLOCK
    # the hogs did take the cores: the calibration's thread waited for a share of its steps
    assert busy.busy > 0.2
    assert abs(busy.batches - quiet.batches) <= 0.1 * quiet.batches, (quiet, busy)


def test_the_calibration_records_what_the_budget_bought(mini_dataset: Path) -> None:
    c = calibrate(TINY, mini_dataset, 20.0, batches=2, rounds=2)
    first, second = c.steps_s[:2], c.steps_s[2:]  # the rounds, over the same 2 batches
    assert len(c.steps_s) == 4
    assert c.step_s == pytest.approx((min(first[0], second[0]) + min(first[1], second[1])) / 2)
    assert c.batches == int(20.0 / TINY.epochs / c.step_s)
    assert c.examples == c.batches * TINY.batch_size * TINY.epochs
    record = c.to_dict()
    assert record["batches"] == c.batches and record["spread"] == c.spread
    assert record["steps_s"] == list(c.steps_s)


def test_budget_buys_batches(mini_dataset: Path) -> None:
    few = calibrate_batches(TINY, mini_dataset, 0.001)
    many = calibrate_batches(TINY, mini_dataset, 60.0)
    assert few == 1 and many > 10 * few


def test_a_budget_must_be_positive(mini_dataset: Path) -> None:
    with pytest.raises(ModelError, match="budget_s > 0"):
        calibrate(TINY, mini_dataset, 0.0)


def test_the_old_home_still_imports_with_a_warning() -> None:
    from seannet.evaluation import compare

    with pytest.warns(DeprecationWarning, match="seannet.training.budget"):
        old = compare.calibrate_batches
    assert old is calibrate_batches
