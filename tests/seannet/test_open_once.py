"""A command opens its dataset once (STYLE.md habit 15): ``dataset.json`` is read one time per
``benchmark``, ``compare``, ``eval``, ``train`` or ``train-navigator``, however many loaders,
checkpoints and records sit below."""

from __future__ import annotations

import builtins
import io
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from seannet.evaluation.compare import compare_models
from seannet.evaluation.run_eval import evaluate_run
from seannet.training.config import TrainConfig
from seannet.training.train import train
from sgdata.dataset.paths import MANIFEST
from tests.cli_runner import run_cli

# one spawned worker for the module's one-worker navigations (conftest.one_pool)
pytestmark = pytest.mark.usefixtures("one_pool")

TINY = TrainConfig().replace(
    model="resnet18",
    image_size=64,
    embed_dim=64,
    epochs=1,
    batch_size=2,
    max_train_batches=1,
    num_workers=0,
)


class ManifestReads:
    """Counts every opening of a ``dataset.json`` in this process (``open``, ``io.open`` and
    so ``Path.read_text`` / ``read_bytes``), by file."""

    def __init__(self) -> None:
        self.paths: list[Path] = []

    def wrap(self, real: Any) -> Any:
        def counted(file: Any, *args: Any, **kwargs: Any) -> Any:
            if isinstance(file, (str, Path)) and Path(file).name == MANIFEST:
                self.paths.append(Path(file).resolve())
            return real(file, *args, **kwargs)

        return counted

    def of(self, root: Path) -> int:
        return self.paths.count((root / MANIFEST).resolve())


@pytest.fixture
def manifest_reads(monkeypatch: pytest.MonkeyPatch) -> Iterator[ManifestReads]:
    reads = ManifestReads()
    real = io.open
    monkeypatch.setattr(io, "open", reads.wrap(real))
    monkeypatch.setattr(builtins, "open", reads.wrap(real))
    yield reads


def test_compare_reads_the_manifest_once(
    tmp_path: Path, mini_dataset: Path, manifest_reads: ManifestReads
) -> None:
    # calibration, training (loaders, model, checkpoint identity, provenance), evaluation on
    # val and test with and without the box term (embedding cache key, moved objects), counts
    compare_models(
        mini_dataset,
        tmp_path / "cmp",
        ["resnet18", "resnet18+boxes"],
        preset=TINY,
        seeds=(0,),
        lrs=(0.01,),
        budget_s=0.001,
    )
    assert manifest_reads.of(mini_dataset) == 1


def test_train_and_eval_read_the_manifest_once_each(
    tmp_path: Path, mini_dataset: Path, manifest_reads: ManifestReads
) -> None:
    run = tmp_path / "run"
    train(TINY, mini_dataset, run)
    assert manifest_reads.of(mini_dataset) == 1
    evaluate_run(run, mini_dataset, split="val", boxes="+box-kernel")
    assert manifest_reads.of(mini_dataset) == 2


def test_train_navigator_reads_the_manifest_once(
    tmp_path: Path, mini_dataset: Path, manifest_reads: ManifestReads
) -> None:
    # identity, provenance and the live rooms that render its pairs share one opening
    from seannet.navigation.navigator import NavigatorConfig
    from seannet.navigation.navigator_training import train_navigator

    config = NavigatorConfig(
        image_size=64, hidden=16, epochs=1, batch_size=8, train_pairs=8, val_pairs=4
    )
    train_navigator(config, mini_dataset, tmp_path / "nav")
    assert manifest_reads.of(mini_dataset) == 1


def test_benchmark_reads_the_manifest_once(
    tmp_path: Path, mini_dataset: Path, manifest_reads: ManifestReads
) -> None:
    # a frozen baseline and a bundled network: the harness's loaders, the network's training
    # (identity, checkpoints, its lambda on val), the moved objects, the saved method, the card
    done = run_cli(
        "seannet", "benchmark", "--data", mini_dataset, "--methods", "tiny-image,resnet18+boxes",
        "--out", tmp_path / "cards", "--seeds", "0", "--batches", "1", "--epochs", "1",
        "--lrs", "0.01", "--preset", "smoke",
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert manifest_reads.of(mini_dataset) == 1


def test_map_localize_and_navigate_read_the_manifest_once_each(
    tmp_path: Path, mini_dataset: Path, localizer_run: Path, manifest_reads: ManifestReads
) -> None:
    # the localizer's identity, the live rooms that render the sub-nodes, the maps and the
    # queries' loader share the command's one opening (navigate's episodes run in worker
    # processes, which open their own)
    maps = tmp_path / "maps"
    done = run_cli("seannet", "map", localizer_run, "--data", mini_dataset, "--out", maps)
    assert done.returncode == 0, done.stderr
    assert manifest_reads.of(mini_dataset) == 1
    done = run_cli(
        "seannet", "localize", localizer_run, "--map", maps, "--data", mini_dataset,
        "--split", "test", "--epsilon", "0.9", "--out", tmp_path / "loc",
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert manifest_reads.of(mini_dataset) == 2
    done = run_cli(
        "seannet", "navigate", localizer_run, "--data", mini_dataset, "--oracle",
        "--episodes", "1", "--epsilon", "0.9", "--maps", maps, "--out", tmp_path / "nav",
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert manifest_reads.of(mini_dataset) == 3


def test_benchmark_with_its_navigation_test_reads_the_manifest_once(
    tmp_path: Path, mini_dataset: Path, navigation_run: Any, manifest_reads: ManifestReads
) -> None:
    done = run_cli(
        "seannet", "benchmark", "--data", mini_dataset, "--methods", "tiny-image",
        "--out", tmp_path / "cards", "--seeds", "0", "--navigator", navigation_run.navigator,
        "--episodes", "1",
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "cards" / "tiny-image" / "navigation").is_dir()
    assert manifest_reads.of(mini_dataset) == 1
