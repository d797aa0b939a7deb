"""bench/label_proposals.py: docs/labeling.md holds the table the script prints."""

from __future__ import annotations

from ..bench_scripts import ROOT, load_bench


def test_the_doc_prints_the_measured_table() -> None:
    script = load_bench("label_proposals")
    doc = (ROOT / "docs/labeling.md").read_text(encoding="utf-8")
    assert f"{script.BEGIN}\n{script.table()}\n{script.END}" in doc, (
        "docs/labeling.md is stale: run python bench/label_proposals.py --write"
    )
