"""A run directory: its file names, checkpoints (model and optimiser state with the config and
the dataset they belong to), the device runs use, and restoring a trained model from a run."""

from __future__ import annotations

import io
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import torch

from seannet.data.opening import DataSource, dataset_identity, open_dataset
from seannet.errors import CheckpointError
from seannet.model.factory import build_model
from seannet.training.config import TrainConfig
from sgdata.fileio import atomic_write_bytes

__all__ = [
    "BEST",
    "HISTORY",
    "LAST",
    "MODEL_KEYS",
    "RestoredRun",
    "build_for_dataset",
    "check_same_dataset",
    "device_for_run",
    "load_checkpoint",
    "restore_run",
    "save_checkpoint",
]

FORMAT = 1  # bump when the checkpoint layout changes
# a run directory: the last epoch (whole, to resume), the best val epoch (model only), history
LAST, BEST, HISTORY = "last.pt", "best.pt", "history.json"
# What a model depends on in a dataset's identity (dataset_identity): a split of real photos
# is checked on these only, since it is never the dataset the run trained on.
MODEL_KEYS = ("format_version", "num_slots", "vocabulary_sha256")


def device_for_run() -> torch.device:
    """CUDA when present, else the CPU."""
    return torch.device("cuda" if torch.cuda.is_available() else "cpu")


def build_for_dataset(  # noqa: ANN201
    config: TrainConfig,
    root: DataSource,
    *,
    pretrained: Path | None = None,
    pretrained_sha256: str | None = None,
):
    """The model of ``config`` sized for the dataset ``root`` (an opened dataset or its root):
    its class vocabulary, M."""
    dataset = open_dataset(root)
    return build_model(
        config.model,
        num_slots=dataset.manifest.num_slots,
        class_names=list(dataset.class_names),
        class_dynamics=[c.dynamics for c in dataset.manifest.classes],
        pretrained=pretrained,
        pretrained_sha256=pretrained_sha256,
    )


@dataclass
class RestoredRun:
    """A trained model read back from ``run/best.pt``, ready on its device (eval mode)."""

    path: Path  # the checkpoint file
    config: TrainConfig
    model: torch.nn.Module
    device: torch.device
    state: dict[str, Any]


def restore_run(run: Path, data: DataSource, *, keys: Sequence[str] | None = None) -> RestoredRun:
    """``run/best.pt`` built for ``data`` (an opened dataset or its root) with its trained
    weights.

    Args:
        keys: the dataset identity fields that must match the run's (default: all of them;
            :data:`MODEL_KEYS` for a dataset the run was never trained on, e.g. photos).

    Raises:
        CheckpointError: no checkpoint, or it was trained on another dataset.
    """
    dataset = open_dataset(data)
    path = run / BEST
    state = load_checkpoint(path)
    saved, current = state["dataset"], dataset_identity(dataset)
    if keys is not None:
        saved = {k: saved.get(k) for k in keys}
        current = {k: current.get(k) for k in keys}
    check_same_dataset(path, saved, current)
    config = TrainConfig.from_dict(state["config"])
    device = device_for_run()
    model = build_for_dataset(config, dataset).to(device)
    model.load_state_dict(state["model"])
    return RestoredRun(path, config, model.eval(), device, state)


def save_checkpoint(path: Path, state: dict[str, Any]) -> None:
    """Write ``state`` (plain data and tensors) atomically."""
    buffer = io.BytesIO()
    torch.save({"format": FORMAT, **state}, buffer)
    atomic_write_bytes(path, buffer.getvalue())


def load_checkpoint(path: Path) -> dict[str, Any]:
    """Read a checkpoint written by :func:`save_checkpoint`.

    Raises:
        CheckpointError: missing, unreadable, or of another checkpoint format.
    """
    if not path.is_file():
        raise CheckpointError(f"{path}: no checkpoint here (train first, or check the run dir)")
    try:
        state = torch.load(path, map_location="cpu", weights_only=False)
    except Exception as exc:  # torch raises many types for a damaged file
        raise CheckpointError(f"{path}: unreadable checkpoint ({type(exc).__name__})") from None
    if not isinstance(state, dict) or state.get("format") != FORMAT:
        raise CheckpointError(f"{path}: not a seannet checkpoint of format {FORMAT}")
    return state


def check_same_dataset(path: Path, saved: dict[str, Any], current: dict[str, Any]) -> None:
    """Refuse a dataset other than the one a checkpoint was trained on.

    Raises:
        CheckpointError: naming the first field that differs.
    """
    for key in sorted(set(saved) | set(current)):
        if saved.get(key) != current.get(key):
            raise CheckpointError(
                f"{path}: trained on dataset {key}={saved.get(key)!r}, but this dataset has "
                f"{key}={current.get(key)!r}; use the dataset it was trained on"
            )
