"""A training step's figures as a table: each network's step as the training budget times it
(:func:`~seannet.training.budget.calibrate`), the one layout ``bench/train_step.py`` prints and
docs/benchmarks.md shows."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from seannet.markdown import table

__all__ = ["step_table"]


def step_table(networks: Sequence[Mapping[str, Any]]) -> list[str]:
    """Markdown table lines, one row per network: its ``network`` name, ``step_s`` (seconds
    of one step), ``step_ratio`` (that step over the first network's), ``spread`` and
    ``busy`` (shares: how far the timing rounds disagree, how much wall time went to other
    work) and ``batches`` (per epoch, what the budget buys)."""
    first = networks[0]["network"]
    rows = [
        (
            f"`{n['network']}`",
            f"{n['step_s']:.3f}",
            f"{n['step_ratio']:.2f}x",
            f"{100 * n['spread']:.0f} %",
            f"{100 * n['busy']:.0f} %",
            str(n["batches"]),
        )
        for n in networks
    ]
    return table(("network", "step s", f"x {first}", "spread", "busy", "batches per epoch"), rows)
