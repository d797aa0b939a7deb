"""Markdown that seannet's commands and the bench scripts write: one table helper, one
percent cell, so every generated document renders its figures the same way."""

from __future__ import annotations

from collections.abc import Sequence

__all__ = ["pct", "table"]


def table(header: Sequence[str], rows: Sequence[Sequence[str]]) -> list[str]:
    """A GitHub markdown table, one line per row, every column left-aligned."""
    return [
        "| " + " | ".join(header) + " |",
        "|" + "---|" * len(header),
        *("| " + " | ".join(row) + " |" for row in rows),
    ]


def pct(share: float | None, digits: int = 1) -> str:
    """A share (0..1) as a percent with ``digits`` decimals; ``-`` for None or NaN."""
    return "-" if share is None or share != share else f"{100 * share:.{digits}f}"
