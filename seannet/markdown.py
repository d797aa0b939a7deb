"""Markdown that seannet's commands and the bench scripts write: the table helper (sgdata's),
one percent cell, so every generated document renders its figures the same way."""

from __future__ import annotations

from sgdata.markdown import table  # the one table helper, sgdata's and seannet's

__all__ = ["pct", "table"]


def pct(share: float | None, digits: int = 1) -> str:
    """A share (0..1) as a percent with ``digits`` decimals; ``-`` for None or NaN."""
    return "-" if share is None or share != share else f"{100 * share:.{digits}f}"
