"""bench/results.py, like for like: the boxes section is the headline's runs, every network of
a section gets one budget rule, and the doc says what each got (or that it was not recorded)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from seannet.provenance import append_provenance
from seannet.training.config import TrainConfig

from ..bench_scripts import load_bench

BUDGET_S = 0.05  # seconds of one thread: a batch per epoch for the tiny networks


def _section(doc: str, title: str) -> str:
    start = doc.index(f"## {title}")
    end = doc.find("\n## ", start + 1)
    return doc[start : end if end > 0 else None]


@pytest.mark.slow  # three protocol steps, each two networks x two seeds x two lrs
def test_sections_compare_like_for_like(
    tmp_path: Path, mini_dataset: Path, tiny_seannet: TrainConfig
) -> None:
    results = load_bench("results")
    runs = tmp_path / "runs"
    ours = results.SEANNET
    steps = {
        "headline": (ours, "resnet18"),
        "boxes": None,  # the step's own models
        "ablations": (ours, "seannet-image"),
    }
    for step, models in steps.items():
        append_provenance(runs, mini_dataset, step=step)
        results.run_step(
            mini_dataset,
            runs,
            step,
            budget_s=BUDGET_S,
            preset=tiny_seannet,
            seeds=(0, 1),
            lrs=(0.003, 0.01),
            models=models,
        )
    head = {
        m["model"]: m for m in json.loads((runs / "selection-headline.json").read_text())["models"]
    }
    boxes = json.loads((runs / "selection-boxes.json").read_text())
    # the boxes step trains at the headline SeanNet's lr only: both rows are its runs
    assert boxes["lrs"] == [head[ours]["lr"]]
    assert all(m["runs"] == head[ours]["runs"] for m in boxes["models"])
    # the ablations' SeanNet keeps the headline's calibration (calibrations.json, one record
    # per network) and says whose it is; the image branch is calibrated by the same rule under
    # the same budget, for the ablations
    ablations = {
        m["model"]: m for m in json.loads((runs / "selection-ablations.json").read_text())["models"]
    }
    assert ablations[ours]["budget"] == head[ours]["budget"]
    assert ablations[ours]["budget"]["timed_for"] == "headline"
    assert ablations["seannet-image"]["budget"]["timed_for"] == "ablations"
    assert ablations["seannet-image"]["budget"]["budget_s"] == BUDGET_S
    kept = json.loads((runs / "calibrations.json").read_text())
    assert [(r["key"]["trained"], r["comparison"]) for r in kept] == [
        (ours, "headline"),
        ("resnet18", "headline"),
        ("seannet-image", "ablations"),
    ]

    doc = results.tables(runs)
    section = _section(doc, "SeanNet plus the hand-made overlap")
    headline_runs = f"the headline {ours}'s runs"
    assert f"{ours}+boxes: {headline_runs}; {ours}: {headline_runs}" in section
    # its batches are the headline's, timed by today's rule: the section says that rule
    assert f"{BUDGET_S:g} s of one thread's compute per run" in section
    assert "timed before 2026-12-02" not in section
    section = _section(doc, "Ablations")
    for name, entry in ablations.items():
        row = (
            f"| {name} | {entry['trained']} | {entry['batches_per_epoch']} | {entry['epochs']} | "
            f"{entry['examples']:,} |"
        )
        assert row in section
    assert f"| {ours} | {ours} | " in section and "calibrated in `headline`" in section
    assert "| seannet-image | seannet-image | " in section and "calibrated here" in section
    assert f"Like for like: every network's batches fill the same {BUDGET_S:g} s" in section

    # a section whose runs are not the headline's says so, and names why
    path = runs / "comparison-boxes.json"
    tampered = json.loads(path.read_text())
    other = tampered["models"][0]
    other["lr"], other["val_accuracy_by_lr"]["0.1"] = 0.1, 0.5
    for r in other["runs"]:
        r["run"] = r["run"].replace("/lr", "/other-lr")
    path.write_text(json.dumps(tampered))
    section = _section(results.tables(runs), "SeanNet plus the hand-made overlap")
    assert f"the headline {ours}'s runs" in section  # the untouched row
    assert f"{ours}+boxes: not the headline {ours}'s runs (lr 0.1 against" in section

    # runs made before budgets were recorded: "not recorded", and no like-for-like claim
    path = runs / "comparison-ablations.json"
    old = json.loads(path.read_text())
    for m in old["models"]:
        del m["budget"], m["examples"]
    path.write_text(json.dumps(old))
    (runs / "selection-ablations.json").write_text(json.dumps(old | {"split": None}))
    section = _section(results.tables(runs), "Ablations")
    assert section.count("| not recorded |") == len(old["models"])
    assert f"Like for like not shown: {ours}, seannet-image have no budget record" in section
    assert "Like for like: every" not in section


def test_a_network_timed_on_a_later_machine_says_so() -> None:
    results = load_bench("results")
    budget = {"source": "calibrated", "budget_s": 1200.0, "step_s": 3.1, "spread": 0.05}
    entry = {"trained": "seannet", "batches_per_epoch": 77, "budget": budget}
    assert results._budget_cell(entry, "fc") == (
        "calibrated here: 1200 s, a step 3.100 s, rounds 5 % apart"
    )
    converted = {
        "reference": "resnet18",
        "reference_then_s": 2.0,
        "reference_now_s": 4.0,
        "timed_s": 6.2,
    }
    entry["budget"] = {**budget, "converted_by": converted}
    assert results._budget_cell(entry, "fc").endswith(
        "(timed 6.200 s on a later machine, put in the first one's seconds by resnet18's "
        "step: 2.000 s there, 4.000 s here)"
    )
