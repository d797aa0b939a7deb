"""Fixtures of the localization and navigation tests: a tiny trained localizer run."""

from __future__ import annotations

from pathlib import Path

import pytest

from seannet.training.config import TrainConfig
from seannet.training.train import train

# A localizer run in seconds: the ResNet-18 baseline at 64 px, one batch of two triplets.
TINY_LOCALIZER = TrainConfig().replace(
    model="resnet18",
    image_size=64,
    embed_dim=64,
    epochs=1,
    batch_size=2,
    max_train_batches=1,
    num_workers=0,
)


# SeanNet in seconds: ResNet-18 at 64 px, an 8 x 8 layout pathway, one batch of four triplets.
TINY_SEANNET = TrainConfig().replace(
    depth=18,
    image_size=64,
    roi_size=4,
    visual_features="c5",
    embed_dim=64,
    layout_grid=8,
    layout_sketch=0,
    epochs=1,
    batch_size=4,
    max_train_batches=1,
    num_workers=0,
)


@pytest.fixture
def tiny_seannet() -> TrainConfig:
    """A SeanNet training config that runs in seconds on the CPU."""
    return TINY_SEANNET


@pytest.fixture(scope="session")
def localizer_run(tmp_path_factory: pytest.TempPathFactory, mini_dataset: Path) -> Path:
    """A run directory (best.pt) trained on the mini dataset; no eval file, so no epsilon."""
    run = tmp_path_factory.mktemp("localizer") / "run"
    train(TINY_LOCALIZER, mini_dataset, run)
    return run
