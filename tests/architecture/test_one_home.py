"""Facts with one home (house habit 11), each written once in the code and imported
everywhere else: reading the git commit (``seannet.provenance``) and drawing a markdown table
(``sgdata.markdown.table``)."""

from __future__ import annotations

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
CODE = ("sgdata", "seannet", "cli", "bench", "scripts")  # what the project runs, tests aside

# the literal that gives the fact away -> the one file that may hold it
HOMES = {
    "rev-parse": "seannet/provenance.py",  # the commit a record or a page names
    "---|": "sgdata/markdown.py",  # a markdown table's rule line
}


def _holders(literal: str) -> list[str]:
    return sorted(
        str(path.relative_to(ROOT))
        for folder in CODE
        for path in (ROOT / folder).rglob("*.py")
        if literal in path.read_text(encoding="utf-8")
    )


@pytest.mark.parametrize("literal", HOMES)
def test_each_fact_is_written_in_its_home_only(literal: str) -> None:
    assert _holders(literal) == [HOMES[literal]]
