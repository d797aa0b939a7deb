"""Boxes a detector proposes on a photo before a person labels it (``sgdata label --detector``).

sgdata knows no detector. A detector's run directory names the function that opens it, in its
``detector.json``::

    "proposer": "package.module:function"

(``seannet detector train`` writes ``seannet.detection.proposer:open_proposer``). The function
takes the run directory and returns a callable from a photo's pixels as shown (an (H, W, 3)
uint8 RGB array) to :class:`ProposedBox` rows. :func:`open_proposer` checks what comes back,
keeps the boxes of at least ``min_score`` with a class the labeler knows, and clips them to the
photo, so a detector's slip is a box left out, not a label that cannot be saved.
"""

from __future__ import annotations

import importlib
import json
import math
import numbers
import threading
from collections.abc import Callable, Collection
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from sgdata.errors import ConfigError, one_line

__all__ = ["DEFAULT_MIN_SCORE", "DETECTOR_JSON", "BoxProposer", "ProposedBox", "open_proposer"]

DETECTOR_JSON = "detector.json"
# the boxes worth a look: deleting a wrong box costs a key, finding a missed one costs a drag
DEFAULT_MIN_SCORE = 0.5


@dataclass(frozen=True)
class ProposedBox:
    """One detection: a class name, the pixel box [u1, v1, u2, v2] and the detector's score."""

    class_name: str
    box: tuple[float, float, float, float]
    score: float


Detect = Callable[[np.ndarray], list[ProposedBox]]


class BoxProposer:
    """The boxes a run's detector proposes on a photo, checked, filtered and best first."""

    def __init__(self, run: Path, detect: Detect, *, min_score: float, known: Collection[str]):
        self.run, self._detect, self.min_score = run, detect, min_score
        self._known = set(known)
        self._lock = threading.Lock()  # one photo at a time: the server's threads share it

    def __call__(self, pixels: np.ndarray) -> list[ProposedBox]:
        """The boxes proposed on ``pixels`` ((H, W, 3) uint8), best score first.

        Raises:
            ConfigError: the detector failed or returned something that is not boxes.
        """
        height, width = pixels.shape[:2]
        with self._lock:
            try:
                found = list(self._detect(pixels))
            except Exception as exc:  # noqa: BLE001 - a detector of any library
                failed = f"{type(exc).__name__}: {one_line(exc)}"
                raise ConfigError(f"--detector {self.run}: detection failed: {failed}") from None
        kept = []
        for k, item in enumerate(found):
            values, problem = _box_values(item)
            if problem:
                raise ConfigError(
                    f"--detector {self.run}: result {k} {problem}; expected a "
                    "sgdata.label.box_proposer.ProposedBox (class_name: str, box: 4 numbers, "
                    "score: a number)"
                )
            *corners, score = values
            # NaN or infinite corners or score, an unknown class: a slip, left out
            if not all(math.isfinite(x) for x in values) or score < self.min_score:
                continue
            if item.class_name not in self._known:
                continue
            u1, v1, u2, v2 = (round(x) for x in corners)
            u1, u2 = max(0, min(u1, width)), max(0, min(u2, width))
            v1, v2 = max(0, min(v1, height)), max(0, min(v2, height))
            if u2 - u1 >= 2 and v2 - v1 >= 2:
                kept.append(ProposedBox(item.class_name, (u1, v1, u2, v2), score))
        return sorted(kept, key=lambda b: -b.score)


def _number(value: object) -> bool:
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


def _float(value: numbers.Real) -> float:
    """A real number as a float; an integer too large for one is infinite (a slip)."""
    try:
        return float(value)
    except OverflowError:
        return math.inf if value > 0 else -math.inf


def _box_values(item: object) -> tuple[list[float], str]:
    """A detector's result as its box's four corners and its score, or what keeps it from
    being a box (the detector is broken, not slipping, so the labeler hears of it)."""
    if not isinstance(item, ProposedBox):
        return [], f"is {type(item).__name__}"
    if not isinstance(item.class_name, str):
        return [], f"has a class_name of type {type(item.class_name).__name__}"
    if not _number(item.score):
        return [], f"has a score of type {type(item.score).__name__}"
    try:
        corners = list(item.box)
    except TypeError:
        return [], f"has a box of type {type(item.box).__name__}"
    if len(corners) != 4:
        return [], f"has a box of {len(corners)} values"
    wrong = next((x for x in corners if not _number(x)), None)
    if wrong is not None:
        return [], f"has a box corner of type {type(wrong).__name__}"
    return [_float(x) for x in (*corners, item.score)], ""


def open_proposer(run: Path, *, min_score: float, known: Collection[str]) -> BoxProposer:
    """The proposer of the detector run ``run``, keeping boxes of score >= ``min_score`` whose
    class is in ``known`` (the labeler's class names).

    Raises:
        ConfigError: no run, no ``proposer`` in its ``detector.json``, a path that does not
            import, or a function that fails to open the run.
    """
    if not 0.0 <= min_score <= 1.0:
        raise ConfigError(f"--min-score {min_score}: expected a score in [0, 1]")
    record_path = Path(run) / DETECTOR_JSON
    try:
        record = json.loads(record_path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise ConfigError(
            f"--detector {run}: no {DETECTOR_JSON}; expected a detector run "
            "(seannet detector train --out RUN)"
        ) from None
    except (OSError, ValueError, RecursionError) as exc:  # RecursionError: nested too deeply
        raise ConfigError(f"{record_path}: not readable JSON ({exc})") from None
    target = record.get("proposer") if isinstance(record, dict) else None
    if not isinstance(target, str) or target.count(":") != 1:
        raise ConfigError(
            f"{record_path}: proposer: expected an import path 'package.module:function' "
            "that opens this run (seannet's runs: 'seannet.detection.proposer:open_proposer')"
        )
    where, attr = target.split(":")
    try:
        opener = getattr(importlib.import_module(where), attr)
        detect = opener(Path(run))
    except Exception as exc:  # noqa: BLE001 - a detector package of any kind
        raise ConfigError(
            f"{record_path}: proposer {target!r} failed: {type(exc).__name__}: {one_line(exc)}"
        ) from None
    return BoxProposer(Path(run), detect, min_score=min_score, known=known)
