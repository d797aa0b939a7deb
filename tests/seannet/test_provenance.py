"""Provenance: the code state is read when seannet is imported, records are appended, never
overwritten, and the stamp names every run; directories of before are read too."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

from seannet.provenance import (
    PROCESS,
    PROVENANCE,
    ProcessState,
    append_provenance,
    read_provenance,
    stamp,
)
from sgdata.dataset import Dataset

ROOT = Path(__file__).resolve().parents[2]


def test_records_are_appended_and_each_is_named(tmp_path: Path, mini_dataset: Path) -> None:
    data, manifest = mini_dataset, Dataset.open(mini_dataset).manifest
    run = tmp_path / "run"
    first = append_provenance(run, data, step="train")
    second = append_provenance(run, data, step="resume")
    lines = (run / PROVENANCE).read_text().splitlines()
    assert [json.loads(line)["step"] for line in lines] == ["train", "resume"]
    assert read_provenance(run) == [first, second]
    assert read_provenance(run, "resume") == [second]
    assert first["commit"] == PROCESS.commit
    assert first["format_version"] == manifest.format_version
    assert first["dataset_seed"] == manifest.seed and len(first["manifest_sha256"]) == 64
    assert first["recipe"] == manifest.recipe_fingerprint()  # the identity that travels
    text = stamp(read_provenance(run))
    assert text.startswith("*Made by 2 commands:")
    assert text.count(first["manifest_sha256"][:16]) == 2
    assert text.count(f"recipe `{first['recipe'][:16]}") == 2
    # a killed writer's torn last line is skipped
    with open(run / PROVENANCE, "a") as f:
        f.write('{"step": "tr')
    assert len(read_provenance(run)) == 2


def test_a_directory_of_before_is_read(tmp_path: Path) -> None:
    old = {"commit": "a" * 40, "dirty": False, "command": "bench/results.py run", "started": "x"}
    (tmp_path / "provenance-headline.json").write_text(json.dumps(old))
    append_provenance(tmp_path, None, step="headline")
    records = read_provenance(tmp_path, "headline")
    assert records[0]["commit"] == "a" * 40 and len(records) == 2
    assert stamp([]) == ""


def test_the_commit_is_the_one_loaded_not_the_one_at_write_time(tmp_path: Path) -> None:
    """A checkout whose HEAD moves after the process started: records name the first."""
    repo = tmp_path / "repo"
    repo.mkdir()
    git = ["git", "-C", str(repo), "-c", "user.name=t", "-c", "user.email=t@t"]
    subprocess.run([*git, "init", "-q"], check=True)
    (repo / "f").write_text("1")
    subprocess.run([*git, "add", "f"], check=True)
    subprocess.run([*git, "commit", "-qm", "one"], check=True)
    state = ProcessState.capture(repo, argv=["seannet", "train", "--out", "a b"])
    (repo / "f").write_text("2")
    subprocess.run([*git, "commit", "-qam", "two"], check=True)
    head = subprocess.run([*git, "rev-parse", "HEAD"], capture_output=True, text=True).stdout
    assert state.commit != head.strip() and len(state.commit) == 40 and not state.dirty
    assert state.command == "seannet train --out 'a b'"
    record = append_provenance(tmp_path / "run", None, process=state)
    assert record["commit"] == state.commit
    (repo / "f").write_text("3")
    assert ProcessState.capture(repo).dirty
    assert ProcessState.capture(tmp_path / "nowhere").commit == "unknown"
    installed = str(Path(sys.executable).parent / "seannet")
    assert ProcessState.capture(repo, argv=[installed, "eval"]).command == "seannet eval"
    elsewhere = str(tmp_path / "bin" / "seannet")
    assert ProcessState.capture(repo, argv=[elsewhere, "eval"]).command == f"{elsewhere} eval"


def test_importing_seannet_reads_the_commit_once() -> None:
    code = "import sys, seannet.provenance as p; print(p.PROCESS.commit, 'torch' in sys.modules)"
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, check=True
    ).stdout.split()
    head = subprocess.run(["git", "rev-parse", "HEAD"], capture_output=True, text=True, cwd=ROOT)
    assert out == [head.stdout.strip(), "False"]
