"""Markdown that sgdata writes (the dataset card, ``sgdata report``, label accuracy, bench
tables): one table helper, so every generated document draws its tables the same way."""

from __future__ import annotations

from collections.abc import Collection, Iterable, Sequence

__all__ = ["table"]


def table(
    header: Sequence[str], rows: Iterable[Sequence[object]], *, right: Collection[int] = ()
) -> list[str]:
    """A GitHub markdown table, one line per row; cells as ``str``, the columns whose index is
    in ``right`` right-aligned, the others left-aligned."""
    rule = "".join("---:|" if k in right else "---|" for k in range(len(header)))
    return [
        "| " + " | ".join(header) + " |",
        "|" + rule,
        *("| " + " | ".join(str(cell) for cell in row) + " |" for row in rows),
    ]
