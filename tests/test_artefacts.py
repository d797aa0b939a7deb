"""The shared artefacts of a test run (tests/artefacts.py): built once, handed out read-only,
and a change in place is caught when the session ends."""

from __future__ import annotations

from pathlib import Path

import pytest

from . import artefacts


def test_an_artefact_is_built_once_and_handed_out_again(
    tmp_path_factory: pytest.TempPathFactory,
) -> None:
    built = []

    def build(path: Path) -> None:
        built.append(path)
        path.mkdir()
        (path / "data.txt").write_text("made once")

    first = artefacts.shared_artefact(tmp_path_factory, "built_once_probe", build)
    again = artefacts.shared_artefact(tmp_path_factory, "built_once_probe", build)
    assert first == again and (first / "data.txt").read_text() == "made once"
    # under xdist another worker may have built it first; either way, this process did not
    # build it twice
    assert len(built) <= 1


def test_a_change_in_place_is_caught_and_the_cache_is_not_one(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    run = tmp_path / "run"
    (run / artefacts.CACHES[0]).mkdir(parents=True)
    (run / "best.pt").write_bytes(b"weights")
    built = artefacts.fingerprint(run)
    monkeypatch.setitem(artefacts._HANDED_OUT, run, built)  # as if handed out by a fixture
    # the library's own cache fills in: not a change
    (run / artefacts.CACHES[0] / "test.npz").write_bytes(b"embeddings")
    assert artefacts.changed_artefacts() == []
    # a test writes beside the checkpoint: caught, by path
    (run / "eval_test.json").write_text("{}")
    assert artefacts.changed_artefacts() == [str(run)]
    (run / "eval_test.json").unlink()
    (run / "best.pt").write_bytes(b"retrained")  # the same names, other bytes: caught too
    assert artefacts.changed_artefacts() == [str(run)]
