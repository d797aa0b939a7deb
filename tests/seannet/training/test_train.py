"""The trainer and evaluation on a real generated dataset: learning, exact resume, refusals."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
import torch

from seannet.data.datasets import ImageTransform, TripletDataset, collate_triplets
from seannet.errors import CheckpointError
from seannet.evaluation.run_eval import evaluate_run
from seannet.model.loss import TripletLoss
from seannet.seeds import init_seed
from seannet.training.config import TrainConfig
from seannet.training.runs import build_for_dataset, load_checkpoint
from seannet.training.train import train

from ...cli_runner import run_cli

# Small enough for a CPU test: the cpu preset's SeanNet (GCN fc 512 wide) on ResNet-18 at 64 px,
# 12 triplets an epoch, no loader workers.
FAST = TrainConfig().replace(
    model="seannet-fc512",
    depth=18,
    image_size=64,
    roi_size=4,
    embed_dim=256,
    epochs=4,
    batch_size=4,
    lr=0.01,
    max_train_batches=3,
    num_workers=0,
    decay_every=10,
)


def _loss_on_train_split(model: torch.nn.Module, data: Path) -> float:
    """The triplet loss over every training triplet (eval mode: no dropout)."""
    triplets = TripletDataset(
        data, "train", transform=ImageTransform.for_model(FAST.model.image_size)
    )
    anchor, positive, negative, _ = collate_triplets([triplets[i] for i in range(len(triplets))])
    with torch.no_grad():
        embed = model.eval().embed
        return float(TripletLoss(FAST.margin)(embed(anchor), embed(positive), embed(negative)))


def test_short_run_lowers_the_loss(tmp_path: Path, mini_dataset: Path) -> None:
    torch.manual_seed(init_seed(FAST.seed))  # the weights the run starts from
    before = _loss_on_train_split(build_for_dataset(FAST, mini_dataset), mini_dataset)
    results = train(FAST, mini_dataset, tmp_path / "run")
    assert len(results) == FAST.epochs
    trained = build_for_dataset(FAST, mini_dataset)
    trained.load_state_dict(load_checkpoint(tmp_path / "run" / "last.pt")["model"])
    # on the same triplets (the per-epoch losses are over 12 random ones each: too noisy)
    assert _loss_on_train_split(trained, mini_dataset) < before
    state = load_checkpoint(tmp_path / "run" / "best.pt")
    assert state["dataset"]["name"] == "mini"
    assert state["config"] == FAST.to_dict()
    result = evaluate_run(tmp_path / "run", mini_dataset, split="test")
    assert result["triplets"] == 10 and 0.0 <= result["accuracy"] <= 1.0
    assert set(result["per_tier"]) <= {0, 1, 2, 3, 4}
    assert (tmp_path / "run" / "heat_mean_test.png").read_bytes()[:4] == b"\x89PNG"
    assert result["examples"] and all(e["ids"][0] != e["ids"][-1] for e in result["examples"])
    assert (tmp_path / "run" / "examples_test.png").read_bytes()[:4] == b"\x89PNG"


def test_resume_continues_exactly(tmp_path: Path, mini_dataset: Path) -> None:
    config = FAST.replace(epochs=2)
    train(config, mini_dataset, tmp_path / "straight")
    train(config.replace(epochs=1), mini_dataset, tmp_path / "resumed")
    train(config, mini_dataset, tmp_path / "resumed", resume=True)
    straight = load_checkpoint(tmp_path / "straight" / "last.pt")["model"]
    resumed = load_checkpoint(tmp_path / "resumed" / "last.pt")["model"]
    for key, value in straight.items():
        assert torch.equal(value, resumed[key]), key


def test_other_dataset_and_existing_run_are_refused(tmp_path: Path, mini_dataset: Path) -> None:
    config = FAST.replace(epochs=1)
    train(config, mini_dataset, tmp_path / "run")
    with pytest.raises(CheckpointError, match="holds a run already"):
        train(config, mini_dataset, tmp_path / "run")
    other = tmp_path / "other"  # the same files under another dataset name
    shutil.copytree(mini_dataset, other)
    manifest = json.loads((other / "dataset.json").read_text())
    manifest["name"] = "someone-else"
    (other / "dataset.json").write_text(json.dumps(manifest, indent=2))
    with pytest.raises(CheckpointError, match="trained on dataset name='mini'"):
        evaluate_run(tmp_path / "run", other, split="test")
    with pytest.raises(CheckpointError, match="trained on dataset"):
        train(config.replace(epochs=2), other, tmp_path / "run", resume=True)


def test_cli_refuses_a_bad_pretrained_file(tmp_path: Path, mini_dataset: Path) -> None:
    bad = tmp_path / "weights.pth"
    bad.write_bytes(b"not a state dict")
    result = run_cli(
        "seannet", "train", "--data", mini_dataset, "--out", tmp_path / "r", "--pretrained", bad
    )
    assert result.returncode == 2, result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and "weights.pth" in lines[0] and "Traceback" not in result.stderr
