"""sgdata validate / sgdata report from the command line (the console script's entry point,
in-process: tests/cli_runner.py)."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

from ..cli_runner import Done, run_cli


def run(*args: str) -> Done:
    return run_cli("sgdata", *args)


def test_validate_clean_and_damaged(mini_dataset: Path, tmp_path: Path) -> None:
    result = run("validate", str(mini_dataset))
    assert result.returncode == 0, result.stdout + result.stderr
    assert "clean" in result.stdout and "relations.recompute" in result.stdout
    result = run("validate", str(mini_dataset), "--json", "--quick")
    assert result.returncode == 0
    data = json.loads(result.stdout)
    assert data["ok"] is True and "images.decode" in data["skipped"]

    copy = tmp_path / "copy"
    shutil.copytree(mini_dataset, copy)
    (copy / "triplets/train.parquet").write_bytes(b"not parquet")
    result = run("validate", str(copy), "--json")
    assert result.returncode == 1
    data = json.loads(result.stdout)
    assert not data["ok"]
    assert {p["check"] for p in data["problems"]} >= {"files.sha256", "tables.schema"}
    result = run("validate", str(copy), "--quick")
    assert result.returncode == 1 and "triplets/train.parquet" in result.stdout


def test_validate_not_a_dataset(tmp_path: Path) -> None:
    result = run("validate", str(tmp_path))
    assert result.returncode == 2
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and "no dataset.json" in lines[0] and "Traceback" not in result.stderr


def test_report(mini_dataset: Path, tmp_path: Path) -> None:
    result = run("report", str(mini_dataset), "-o", str(tmp_path / "rep"), "--triplets", "2")
    assert result.returncode == 0, result.stderr
    assert (tmp_path / "rep/summary.md").is_file() and (tmp_path / "rep/tiers.png").is_file()
