"""Checkpoints: model and optimiser state with the config and the dataset they belong to."""

from __future__ import annotations

import io
from pathlib import Path
from typing import Any

import torch

from seannet.errors import CheckpointError
from sgdata.fileio import atomic_write_bytes

__all__ = ["save_checkpoint", "load_checkpoint", "check_same_dataset"]

FORMAT = 1  # bump when the checkpoint layout changes


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
