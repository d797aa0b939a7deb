"""A few seeded examples of every input surface per test run (``bench/fuzz.py`` runs the same
test as a long campaign): each answers a clear one-line error or a correct result, and writes
nothing half."""

from __future__ import annotations

import json
import os
import time
from pathlib import Path

import pytest

from .harness import Report, campaign
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
    "localization methods (checks)": 100,
    "detector exports (COCO, YOLO)": 16,
    "detector runs for sgdata label --detector": 150,
    "COCO files seannet detector reads": 150,
}
# the surfaces whose examples edit copies of a dataset of the suite's (a session fixture)
DATASETS = {
    "datasets (Dataset.open, validate)": "channels_dataset",
    "detector exports (COCO, YOLO)": "channels_dataset",
}
# A campaign (bench/fuzz.py) sets these: examples per surface, the hypothesis seed, the
# surfaces to run (a JSON list; default all) and a JSON-lines file each surface's report goes to.
CAMPAIGN = (
    "SGDATA_FUZZ_EXAMPLES",
    "SGDATA_FUZZ_SEED",
    "SGDATA_FUZZ_SURFACES",
    "SGDATA_FUZZ_REPORT",
)


@pytest.mark.parametrize("name", sorted(SURFACES))
def test_every_surface_keeps_the_contract(
    name: str, tmp_path: Path, request: pytest.FixtureRequest
) -> None:
    examples_env, seed_env, surfaces_env, report_env = (os.environ.get(k) for k in CAMPAIGN)
    if surfaces_env and name not in json.loads(surfaces_env):
        pytest.skip("not in this campaign")
    examples = int(examples_env) if examples_env else EXAMPLES[name]
    surface = SURFACES[name]
    # the datasets surfaces edit copies of the suite's shared datasets
    session = request.getfixturevalue(DATASETS[name]) if name in DATASETS else None
    start = time.perf_counter()
    report = campaign(
        surface, examples, seed=int(seed_env or 0), session=session, work_root=tmp_path
    )
    if report_env:
        _record(Path(report_env), name, report, time.perf_counter() - start)
    assert report.tried >= examples // 2
    assert not report.failures, {k: (f.message, f.example) for k, f in report.failures.items()}


def _record(path: Path, name: str, report: Report, seconds: float) -> None:
    """One JSON line of a campaign's report on a surface (what bench/fuzz.py prints)."""
    failures = {
        k: {"message": f.message, "example": repr(f.example)[:2000]}
        for k, f in report.failures.items()
    }
    line = {
        "surface": name,
        "tried": report.tried,
        "refused": report.refused,
        "failures": failures,
        "known": report.known,
        "seconds": round(seconds, 1),
    }
    with path.open("a", encoding="utf-8") as handle:
        handle.write(json.dumps(line) + "\n")


def test_every_surface_has_a_number_of_examples() -> None:
    assert set(EXAMPLES) == set(SURFACES)
