"""bench/suite.py: docs/benchmarks.md is written from the figures the scripts printed, each
section stamped (commit, dirty flag, machine, load average, date); nothing typed by hand."""

from __future__ import annotations

import argparse
import hashlib
import json
from pathlib import Path

from ..bench_scripts import load_bench


def test_the_page_is_the_scripts_figures(tmp_path: Path, mini_dataset: Path) -> None:
    suite = load_bench("suite")
    out = tmp_path / "bench"
    args = argparse.Namespace(views=2, rooms=1, validate=None, settle=0.0)
    # real measures on the mini dataset: sgdata validate, and the channels script's JSON
    validate = suite.run_measure("validate", args, mini_dataset, out)
    channels = suite.run_measure("channels", args, mini_dataset, out)
    stamp = validate["stamp"]
    assert {"commit", "dirty", "cpu", "cores", "memory_gib", "gpu", "load_average", "date"} <= set(
        stamp
    )
    assert json.loads((out / "validate.json").read_text()) == validate

    # a generate record: bench/render.py's figures, then bench/generate.py's two rounds of 1
    # worker, 2 workers and Ray interleaved: the page takes each one's fastest round and
    # computes the ratios, 1 worker's against the textured pipeline's
    def run(wall: float, rate: float, peaks: tuple[float, float] = (400.0, 401.0)) -> dict:
        return {
            "views": 70,
            "wall_s": wall,
            "views_per_s": rate,
            "worker_peak_after_3_mib": peaks[0],
            "worker_peak_after_all_mib": peaks[1],
        }

    runs = [run(7.0, 10.0), run(3.5, 20.0), run(4.0, 17.5), run(8.75, 8.0, (398.0, 420.4)),
            run(4.375, 16.0), run(3.5, 20.0)]  # fmt: skip
    generated = {"render": {"pipeline_textured": 12.5}, "runs": runs}
    settled = {**stamp, "settled_s": 54.0}  # it waited for the load to fall before it ran
    record = {"measure": "generate", "stamp": settled, "commands": [["x"]], "result": generated}
    (out / "generate.json").write_text(json.dumps(record))

    # a profile record as bench/generate.py --profile prints it, 1 worker then 2
    def profiled(wall: float, views: float, outside: float, workers: int) -> dict:
        rows = [{"phase": "command", "stage": "views", "calls": 1, "seconds": wall, "share": 0.9},
                {"phase": "views", "stage": "render", "calls": 70, "seconds": views, "share": 0.5},
                {"phase": "views", "stage": "outside the tasks", "calls": 1, "seconds": outside,
                 "share": 0.25}]  # fmt: skip
        share = round(views / (wall * workers), 4)
        return {"views": 70, "rooms": 2, "workers": workers, "wall_s": wall, "profile": rows,
                "pipeline_share": share}  # fmt: skip

    profile = [profiled(7.0, 3.5, 1.75, 1), profiled(4.0, 3.0, 2.0, 2)]
    (out / "profile.json").write_text(
        json.dumps({"measure": "profile", "stamp": stamp, "commands": [["x"]], "result": profile})
    )
    # a train record as bench/train_step.py --json prints it: its rows, as measured
    steps = {
        "budget_s": 1200.0, "batch_size": 16, "epochs": 5, "clock": "thread-cpu, 1 torch thread",
        "networks": [
            {"network": "resnet18", "step_s": 2.5, "spread": 0.04, "busy": 0.01, "batches": 96,
             "examples": 7680, "step_ratio": 1.0},
            {"network": "seannet", "step_s": 4.25, "spread": 0.31, "busy": 0.0, "batches": 56,
             "examples": 4480, "step_ratio": 1.7},
        ],
    }  # fmt: skip
    train = {"measure": "train", "stamp": stamp, "commands": [["x"]], "result": steps}
    (out / "train.json").write_text(json.dumps(train))
    older = tmp_path / "older.md"
    older.write_text("# Old\n\n## A section\n\nMeasured at `abc1234`: 3 views/s.\n")

    doc = suite.page(out, older=older)
    dirty = " with uncommitted changes" if stamp["dirty"] else ""
    assert f"at commit `{stamp['commit'][:10]}`{dirty} on {stamp['cores']} x {stamp['cpu']}" in doc
    assert f"load average {stamp['load_average']:.2f} at the start" in doc
    assert stamp["settled_s"] == 0  # --settle 0: no wait, and the page says none
    assert stamp["date"] in doc
    assert f"| `{mini_dataset.name}` | {validate['result']['seconds']:.1f} |" in doc
    result = channels["result"]
    assert f"| channels / RGB only | {result['ratio']:.2f}x | >= 0.85x |" in doc
    assert f"| PNG bytes per view, image | {result['bytes_per_view']['image']:,} |" in doc
    assert "| local, 1 worker: 70 views in 7.0 s, 8.75 s | 10.00 views/s | 400 / 420 |  |" in doc
    assert "at the start (after 54 s waiting for it to settle): `x`" in doc
    assert "| **2 workers / 1** | 2.00x (rounds 2.00x to 2.00x) |  |  | >= 1.8x |" in doc
    assert "| **Ray local / local pool** | 1.00x (rounds 0.88x to 1.25x) |  |  | >= 0.9x |" in doc
    alone = "textured: 12.5 annotated views/s) | 0.80x (rounds 0.64x to 0.80x) |  |  | >= 0.85x |"
    assert alone in doc
    assert "| `seannet` | 4.250 | 1.70x | 31 % | 0 % | 56 |" in doc
    assert "| views | render | 3.50 s (50.0 %) | 3.00 s (50.0 %) |" in doc
    assert "| views | outside the tasks | 1.75 s (25.0 %) | 2.00 s (25.0 %) |" in doc
    assert "70 views of 2 rooms: 7.0 s with 1 worker, 4.0 s with 2" in doc
    assert "on the very views generated: **1 worker 0.50, 2 workers 0.38**" in doc
    assert "batches per epoch 1200 s buy each over 5 epochs" in doc
    # what was not measured is listed with its command; the older page is fingerprinted
    assert "## Not measured in this set" in doc
    assert "`python bench/suite.py run OUT --extras fuzz`" in doc
    assert (
        "## Rendering" not in doc and "`bench/render.py`): `python bench/suite.py run OUT`" in doc
    )
    digest = hashlib.sha256(older.read_bytes()).hexdigest()
    assert f"sha256 `{digest[:16]}…`" in doc and "`abc1234`" in doc and "A section" in doc
    # the figures change with the files, not with the template
    runs[1]["views_per_s"] = 30.0
    (out / "generate.json").write_text(json.dumps(record))
    assert "| **2 workers / 1** | 3.00x (rounds 2.00x to 3.00x) |" in suite.page(out, older=older)


