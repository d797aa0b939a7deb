"""sgdata.pictures.report: charts, contact sheet and summary.md from a generated mini dataset."""

from __future__ import annotations

from pathlib import Path

import pytest
from PIL import Image

from sgdata.errors import DatasetError
from sgdata.pictures.report import bar_chart, write_report


def test_write_report(mini_dataset: Path, tmp_path: Path) -> None:
    written = write_report(mini_dataset, tmp_path / "rep", triplets=2, seed=1)
    names = {p.name for p in written}
    assert names == {
        "classes.png",
        "relations.png",
        "tiers.png",
        "headings.png",
        "visible_objects.png",
        "contact_sheet.png",
        "summary.md",
    }
    with Image.open(tmp_path / "rep/contact_sheet.png") as sheet:
        assert sheet.width >= 3 * 96 * 2 and sheet.height > 2 * 96 * 2
    summary = (tmp_path / "rep/summary.md").read_text()
    assert "| train | 1 |" in summary and "mean objects" in summary and "bathroom" in summary
    again = write_report(mini_dataset, tmp_path / "rep2", triplets=2, seed=1)
    sheet_a = (tmp_path / "rep/contact_sheet.png").read_bytes()
    assert sheet_a == (again[5]).read_bytes()  # seeded: the same triplets


def test_bar_chart_sizes() -> None:
    image = bar_chart("t", ["a", "bb"], [3, 0], xlabel="n")
    assert image.width > 400 and image.height > 60


def test_not_a_dataset(tmp_path: Path) -> None:
    with pytest.raises(DatasetError):
        write_report(tmp_path, tmp_path / "out")
