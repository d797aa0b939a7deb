"""A method's spec is parsed once, where it comes in (a command's argument): ``parse_spec``
resolves it to a :class:`~seannet.model.specs.ResolvedSpec` and every layer below (the
method's factory, its configs, its training for every seed) takes that object."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from seannet.methods.bundled import NetworkMethod
from seannet.model.specs import ResolvedSpec
from tests.cli_runner import run_cli


@pytest.fixture
def parses(monkeypatch: pytest.MonkeyPatch) -> Iterator[list[str]]:
    """The text of every spec resolved in this process, in order (every parse ends in one
    ResolvedSpec, whichever module called the parser)."""
    made: list[str] = []
    real = ResolvedSpec.__init__

    def counted(self: ResolvedSpec, spec: str, *args: Any, **kwargs: Any) -> None:
        made.append(spec)
        real(self, spec, *args, **kwargs)

    monkeypatch.setattr(ResolvedSpec, "__init__", counted)
    yield made


def test_benchmark_parses_each_spec_once(
    tmp_path: Path, mini_dataset: Path, parses: list[str]
) -> None:
    # two seeds of a trained network with a scene term: a factory call, a config and a
    # training per seed, the lambda on val, the saved method, the card
    done = run_cli(
        "seannet", "benchmark", "--data", mini_dataset, "--methods", "tiny-image,resnet18+boxes",
        "--out", tmp_path / "cards", "--seeds", "0,1", "--batches", "1", "--epochs", "1",
        "--lrs", "0.01", "--preset", "smoke",
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert parses == ["resnet18+boxes"]  # was 9: 1 to find it, 2 per factory call, 2 per fit


def test_train_parses_its_spec_once(tmp_path: Path, mini_dataset: Path, parses: list[str]) -> None:
    # a scene term is refused after the one parse, before any work
    done = run_cli(
        "seannet", "train", "--data", mini_dataset, "--out", tmp_path / "run",
        "--model", "resnet18+boxes",
    )  # fmt: skip
    assert done.returncode != 0 and "scene term +boxes" in done.stderr
    assert parses == ["resnet18+boxes"]


def test_the_layers_below_take_only_the_resolved_spec() -> None:
    with pytest.raises(TypeError, match="ResolvedSpec"):
        NetworkMethod("resnet18+boxes")  # type: ignore[arg-type]
