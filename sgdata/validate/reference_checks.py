"""``--against REF``: the dataset beside a reference dataset, as ``sgdata diff REF ROOT``
compares them (:mod:`sgdata.dataset.diff`). A difference beyond the tolerance is a problem; the
report of one within it (another CPU's edge pixels) becomes the report's notes."""

from __future__ import annotations

from pathlib import Path

from sgdata.dataset.diff import BEYOND, IDENTICAL, diff_datasets
from sgdata.errors import DatasetError
from sgdata.validate.problems import Collector

__all__ = ["CHECK", "check_against"]

CHECK = "against.reference"


def check_against(root: Path, reference: Path, out: Collector) -> None:
    where = f"against {reference}"
    try:
        report = diff_datasets(reference, root)
    except DatasetError as exc:
        out.add(CHECK, where, f"the reference is not a readable dataset: {exc}")
        return
    out.count(CHECK)
    for level, text in report.findings:
        if level == BEYOND:
            out.add(CHECK, where, text)
    if report.verdict != IDENTICAL:
        out.notes.extend(report.lines())
