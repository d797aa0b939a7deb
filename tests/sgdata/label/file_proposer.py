"""A detector whose boxes come from its run's ``boxes.json``: the plug-in contract of
``sgdata label --detector`` with boxes a test chooses (seannet's trained detector, the real
one, is driven in tests/seannet/detection/test_proposer.py and the browser test)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from sgdata.label.box_proposer import ProposedBox

OPENER = "tests.sgdata.label.file_proposer:open_file_proposer"


def file_run(run: Path, rows: object, proposer: str = OPENER) -> Path:
    """A run folder whose ``detector.json`` names ``proposer`` and whose boxes are ``rows``:
    [class, [u1, v1, u2, v2], score] lists, or "fail to open" / "fail to detect"."""
    run.mkdir(parents=True, exist_ok=True)
    (run / "detector.json").write_text(json.dumps({"proposer": proposer}))
    (run / "boxes.json").write_text(json.dumps(rows))
    return run


def open_file_proposer(run: Path):  # noqa: ANN201
    rows = json.loads((run / "boxes.json").read_text())
    if rows == "fail to open":
        raise FileNotFoundError("weights.pt")

    def detect(pixels: np.ndarray) -> list:
        assert pixels.dtype == np.uint8 and pixels.ndim == 3 and pixels.shape[2] == 3
        if rows == "fail to detect":
            raise ValueError("a bad image")
        return [ProposedBox(r[0], tuple(r[1]), r[2]) if isinstance(r, list) else r for r in rows]

    return detect
