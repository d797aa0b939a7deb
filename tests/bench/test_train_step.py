"""bench/train_step.py: the networks' steps by the budget's rule, SeanNet's GCN forms and its
step part by part, on the mini dataset's real batches."""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path
from types import ModuleType

from seannet.training.step_profile import PARTS

from ..bench_scripts import load_bench, run_bench


def _bench() -> ModuleType:
    return load_bench("train_step")


def _number(cell: str) -> float:
    return float(re.sub(r"[*,% ]", "", cell))


def test_profile_books_the_whole_step_to_parts(mini_dataset: Path, tmp_path: Path) -> None:
    data = tmp_path / "data"  # the bench builds the image cache inside the dataset it reads:
    shutil.copytree(mini_dataset, data)  # a copy keeps the shared fixture's bytes as they were
    done = run_bench("train_step", data, "--profile", "--batch-size", "2", "--steps", "1")
    assert done.returncode == 0, done.stderr
    out = done.stdout
    assert "resnet18" not in out  # the profile alone: the comparison did not run
    rows = [line.split(" | ") for line in out.splitlines() if line.startswith("| ")]
    header, *parts, step = rows
    assert header[0] == "| part" and step[0] == "| **step**"
    labels = [label for _, label in PARTS]
    assert len(parts) == len(labels)
    for row, label in zip(parts, labels, strict=True):
        assert row[0].startswith("| " + label.split("{")[0].split(" (")[0]), (row[0], label)
    cells = {row[0][2:]: [_number(c.strip(" |")) for c in row[1:]] for row in parts}
    assert all(value >= 0 for values in cells.values() for value in values)
    # forward + backward = total, the shares add up to the step, parts' parameters to the model's
    assert all(abs(f + b - t) < 0.2 for f, b, t, *_ in list(cells.values())[:-1])
    assert abs(sum(values[3] for values in cells.values()) - 100) < 1.0
    assert sum(values[4] for values in cells.values()) == _number(step[-1].strip(" |"))
    by_key = dict(zip((key for key, _ in PARTS), cells.values(), strict=True))
    for key in ("backbone", "head", "objects", "pathways", "fc", "optimiser"):
        assert by_key[key][2] > 0, key
    assert by_key["fc"][4] == 6144 * 4096 + 4096 + 4096 * 2048 + 2048  # the 6,144 -> ...
    assert "GCN fc 6,144 -> 4,096 -> 2,048" in out
    assert re.search(r"backward booked to a part: (9\d|100)\.\d %", out)


def test_step_costs_are_the_budgets_calibration_and_branch_motion_trains_by_the_library_step(
    mini_dataset: Path, tmp_path: Path
) -> None:
    """bench/train_step.py times each network with the budget's calibration (the figures a
    comparison's budget table shows), its --gcn-forms and bench/branch_motion.py run
    seannet.training's own step (train_one_epoch over triplet_step) on the mini dataset."""
    bench = _bench()
    # by default, the networks the protocol trains (seannet.protocol), once each, ResNet-18 first
    assert bench.RESULTS_NETWORKS[0] == "resnet18" and "seannet-nolayout" in bench.RESULTS_NETWORKS
    assert not any("+" in name for name in bench.RESULTS_NETWORKS)
    assert len(set(bench.RESULTS_NETWORKS)) == len(bench.RESULTS_NETWORKS)
    data = tmp_path / "data"
    shutil.copytree(mini_dataset, data)
    step = ("train_step", data, "--batch-size", "2")
    done = run_bench(*step, "--models", "resnet18,seannet-fc512", "--budget", "60", "--json")
    assert done.returncode == 0, done.stderr
    figures = json.loads(done.stdout)
    assert figures["clock"] == "thread-cpu, 1 torch thread" and figures["batch_size"] == 2
    first, fc512 = figures["networks"]
    assert (first["network"], fc512["network"]) == ("resnet18", "seannet-fc512")
    for row in figures["networks"]:  # the budget's rule: batches fill 60 s over the epochs
        assert row["batches"] == max(1, int(60 / figures["epochs"] / row["step_s"]))
        assert row["examples"] == row["batches"] * 2 * figures["epochs"]
        assert row["step_ratio"] == row["step_s"] / first["step_s"]
    forms = run_bench(*step, "--gcn-forms", "--steps", "1")
    assert forms.returncode == 0, forms.stderr
    assert "with the dense GCN" in forms.stdout and "present nodes" in forms.stdout
    branch = run_bench("branch_motion", data, "--batches", "1")
    assert branch.returncode == 0, branch.stderr
    motion = branch.stdout
    moved = {
        line[:18].strip(): float(line[18:])
        for line in motion.splitlines()
        if line[:18].strip() in _branch_parts()
    }
    assert set(moved) == set(_branch_parts()) and moved["fusion"] > 0  # one step moved it
    assert "graph share" in motion


def _branch_parts() -> list[str]:
    return list(load_bench("branch_motion").PARTS)


def test_an_unknown_network_is_one_line_before_any_timing(mini_dataset: Path) -> None:
    done = run_bench("train_step", mini_dataset, "--models", "resnet18,nope")
    assert done.returncode == 1 and "Traceback" not in done.stderr
    assert done.stderr.startswith("--models: model 'nope': unknown name 'nope'")
    assert len(done.stderr.strip().splitlines()) == 1 and done.stdout == ""
