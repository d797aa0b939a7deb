"""The localizers maps and the navigation test use: a trained run (its model, image size and
threshold epsilon), or any method (:class:`seannet.methods.MethodLocalizer`).

The paper's localizer (§V-D, §VI-B) says "same place" when S(current, goal) > epsilon. A run's
epsilon is the one ``seannet eval`` chose on the validation split (``eval_<split>.json``,
``threshold.epsilon``); ``--epsilon`` gives one where the run has not been evaluated.

:func:`open_localizer` takes whatever names a localizer on the command line: a run directory
(``best.pt``), a method directory (``method.json``: every benchmark card directory) or a
method's name; each gives ``name``, ``source``, ``digest``, ``identity``, ``epsilon``,
``epsilon_source``, ``transform``, ``embed(views)`` and ``similarities(vector, rows)``.
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import torch

from seannet.data.datasets import ImageTransform, ViewTensors, collate_views
from seannet.data.opening import DataSource, open_dataset
from seannet.errors import NavigationError
from seannet.evaluation.run_eval import eval_file
from seannet.methods.localizer import METHOD_FILE, MethodLocalizer, open_method
from seannet.training.config import TrainConfig
from seannet.training.loop import collect, embed_batch
from seannet.training.runs import restore_run
from sgdata.fileio import sha256_file

__all__ = ["AnyLocalizer", "Localizer", "load_localizer", "open_localizer", "run_epsilon"]

EVAL_SPLITS = ("val", "test")  # eval files searched for epsilon, in this order, then any other
BATCH = 16  # views embedded per forward pass


@dataclass
class Localizer:
    """A run ready to embed views (eval mode) and to judge "same place" by epsilon."""

    run: Path
    name: str  # the run's model name (seannet, resnet18, ...)
    model: torch.nn.Module
    config: TrainConfig
    epsilon: float
    epsilon_source: str  # the eval file it came from, or "--epsilon"
    identity: dict[str, Any]  # the dataset the run was trained on
    digest: str  # sha256 of the checkpoint: maps record it
    device: torch.device

    @property
    def source(self) -> str:
        """What names this localizer: the run directory, resolved."""
        return str(self.run.resolve())

    def similarities(self, vector: np.ndarray, rows: np.ndarray) -> np.ndarray:
        """(N,) cosine similarity of one unit vector of :meth:`embed` to each of ``rows``."""
        return rows @ vector

    @property
    def transform(self) -> ImageTransform:
        """The run's image transform (its input size)."""
        model = self.config.model
        return ImageTransform.for_model(model.image_size, model.image_family)

    def embed(self, views: Sequence[ViewTensors]) -> np.ndarray:
        """Unit embeddings (N, D) float32 of views, in batches of 16."""
        if not views:
            return np.zeros((0, self.model.out_dim), dtype=np.float32)
        batches = (
            collate_views(list(views[start : start + BATCH]))
            for start in range(0, len(views), BATCH)
        )
        vectors = collect(self.model, batches, embed_batch(self.model, self.device))
        return vectors.numpy().astype(np.float32)


def run_epsilon(run: Path) -> tuple[float, str] | None:
    """The threshold ``seannet eval`` chose for ``run``, and the file it is read from.

    ``eval_val.json``, then ``eval_test.json``, then any other ``eval_*.json``; files whose
    epsilon is missing or NaN are skipped. None when no file has one.
    """
    names = [eval_file(run, s).name for s in EVAL_SPLITS]
    others = sorted(p.name for p in run.glob("eval_*.json") if p.name not in names)
    for name in [*names, *others]:
        path = run / name
        if not path.is_file():
            continue
        try:
            value = json.loads(path.read_text())["threshold"]["epsilon"]
        except (ValueError, KeyError, TypeError):
            continue
        if isinstance(value, int | float) and math.isfinite(value):
            return float(value), name
    return None


def load_localizer(
    run: Path,
    data: DataSource,
    *,
    epsilon: float | None = None,
    source: str = "--epsilon",
    require_epsilon: bool = True,
) -> Localizer:
    """``run/best.pt`` on ``data`` (the dataset it was trained on) as a localizer.

    Args:
        run: the run directory.
        data: the dataset the run was trained on (opened already, or its root).
        epsilon: the threshold to use; None reads the run's eval files (:func:`run_epsilon`).
        source: where a given ``epsilon`` comes from (reported beside it).
        require_epsilon: without one, raise (True) or leave epsilon NaN (building maps).

    Raises:
        CheckpointError: no checkpoint, or it was trained on another dataset.
        NavigationError: no epsilon given and the run has no evaluated threshold.
    """
    ds = open_dataset(data)
    restored = restore_run(run, ds)
    if epsilon is None:
        found = run_epsilon(run)
        if found is None and not require_epsilon:
            found = (float("nan"), "none")
        if found is None:
            raise NavigationError(
                f"{run}: no eval_<split>.json with threshold.epsilon; run `seannet eval {run} "
                f"--data {ds.root} --split test` first, or pass --epsilon"
            )
        epsilon, source = found
    if require_epsilon and not math.isfinite(epsilon):
        raise NavigationError(f"epsilon {epsilon}: expected a finite number")
    return Localizer(
        run=run,
        name=restored.config.model.name,
        model=restored.model,
        config=restored.config,
        epsilon=float(epsilon),
        epsilon_source=source,
        identity=restored.state["dataset"],
        digest=sha256_file(restored.path)[0],
        device=restored.device,
    )


AnyLocalizer = Localizer | MethodLocalizer


def open_localizer(
    target: str | Path,
    data: DataSource,
    *,
    epsilon: float | None = None,
    source: str = "--epsilon",
    require_epsilon: bool = True,
) -> AnyLocalizer:
    """The localizer ``target`` names: a method directory (``method.json``, e.g. a benchmark
    card's) or a method name (:func:`seannet.methods.localizer.open_method`), else a run
    directory (:func:`load_localizer`). Arguments as :func:`load_localizer`'s.

    Raises:
        CheckpointError, NavigationError: as :func:`load_localizer`, for a run.
        MethodError: as :func:`~seannet.methods.localizer.open_method`, for a method.
    """
    path = Path(target)
    text = str(target)
    if not path.is_dir() and "/" in text and ":" not in text:
        raise NavigationError(f"{text}: no such run or method directory")
    if (path / METHOD_FILE).is_file() or not path.is_dir():
        return open_method(target, data, epsilon=epsilon, source=source,
                           require_epsilon=require_epsilon)  # fmt: skip
    return load_localizer(path, data, epsilon=epsilon, source=source,
                          require_epsilon=require_epsilon)  # fmt: skip
