"""A few seeded examples of every input surface per test run (``bench/fuzz.py`` runs long
campaigns): each answers a clear one-line error or a correct result, and writes nothing half."""

from __future__ import annotations

from pathlib import Path

import pytest

from .harness import campaign
from .surfaces import SURFACES

# examples per surface in the normal suite: seeded, so every run feeds the same inputs; sized
# so all surfaces together take well under a minute on one busy CPU
EXAMPLES = {
    "USD rooms": 25,
    "toml configs": 60,
    "label files (COCO, LabelMe, Label Studio)": 40,
    "label server request bodies": 30,
    "datasets (Dataset.open, validate)": 12,
    "mesh assets": 40,
}


@pytest.mark.parametrize("name", sorted(SURFACES))
def test_every_surface_keeps_the_contract(
    name: str, tmp_path: Path, request: pytest.FixtureRequest
) -> None:
    surface = SURFACES[name]
    # the datasets surface corrupts copies of the suite's shared mini dataset
    session = request.getfixturevalue("mini_dataset") if name.startswith("datasets") else None
    report = campaign(surface, EXAMPLES[name], seed=0, session=session, work_root=tmp_path)
    assert report.tried >= EXAMPLES[name] // 2
    assert not report.failures, {k: (f.message, f.example) for k, f in report.failures.items()}


def test_every_surface_has_a_number_of_examples() -> None:
    assert set(EXAMPLES) == set(SURFACES)
