"""``seannet compare``: train every model with one preset and budget, evaluate, one table."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

from seannet.config import preset as load_preset
from seannet.errors import ModelError
from seannet.eval_run import evaluate_run
from seannet.train import LAST, train
from sgdata.fileio import atomic_write_text

__all__ = ["COMPARISON", "compare_models"]

COMPARISON = "comparison.json"  # the results, one entry per model, under the output directory


def compare_models(
    data: Path,
    out: Path,
    models: list[str],
    *,
    preset: str = "cpu",
    split: str = "test",
    announce: Callable[[str], None] | None = None,
) -> list[dict[str, Any]]:
    """Train (or resume) one run per model under ``out/<model>``, evaluate each on ``split``.

    A run that already has a checkpoint resumes from it, so an interrupted comparison picks up
    where it stopped. Writes ``out/comparison.json`` atomically and returns its entries.

    Raises:
        ModelError: no model named.
    """
    if not models:
        raise ModelError("--models is empty: name at least one model, e.g. seannet,resnet18")
    rows = []
    for name in models:
        run = out / name
        config = load_preset(preset).replace(model=name)
        if announce is not None:
            announce(f"training {name} ({preset} preset) -> {run}")
        train(config, data, run, resume=(run / LAST).exists())
        rows.append(evaluate_run(run, data, split=split))
    atomic_write_text(out / COMPARISON, json.dumps(rows, indent=2))
    return rows
