"""The one markdown table helper and the one rewrite of a generated block of a document."""

from __future__ import annotations

import pytest

from sgdata.errors import SgdataError
from sgdata.markdown import replace_block, table


def test_a_table_is_header_rule_and_rows_as_str() -> None:
    assert table(("name", "count"), [("a", 1), ("b", 22)], right=(1,)) == [
        "| name | count |",
        "|---|---:|",
        "| a | 1 |",
        "| b | 22 |",
    ]


def test_a_block_is_rewritten_between_its_markers_only() -> None:
    text = "intro\n<!-- b -->\nold\nlines\n<!-- /b -->\noutro\n"
    assert replace_block(text, "<!-- b -->", "<!-- /b -->", "new") == (
        "intro\n<!-- b -->\nnew\n<!-- /b -->\noutro\n"
    )


@pytest.mark.parametrize(
    ("text", "found"), [("no markers\n", "no block"), ("[x] [/x] [x] [/x]", "2 blocks")]
)
def test_a_document_without_exactly_one_block_is_refused(text: str, found: str) -> None:
    with pytest.raises(SgdataError, match=f"{found} .*where one was expected"):
        replace_block(text, "[x]", "[/x]", "body")
