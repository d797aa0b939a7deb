"""examples/custom_method.py end to end: a fresh interpreter outside the package runs
``seannet benchmark`` with the file imported by path, on the mini dataset; a card is written.
A bad method is one line on stderr and a non-zero exit (in this process)."""

from __future__ import annotations

import hashlib
import json
import subprocess
import sys
from pathlib import Path

import pytest

from tests.cli_runner import run_cli

EXAMPLE = Path(__file__).resolve().parents[3] / "examples" / "custom_method.py"
SEANNET = [sys.executable, "-m", "sgdata_cli.seannet_app"]


def _run(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run(
        [*SEANNET, *args], capture_output=True, text=True, cwd=cwd, timeout=600,
        env={"OMP_NUM_THREADS": "1", "PATH": "/usr/bin:/bin"},
    )  # fmt: skip


def test_the_example_is_a_short_file_one_command_from_a_card(
    tmp_path: Path, mini_dataset: Path
) -> None:
    assert len(EXAMPLE.read_text().splitlines()) <= 30
    # the command its docstring gives names the factory this test runs
    assert "--methods examples/custom_method.py:ColourBoxes " in EXAMPLE.read_text()
    method = f"{EXAMPLE}:ColourBoxes"
    done = _run("benchmark", "--data", str(mini_dataset), "--methods", method, "--out", "cards",
                cwd=tmp_path)  # fmt: skip
    assert done.returncode == 0, done.stderr
    card = json.loads(
        (tmp_path / "cards" / "custom_method.py__ColourBoxes" / "card.json").read_text()
    )
    # named by its class, not the folders of this machine; the file's bytes in provenance
    assert card["method"] == "ColourBoxes" and card["spec"] == method and not card["trained"]
    source = card["provenance"]["method_source"]
    assert source == {"file": "custom_method.py",
                      "sha256": hashlib.sha256(EXAMPLE.read_bytes()).hexdigest()}  # fmt: skip
    assert card["summary"]["box_noise"]  # it uses boxes: the noise sweep ran
    assert card["provenance"]["command"].endswith(f"--methods {method} --out cards")
    markdown = (tmp_path / "cards" / "custom_method.py__ColourBoxes" / "card.md").read_text()
    assert "# Benchmark card: ColourBoxes" in markdown
    loaded = f"Loaded from `custom_method.py:ColourBoxes`, sha256 `{source['sha256'][:16]}"
    assert loaded in markdown
    board = _run("leaderboard", "cards", cwd=tmp_path)
    assert board.returncode == 0 and "`ColourBoxes`" in board.stdout
    rows = [line for line in board.stdout.splitlines() if line.startswith("| `")]
    assert len(rows) == 1 and str(EXAMPLE.parent) not in rows[0]  # the stamp quotes the command


def test_a_bad_method_is_one_line_on_stderr(
    tmp_path: Path, mini_dataset: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    bad = tmp_path / "bad.py"
    bad.write_text(
        "import torch\n\nclass Bad:\n    def embed(self, views):\n"
        "        return torch.full((len(views), 2), float('inf'))\n"
    )
    monkeypatch.chdir(tmp_path)  # in this process: the refusal, not the interpreter, is tested
    done = run_cli("seannet", "benchmark", "--data", mini_dataset, "--methods", f"{bad}:Bad",
                   "--out", "cards")  # fmt: skip
    assert done.returncode != 0
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and "bad.py:Bad" in lines[0] and "check: finite" in lines[0]
    assert not (tmp_path / "cards").exists() or not list((tmp_path / "cards").rglob("card.*"))
