"""bench/results.py: docs/results.md's tables are built from run files, stamped, not typed."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from seannet.evaluation.compare import compare_models
from seannet.provenance import append_provenance
from seannet.training.config import TrainConfig

from ..bench_scripts import load_bench


@pytest.mark.slow  # the headline, noise, kernel and full-map steps trained and evaluated for real
def test_tables_are_the_runs_figures(
    tmp_path: Path, mini_dataset: Path, tiny_seannet: TrainConfig
) -> None:
    results = load_bench("results")
    runs = tmp_path / "runs"
    head = compare_models(
        mini_dataset,
        runs,
        results.HEADLINE,
        preset=tiny_seannet,
        seeds=(0, 1),
        lrs=(0.01,),  # one lr: the selection is compare's own test
        tag="headline",
    )
    record = append_provenance(runs, mini_dataset, step="headline")
    docs: list[str] = []  # what `run --doc` writes after each evaluation
    results.noise_step(  # the aim's point only
        mini_dataset, runs, grid=(results.AIM,), progress=lambda: docs.append(results.tables(runs))
    )
    # each evaluation reaches the doc as it ends: 2 models x 2 seeds at the aim's point
    assert [f"{k} of 14 measured." in d for k, d in enumerate(docs, 1)] == [True] * 4
    doc = results.tables(runs)
    assert doc == docs[-1]
    # the stamp names the code and the data the runs were made with
    assert f"`{record['commit'][:10]}`" in doc
    assert record["manifest_sha256"][:16] in doc and record["command"] in doc
    # counts come from the runs: the mini dataset has one test room, two seeds per row
    rooms = head["models"][0]["summary"]["rooms"]
    assert rooms == 1 and f"triplet accuracy on {rooms} unseen rooms" in doc
    assert "2 seeds per row" in doc and "std over 2 seeds" in doc
    # the strongest baseline is the one with the best val accuracy, whatever test says: give
    # the baseline weaker on test the better val accuracy, and it is the one named
    path = runs / "comparison-headline.json"
    kept = path.read_text()
    tampered = json.loads(kept)
    weaker = min(tampered["models"][1:], key=lambda e: e["summary"]["accuracy"]["mean"])
    for e in tampered["models"][1:]:
        e["val_accuracy_by_lr"][f"{e['lr']:g}"] = 0.9 if e is weaker else 0.1
    path.write_text(json.dumps(tampered))
    assert f"- The strongest baseline, {weaker['model']}: " in results.tables(runs)
    path.write_text(kept)
    # every model's row carries its own figures
    for entry in head["models"]:
        s = entry["summary"]
        row = f"| {entry['model']} | {entry['lr']:g} |"
        assert row in doc
        assert f"{100 * s['accuracy']['mean']:.1f} ± {100 * s['accuracy']['ci95']:.1f}" in doc
    gap = head["models"][1]["difference_to_first"]
    assert f"{100 * gap['mean']:+.1f} [{100 * gap['low']:+.1f}, {100 * gap['high']:+.1f}]" in doc
    # the noise table holds the aim's point on every seed of both models
    noise_rows = [line for line in doc.splitlines() if "(n=2)" in line]
    assert len(noise_rows) == 2 and all("points |" in line for line in noise_rows)
    assert "## Ablations" not in doc  # not run: not printed, but named as missing
    assert "## A learned scene term" not in doc
    assert "--steps kernel`; not run for this set" in doc
    assert "--steps ablations`; not run for this set" in doc
    # the noise step ran its aim only: the doc counts what it still lacks (2 models x 5 points
    # on seed 0 and the aim's on both seeds: 14)
    assert "--steps noise`; 4 of 14 measured." in doc
    # SeanNet is the network the cpu preset trains, and the doc says which
    assert results.HEADLINE[0] == results.SEANNET == "seannet-fc512"
    assert "SeanNet here is `seannet-fc512`" in doc
    # the learned scene term: the headline's runs evaluated again, its section computed
    kernel = compare_models(
        mini_dataset,
        runs,
        results.KERNEL,
        preset=tiny_seannet,
        seeds=(0, 1),
        lrs=(0.01,),
        tag="kernel",
    )
    assert {Path(r["run"]).parent.parent.name for m in kernel["models"] for r in m["runs"]} == {
        results.SEANNET,
        "resnet18",
    }
    append_provenance(runs, mini_dataset, step="kernel")
    doc = results.tables(runs)
    assert "## A learned scene term" in doc and "--steps kernel`" not in doc
    ours = kernel["models"][0]["summary"]["accuracy"]["mean"]
    assert (
        f"| {results.KERNEL[0]} (the learned scene term, below) >= 90 % | {100 * ours:.1f} %" in doc
    )
    for entry in kernel["models"][1:]:
        d = entry["difference_to_first"]
        assert (
            f"{results.KERNEL[0]} minus {entry['model']}: {100 * d['mean']:+.1f} "
            f"[{100 * d['low']:+.1f}, {100 * d['high']:+.1f}]"
        ) in doc
    # full-map recall: maps rendered at spacing 1, each model's figures from its localize file
    results.full_map_step(mini_dataset, runs)
    doc = results.tables(runs)
    for model in results.FULL_MAP_MODELS:
        found = json.loads((runs / "fullmap" / model / "seed0" / results.FULL_MAP).read_text())
        assert found["queries"] > 0
        row = f"| {model} | {found['queries']} | {100 * found['recall@1']:.1f} |"
        assert row in doc
