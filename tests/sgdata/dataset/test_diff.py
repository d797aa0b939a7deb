"""sgdata diff: how two datasets differ, from identical to another recipe; a generation under
an emulated older CPU (llvmpipe's 128-bit path) is the same dataset within the tolerance."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from sgdata.dataset import Dataset, encode_image, observations_path
from sgdata.dataset.diff import BEYOND, IDENTICAL, WITHIN, box_iou, diff_datasets
from sgdata.pipeline.config import load_config
from sgdata.pipeline.generate import generate_dataset

from ...cli_runner import run_cli


def test_a_dataset_is_identical_to_itself(mini_dataset: Path) -> None:
    report = diff_datasets(mini_dataset, mini_dataset)
    assert report.verdict == IDENTICAL and report.findings == []
    assert report.channels["image"].views == sum(
        Dataset.open(mini_dataset).manifest.counts.observations.values()
    )
    result = run_cli("sgdata", "diff", str(mini_dataset), str(mini_dataset))
    assert result.returncode == 0 and "identical" in result.stdout.splitlines()[0]


def _rewrite_rows(root: Path, split: str, room: str, change) -> None:  # noqa: ANN001
    """Change the rows of one shard in place, behind the manifest's back (``change`` takes and
    returns the rows as dicts, image cells as {"bytes", "path"})."""
    path = root / observations_path(split, room)
    table = pq.read_table(path)
    rows = change(table.to_pylist())
    pq.write_table(pa.Table.from_pylist(rows, schema=table.schema), path)


def test_a_few_pixels_differ_within_a_relation_beyond(mini_dataset: Path, tmp_path: Path) -> None:
    dataset = Dataset.open(mini_dataset)
    split, room = "train", dataset.rooms("train")[0]
    copy = tmp_path / "pixels"
    shutil.copytree(mini_dataset, copy)

    def repaint(rows: list[dict]) -> list[dict]:
        rgb = Dataset.read_image(rows[1]["image"]["bytes"]).copy()
        rgb[:2, :3] = 255 - rgb[:2, :3]  # six pixels of the second view
        rows[1]["image"]["bytes"] = encode_image(rgb)
        return rows

    _rewrite_rows(copy, split, room, repaint)
    report = diff_datasets(mini_dataset, copy)
    image = report.channels["image"]
    assert report.verdict == WITHIN, report.lines()
    assert (image.views_differing, image.pixels_differing) == (1, 6)
    view = dataset.observations(split).column("obs_id")[1].as_py()
    assert image.worst_view == view and f"worst view {view}" in "\n".join(report.lines())
    assert run_cli("sgdata", "diff", str(mini_dataset), str(copy)).returncode == 1
    # a tolerance of no pixel at all calls the same copy different
    result = run_cli("sgdata", "diff", str(mini_dataset), str(copy), "--pixel-share", "0")
    assert result.returncode == 2 and "beyond: image: 1 views differ" in result.stdout

    def drop_relation(rows: list[dict]) -> list[dict]:
        view = next(r for r in rows if r["relations"])
        view["relations"] = view["relations"][1:]
        return rows

    _rewrite_rows(copy, split, room, drop_relation)
    report = diff_datasets(mini_dataset, copy)
    assert report.verdict == BEYOND
    assert any(
        "relations among the same objects differ in 1 views" in t for _, t in report.findings
    )
    result = run_cli("sgdata", "validate", str(copy), "--quick", "--against", str(mini_dataset))
    assert result.returncode == 1 and "against.reference" in result.stdout


def test_another_seed_is_another_recipe(mini_dataset: Path, tmp_path: Path) -> None:
    copy = tmp_path / "seed"
    shutil.copytree(mini_dataset, copy)
    manifest = json.loads((copy / "dataset.json").read_text())
    manifest["seed"] += 1
    (copy / "dataset.json").write_text(json.dumps(manifest))
    report = diff_datasets(mini_dataset, copy)
    assert report.verdict == BEYOND
    assert report.findings == [(BEYOND, "another recipe: manifest seed differ")]
    result = run_cli("sgdata", "diff", str(mini_dataset), str(copy))
    assert result.returncode == 2 and "another recipe" in result.stdout


def test_box_iou() -> None:
    assert box_iou([0, 0, 10, 10], [0, 0, 10, 10]) == 1.0
    assert box_iou([0, 0, 10, 10], [5, 0, 15, 10]) == pytest.approx(50 / 150)
    assert box_iou([0, 0, 2, 2], [4, 4, 6, 6]) == 0.0


def test_an_older_cpu_draws_the_same_dataset_within_tolerance(
    mini_dataset: Path, mini_config_file: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The same recipe generated on llvmpipe's 128-bit path (CPUs without AVX, ARM): forced
    with LP_NATIVE_VECTOR_WIDTH=128, which alone aborts on textures (the renderer gives it the
    SSE4.1 features that go with it). Edge pixels may differ; the dataset is the same."""
    monkeypatch.setenv("LP_NATIVE_VECTOR_WIDTH", "128")
    monkeypatch.delenv("GALLIUM_OVERRIDE_CPU_CAPS", raising=False)
    older = tmp_path / "width128"
    generate_dataset(load_config(mini_config_file), older, workers=2)
    report = diff_datasets(mini_dataset, older)
    assert report.verdict in (IDENTICAL, WITHIN), report.lines()
    assert report.recipes[0] == report.recipes[1]
    image = report.channels["image"]
    assert image.views == sum(Dataset.open(older).manifest.counts.observations.values())
    assert image.worst_share <= 0.01 and np.isfinite(image.sum_abs)
    result = run_cli("sgdata", "validate", str(older), "--quick", "--against", str(mini_dataset))
    assert result.returncode == 0, result.stdout