def test_a_measure_run_alone_keeps_the_other_sections(tmp_path: Path) -> None:
    suite = load_bench("suite")
    out = tmp_path / "bench"
    out.mkdir()
    stamp = suite.machine_stamp()
    runs = [
        {"target": "test", "wall_s": 450.0, "tests": 3, "test_seconds": 800.0,
         "outcomes": {"passed": 2, "skipped": 1}, "peak_disk_mb": 1500,
         "slowest": [{"test": "tests.a::test_x", "seconds": 25.04, "outcome": "passed"}]},
        {"target": "test-fast", "wall_s": 100.0, "tests": 2, "test_seconds": 150.0,
         "outcomes": {"passed": 2}, "peak_disk_mb": 900, "slowest": []},
    ]  # fmt: skip
    record = {"measure": "tests", "stamp": stamp, "commands": [["x"]], "result": runs}
    (out / "tests.json").write_text(json.dumps(record))
    render = "## Rendering, one llvmpipe thread (`bench/render.py`)"
    current = f"# Benchmarks\n\n{render}\n\n*Measured then.*\n\n| a | 1 |\n\n## Older figures\n"
    doc = suite.page(out, older=tmp_path / "none.md", current=current)
    # the render section, not re-run, stays as it was, stamp and table; the rest is listed
    assert f"{render}\n\n*Measured then.*\n\n| a | 1 |\n\n## " in doc
    assert "`bench/render.py`): `python bench/suite.py run OUT`" not in doc
    assert "`python bench/suite.py run OUT --extras fuzz`" in doc
    assert "| `make test` | 450 s (7.5 min) | 2 passed, 1 skipped | 800 s | 1,500 MB |" in doc
    assert "| `make test-fast` | 100 s (1.7 min) | 2 passed | 150 s | 900 MB |" in doc
    assert "| `tests.a::test_x` | 25.0 |" in doc
    # written again from the page it wrote: the same page
    assert suite.page(out, older=tmp_path / "none.md", current=doc) == doc
