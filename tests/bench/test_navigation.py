"""bench/navigation.py writes docs/navigation.md's tables from runs: here from the tiny ones."""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from types import ModuleType, SimpleNamespace

import pytest

from seannet.provenance import append_provenance, read_provenance

from ..bench_scripts import load_bench

DOC = """# Navigation

<!-- bench/navigation.py: paper -->
typed by hand
<!-- end paper -->

prose that stays

<!-- bench/navigation.py: measured -->
<!-- end measured -->
"""


def _bench() -> ModuleType:
    return load_bench("navigation")


def test_tables_from_tiny_runs(
    navigation_run: SimpleNamespace, mini_dataset: Path, tmp_path: Path
) -> None:
    bench = _bench()
    out = tmp_path / "bench"
    shutil.copytree(navigation_run.navigator, out / "navigator")
    (out / "navigate").mkdir()
    for name in ("navigate_test.json", "navigate_test_times.json"):
        shutil.copy(navigation_run.out / name, out / "navigate")
    # two `run` calls into the same OUT: the stamp names both
    first = append_provenance(out, mini_dataset, step=bench.RUN_STEP)
    made = append_provenance(out, mini_dataset, step=bench.RUN_STEP)
    assert len(read_provenance(out, bench.RUN_STEP)) == 2
    doc = tmp_path / "navigation.md"
    doc.write_text(DOC)
    bench.write_tables(out, doc)
    text = doc.read_text()
    assert "typed by hand" not in text and "prose that stays" in text
    assert "| paper, SeanNet | 5,476 / 204,136 | 80.2 / 65.2 | 2.4 / 6.2 | 13.2 / 21.7 |" in text
    assert made["commit"][:10] in text and made["manifest_sha256"][:16] in text
    assert "Made by 2 commands" in text and text.count(first["started"]) >= 1
    results = navigation_run.results
    (run,) = results["runs"]
    label = f"| {run['model']} ({run['label']}) | 2 / 2 |"
    assert text.count(label) == 2  # the paper rule's table and --replan's
    # the rates are the episodes': success per case under the paper's rule, counted here
    (row,) = [line for line in text.splitlines() if line.startswith(label)][:1]
    for case in ("N", "A"):
        mine = [e for e in run["episodes"] if e["case"] == case]
        won = sum(e["paper"]["outcome"] == "success" for e in mine)
        assert f"{100 * won / len(mine):.1f} [" in row.split("|")[3].split("/")[case == "A"]
    assert "Bump and replan" in text and "path blocked % N / A" in text
    assert "Time per episode" in text and "Val accuracy by action" in text
    bench.write_tables(out, doc)
    assert doc.read_text() == text  # the same runs, the same document
    doc.write_text("# no blocks\n")
    with pytest.raises(SystemExit, match="no block"):
        bench.write_tables(None, doc)


def test_navigator_variants_are_compared_on_the_same_pairs(
    mini_dataset: Path, tmp_path: Path
) -> None:
    bench = _bench()
    out = tmp_path / "bench"
    args = SimpleNamespace(
        data=mini_dataset, out=out, pairs=16, val_pairs=8, image_size=64, cross_layout=0.5,
        epochs=1, encoder="resnet18", jitter=0.0, fusion="early", subset=8, variant_epochs=1,
    )  # fmt: skip
    bench.variants(args)
    record = json.loads((out / bench.VARIANTS).read_text())
    rows = record["variants"]
    assert [r["variant"] for r in rows] == list(bench.NAVIGATOR_VARIANTS)
    assert record["train_pairs"] == 8 and record["epochs"] == 1
    assert all(r["config"]["train_pairs"] == 8 for r in rows)
    assert {r["config"]["fusion"] for r in rows} == {"early", "late"}
    assert all(0 <= r["val_accuracy"] <= 1 and r["seconds_per_epoch"] > 0 for r in rows)
    # a second call reuses the trained variants (and the cached pairs)
    stamp = (out / "variants").stat().st_mtime_ns
    bench.variants(args)
    assert (out / "variants").stat().st_mtime_ns == stamp
    block = bench.variants_block(out)
    assert "| lite0 ImageNet, early fusion |" in block and "8 train pairs" in block


def test_the_stop_thresholds_tried_on_val_are_tabled(tmp_path: Path) -> None:
    bench = _bench()
    grid = [
        {"epsilon": round(0.7 + o, 4), "offset": o, "success": {"N": 0.5 - o, "A": 0.2}}
        for o in bench.EPSILON_OFFSETS
    ]
    record = {
        "provenance": {"started": "now", "commit": "c0ffee" * 7, "data": "d",
                       "manifest_sha256": "ab" * 32, "command": "bench/navigation.py epsilon"},
        "split": "val",
        "episodes_per_case_and_room": 10,
        "localizers": [{"run": "r", "label": "seed0", "eval_epsilon": 0.7,
                        "eval_source": "eval_val.json", "grid": grid, "chosen": 0.5}],
    }  # fmt: skip
    (tmp_path / bench.EPSILON).write_text(json.dumps(record))
    block = bench.epsilon_block(tmp_path)
    assert "| seed0 | 0.700: 50 / 20 | 0.650: 55 / 20 |" in block and block.endswith("| 0.500 |")
    assert "10 episodes per case and room on the val rooms" in block
    assert "chosen thresholds" not in block  # no test run with them yet
