"""bench/learning_curve.py on the mini dataset with tiny networks: a larger budget trains the
first budget's batches scaled, at the lr chosen on val there, and the page is the runs'."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from seannet.training.config import TrainConfig

from ..bench_scripts import load_bench


@pytest.mark.slow  # 6 tiny runs over two budgets, each evaluated on val and test
def test_curve_scales_the_first_budget_and_writes_the_runs(
    tmp_path: Path, mini_dataset: Path, tiny_seannet: TrainConfig
) -> None:
    curve = load_bench("learning_curve")
    runs = tmp_path / "runs"
    budgets = curve.parse_budgets("0.2:1,0.05:2")  # sorted: 0.05 first
    assert [b for b, _ in budgets] == [0.05, 0.2]
    page = tmp_path / "docs" / "curve.md"
    page.parent.mkdir()
    written = []  # what `run --doc` writes after each budget's evaluation

    def write() -> None:
        curve.write_page(runs, page)
        written.append(len(curve.read_curve(runs)["seannet"]))

    curve.run(
        mini_dataset, runs, budgets, ("seannet", "seannet+boxes"), preset=tiny_seannet,
        progress=write,
    )  # fmt: skip
    assert written == [1, 2]  # a point more each time

    points = curve.read_curve(runs)
    assert list(points) == ["seannet", "seannet+boxes"]
    first, last = points["seannet"]
    assert (first["seeds"], last["seeds"]) == (2, 1)
    # the first budget's calibrated batches, scaled by the budget: no second timing
    assert last["batches_per_epoch"] == max(1, round(first["batches_per_epoch"] * 4))
    assert last["lr"] == first["lr"]  # chosen on val at the first budget
    rows = json.loads((runs / "b0.2" / curve.CURVE).read_text())["runs"]
    assert {Path(r["run"]).parent.parent.parent for r in rows} == {runs / "b0.2"}
    # the boxes row is the same network's runs (its lr chosen on val with the boxes)
    assert {Path(r["run"]).parent.parent.name for r in rows} == {"seannet"}

    text = curve.tables(runs, page.with_suffix(".png"))
    assert page.read_text() == text  # the last write holds every point
    assert page.with_suffix(".png").stat().st_size > 1000
    assert "bench/learning_curve.py" in text and "commit" in text  # stamped
    assert f"{100 * last['test']['mean']:.1f} (1 seed)" in text
    assert f"| {first['lr']:g} (val, of 0.003 / 0.01) |" in text
    # the default design's models were not run here: the page lists each point it lacks
    assert "- seannet-fc512 at 4800 s: 1 seed asked, 0 run" in text
    assert f"{100 * first['val']['mean']:.1f} ± {100 * first['val']['ci95']:.1f}" in text


def test_budgets_are_refused_with_one_line() -> None:
    curve = load_bench("learning_curve")
    with pytest.raises(SystemExit, match="expected BUDGET:SEEDS"):
        curve.parse_budgets("300,1200")
    with pytest.raises(SystemExit, match="seeds >= 1"):
        curve.parse_budgets("300:0")


def test_where_a_curve_flattens_is_read_on_val() -> None:
    curve = load_bench("learning_curve")

    def point(budget: float, val: float, test: float) -> dict:
        return {"budget_s": budget, "val": {"mean": val}, "test": {"mean": test}}

    # test rises, val does not: flat, since nothing is read on test
    flat = [point(300, 0.840, 0.80), point(1200, 0.845, 0.90), point(4800, 0.848, 0.95)]
    assert curve._flattens(flat) == (
        "flat from 300 s (val gains, points: 300 to 1200 s: +0.5; 1200 to 4800 s: +0.3)"
    )
    rising = [point(300, 0.80, 0.8), point(1200, 0.82, 0.8)]
    assert curve._flattens(rising) == (
        "still rising at 1200 s (val gains, points: 300 to 1200 s: +2.0)"
    )
    assert curve._flattens(rising[:1]) == "one budget only"
