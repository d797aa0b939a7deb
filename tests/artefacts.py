"""Artefacts built once per test run and shared by every pytest-xdist worker, read-only.

A shared artefact (the mini dataset, a trained run, a map) is built by whichever worker asks
first, under a file lock in the run's base temp folder; the others wait and then read it. Its
fingerprint (every file's path and bytes) is taken when it is built and checked again when the
session ends: a test that changed a shared artefact instead of copying it first fails the run.
"""

from __future__ import annotations

import hashlib
import os
import shutil
from collections.abc import Callable
from pathlib import Path

import pytest
from filelock import FileLock

# path -> fingerprint taken when it was built, for every artefact this process handed out
_HANDED_OUT: dict[Path, str] = {}


def run_folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The folder this whole test run shares: the base temp of the controller under xdist
    (each worker's own base temp is a child of it), this session's base temp otherwise."""
    base = tmp_path_factory.getbasetemp()
    return base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base


# Folders the library itself keeps inside an artefact by design, left out of its fingerprint:
# a run's embedding cache (seannet.evaluation.embedding_cache: keyed by checkpoint, data and
# code, written atomically, so workers that fill it at once write the same bytes).
CACHES = ("embeddings",)


def fingerprint(root: Path) -> str:
    """sha256 over every file's relative path and bytes under ``root`` (a file or a folder),
    the :data:`CACHES` folders left out."""
    digest = hashlib.sha256()
    files = (
        sorted(
            p
            for p in root.rglob("*")
            if p.is_file() and not set(p.relative_to(root).parts[:-1]) & set(CACHES)
        )
        if root.is_dir()
        else [root]
    )
    for path in files:
        digest.update(str(path.relative_to(root) if root.is_dir() else path.name).encode())
        digest.update(b"\0")
        digest.update(hashlib.sha256(path.read_bytes()).digest())
    return digest.hexdigest()


def shared_artefact(
    tmp_path_factory: pytest.TempPathFactory, name: str, build: Callable[[Path], None]
) -> Path:
    """The artefact ``name``: ``build(path)`` runs once per test run, whichever worker asks
    first; later callers (other workers too) get the same path. Hand it out read-only: a
    test that changes it copies it first (``shutil.copytree``)."""
    folder = run_folder(tmp_path_factory) / "shared" / name
    path, stamp = folder / name, folder / "fingerprint"
    folder.mkdir(parents=True, exist_ok=True)
    with FileLock(folder / "lock"):
        if not stamp.exists():
            shutil.rmtree(path, ignore_errors=True)  # what a failed build left
            build(path)
            stamp.write_text(fingerprint(path))
    _HANDED_OUT[path] = stamp.read_text()
    return path


def changed_artefacts() -> list[str]:
    """The artefacts this process handed out whose files changed since they were built."""
    return [str(path) for path, built in _HANDED_OUT.items() if fingerprint(path) != built]
