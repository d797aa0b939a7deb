"""Markdown that sgdata writes (the dataset card, ``sgdata report``, label accuracy, bench
tables): one table helper, so every generated document draws its tables the same way, and one
way to rewrite a generated block of a hand-written document."""

from __future__ import annotations

import re
from collections.abc import Collection, Iterable, Sequence

from sgdata.errors import SgdataError

__all__ = ["replace_block", "table"]


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


def replace_block(text: str, begin: str, end: str, body: str) -> str:
    """``text`` with its one block from the marker line ``begin`` to ``end`` (a generated part
    of a hand-written document) holding ``body``, on lines of its own between the markers.

    Raises:
        SgdataError: ``text`` holds no such block, or more than one.
    """
    pattern = re.compile(re.escape(begin) + r".*?" + re.escape(end), re.S)
    found = len(pattern.findall(text))
    if found != 1:
        what = "no block" if not found else f"{found} blocks"
        raise SgdataError(f"{what} {begin} ... {end} in the document, where one was expected")
    return pattern.sub(lambda _: f"{begin}\n{body}\n{end}", text)
