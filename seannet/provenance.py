"""What made a run: the code (commit and dirty flag, captured when this process loaded it), the
command, the data's fingerprint; appended to the run's ``provenance.jsonl``, never overwritten.

The code's state is read once, when ``seannet`` is first imported (:data:`PROCESS`): a commit
made while a long run goes on does not change what its records say. Each call of
:func:`append_provenance` adds one JSON line, so a directory that several commands or several
calls wrote into names every one of them, and a generated document can say which runs made
its tables (:func:`read_provenance`, :func:`stamp`). Directories written before 2026-12-02
hold one ``provenance.json`` or ``provenance-<step>.json`` each; they are read too.
"""

from __future__ import annotations

import json
import os
import shlex
import subprocess
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from sgdata.dataset import Dataset

__all__ = [
    "PROCESS",
    "PROVENANCE",
    "ProcessState",
    "append_provenance",
    "provenance_record",
    "read_provenance",
    "stamp",
]

PROVENANCE = "provenance.jsonl"  # one JSON record per line, appended
UNKNOWN = "unknown"  # the commit when the code is not a git checkout (an installed package)
_CHECKOUT = Path(__file__).resolve().parents[1]  # the repository root, when it is one


def _utc_now() -> str:
    return time.strftime("%Y-%m-%d %H:%M:%S UTC", time.gmtime())


@dataclass(frozen=True)
class ProcessState:
    """The code a process runs and the command that started it, read at its start."""

    commit: str  # git HEAD of the checkout seannet was imported from, or UNKNOWN
    dirty: bool  # tracked files differed from that commit
    command: str  # the process's command line, shell-quoted
    loaded: str  # when seannet was imported (UTC)

    @classmethod
    def capture(cls, checkout: Path = _CHECKOUT, argv: Sequence[str] | None = None) -> ProcessState:
        """The state of ``checkout`` now (UNKNOWN and not dirty when it is no git checkout)."""
        commit, dirty = UNKNOWN, False
        if (checkout / ".git").exists():
            head = _git(checkout, "rev-parse", "HEAD")
            if head:
                commit = head
                dirty = bool(_git(checkout, "status", "--porcelain", "--untracked-files=no"))
        command = shlex.join(_program_named(list(sys.argv if argv is None else argv)))
        return cls(commit=commit, dirty=dirty, command=command, loaded=_utc_now())


def _program_named(argv: list[str]) -> list[str]:
    """``argv`` with a console script of this interpreter's environment named as typed
    (``seannet``, not ``/home/me/repo/.venv/bin/seannet``): the stamp should not carry the
    user's directories, and the name is what a reader types."""
    program = Path(argv[0]) if argv else None
    if program and program.is_absolute() and program.parent == Path(sys.executable).parent:
        return [program.name, *argv[1:]]
    return argv


def _git(checkout: Path, *args: str) -> str:
    try:
        done = subprocess.run(
            ["git", *args], cwd=checkout, capture_output=True, text=True, check=False, timeout=30
        )
    except (OSError, subprocess.SubprocessError):
        return ""
    return done.stdout.strip() if done.returncode == 0 else ""


PROCESS = ProcessState.capture()  # read once, when this process loaded seannet


def provenance_record(
    data: Path | Dataset | None, *, step: str | None = None, process: ProcessState = PROCESS
) -> dict[str, Any]:
    """One record: ``process``'s code and command, the time, and ``data``'s two identities
    when given: its recipe fingerprint (what was asked for, the same on every machine) and its
    manifest's sha256 (what this machine produced), with format and version and dataset seed;
    ``data`` is a dataset opened already (nothing is read again) or its root (opened here)."""
    record: dict[str, Any] = {
        "step": step,
        "commit": process.commit,
        "dirty": process.dirty,
        "code_loaded": process.loaded,
        "started": _utc_now(),
        "command": process.command,
        "pid": os.getpid(),
    }
    if data is None:
        return record
    from sgdata.dataset import Dataset  # here: importing seannet reads no Arrow

    dataset = data if isinstance(data, Dataset) else Dataset.open(Path(data))
    manifest = dataset.manifest
    record |= {
        "data": str(dataset.root),
        "recipe": manifest.recipe_fingerprint(),
        "manifest_sha256": dataset.manifest_sha256,
        "format": manifest.format,
        "format_version": manifest.format_version,
        "dataset_seed": manifest.config.get("dataset", {}).get("seed"),
    }
    return record


def append_provenance(
    directory: Path,
    data: Path | Dataset | None,
    *,
    step: str | None = None,
    process: ProcessState = PROCESS,
) -> dict[str, Any]:
    """Append :func:`provenance_record` as one line of ``directory/provenance.jsonl``
    (created with its directory); returns the record."""
    record = provenance_record(data, step=step, process=process)
    directory.mkdir(parents=True, exist_ok=True)
    line = json.dumps(record, sort_keys=True) + "\n"
    with open(directory / PROVENANCE, "a", encoding="utf-8") as f:  # one write per record
        f.write(line)
        f.flush()
        os.fsync(f.fileno())
    return record


def read_provenance(
    directory: Path, step: str | None = None, *, legacy: str | None = None
) -> list[dict[str, Any]]:
    """Every record of ``directory`` (of ``step`` when given), oldest first: the one record of
    a directory written before 2026-12-02 (``legacy``, by default ``provenance.json`` or
    ``provenance-<step>.json``) first, then ``provenance.jsonl``'s lines (a torn last line,
    from a killed process, is skipped)."""
    legacy = legacy or ("provenance.json" if step is None else f"provenance-{step}.json")
    old = directory / legacy
    records = [json.loads(old.read_text()) | {"step": step}] if old.is_file() else []
    path = directory / PROVENANCE
    if path.is_file():
        for line in path.read_text(encoding="utf-8").splitlines():
            try:
                record = json.loads(line)
            except ValueError:
                continue
            if step is None or record.get("step") == step:
                records.append(record)
    return records


def stamp(records: Sequence[dict[str, Any]]) -> str:
    """A markdown line naming every command of ``records`` (a process's call, which may
    train many runs): commit (and whether it had
    uncommitted changes), start, data fingerprint, command. Empty when there is none."""
    if not records:
        return ""
    parts = []
    for r in records:
        dirty = " with uncommitted changes" if r.get("dirty") else ""
        data = ""
        if r.get("manifest_sha256"):
            seed = r.get("dataset_seed")
            seed = f"dataset seed {seed}, " if seed is not None else ""
            recipe = f"recipe `{r['recipe'][:16]}…`, " if r.get("recipe") else ""
            data = (
                f" on `{r['data']}` ({seed}format {r.get('format_version')}, {recipe}manifest "
                f"sha256 `{r['manifest_sha256'][:16]}…`)"
            )
        parts.append(
            f"commit `{r['commit'][:10]}`{dirty}, started {r['started']}{data}: `{r['command']}`"
        )
    calls = "one command" if len(parts) == 1 else f"{len(parts)} commands"
    return f"*Made by {calls}: " + "; ".join(parts) + ".*"
