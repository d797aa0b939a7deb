"""The navigator's training: pairs rendered once into a resumable cache, val accuracy on
pairs it never trained on, per action and per goal distance, best.pt chosen on it."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from seannet.data.datasets import dataset_identity
from seannet.data.live_views import LiveRooms
from seannet.navigation.navigator import (
    NavigatorConfig,
    VisualNavigator,
    load_navigator,
    navigator_inputs,
)
from seannet.navigation.navigator_training import jitter, pair_accuracy, train_navigator
from seannet.navigation.pairs import render_pairs
from seannet.training.runs import load_checkpoint

CONFIG = NavigatorConfig(
    image_size=64, hidden=16, epochs=2, batch_size=8, train_pairs=24, val_pairs=12
)


def test_pairs_are_cached_and_val_pairs_are_never_trained_on(
    mini_dataset: Path, tmp_path: Path
) -> None:
    cache = tmp_path / "pairs"
    history = train_navigator(CONFIG, mini_dataset, tmp_path / "a", cache=cache)
    files = sorted(cache.glob("*/*.npz"))
    assert [f.parent.name.split("-")[0] for f in files] == ["train", "val"]
    stamps = {f: f.stat().st_mtime_ns for f in files}

    # a killed render resumes at its next room: the missing room is rendered again, the
    # same pixels; the cached one is read, not rendered
    val_file = next(f for f in files if f.parent.name.startswith("val"))
    before = dict(np.load(val_file))
    val_file.unlink()
    again = train_navigator(CONFIG, mini_dataset, tmp_path / "b", cache=cache)
    after = dict(np.load(val_file))
    assert before.keys() == after.keys()
    assert all(np.array_equal(before[k], after[k]) for k in before)
    train_file = next(f for f in files if f.parent.name.startswith("train"))
    assert train_file.stat().st_mtime_ns == stamps[train_file]
    # same config and seed: the same training, read from the cache
    assert [h["val_accuracy"] for h in again] == [h["val_accuracy"] for h in history]

    with LiveRooms(mini_dataset) as live:
        identity = dataset_identity(mini_dataset)
        train = render_pairs(
            live, "train", CONFIG.train_pairs, CONFIG, cache=cache, identity=identity
        )
        val = render_pairs(live, "val", CONFIG.val_pairs, CONFIG, cache=cache, identity=identity)
    assert len(train) == CONFIG.train_pairs and len(val) == CONFIG.val_pairs
    # never trained on: other rooms, and not one val image pair among the train pairs
    assert not set(val.rooms.tolist()) & set(train.rooms.tolist())
    seen = {(c.tobytes(), g.tobytes()) for c, g in zip(train.current, train.goal, strict=True)}
    assert not any(
        (c.tobytes(), g.tobytes()) in seen for c, g in zip(val.current, val.goal, strict=True)
    )

    # best.pt is the epoch of the best val accuracy, and that accuracy is the val pairs'
    best = max(history, key=lambda h: h["val_accuracy"])
    state = load_checkpoint(tmp_path / "a" / "best.pt")
    assert state["epoch"] == best["epoch"]
    policy = load_navigator(tmp_path / "a")
    report = pair_accuracy(policy.model, val, CONFIG, policy.device)
    assert report["val_accuracy"] == best["val_accuracy"]
    for part in ("val_by_action", "val_by_distance"):
        cells = report[part].values()
        assert sum(n for _, n in cells) == len(val)
        assert sum(a * n for a, n in cells) / len(val) == pytest.approx(report["val_accuracy"])
    assert set(report["val_by_action"]) <= {"forward", "left", "right"}
    assert all(
        1 <= int(d) <= CONFIG.max_forward + CONFIG.max_side for d in report["val_by_distance"]
    )


def test_what_the_test_changes_can_be_trained_for(mini_dataset: Path) -> None:
    # light: each view its own brightness and contrast, drawn from the epoch's stream
    views = np.random.default_rng(0).integers(0, 256, size=(4, 8, 8, 3), dtype=np.uint8)
    assert np.array_equal(jitter(views, np.random.default_rng(1), 0.0), views)
    a, b = (jitter(views, np.random.default_rng(1), 0.3) for _ in range(2))
    assert np.array_equal(a, b) and not np.array_equal(a, views) and a.dtype == np.uint8
    # moved objects, their looks, the light: goal views of another layout, same label rule
    config = CONFIG.replace(cross_layout=1.0)
    with LiveRooms(mini_dataset) as live:
        pairs = render_pairs(live, "val", 8, config)
        same = render_pairs(live, "val", 8, CONFIG)
    crossed = pairs.poses[:, 0] != pairs.poses[:, 4]
    assert crossed.sum() >= len(pairs) // 2  # where the goal cell is free in the other layout
    assert (same.poses[:, 0] == same.poses[:, 4]).all()
    assert set(pairs.distances().tolist()) <= set(range(1, 7))
    # an ImageNet-initialised encoder (EfficientNet-Lite0, its own input normalisation)
    net = VisualNavigator("efficientnet_lite0", hidden=16, pretrained=Path("imagenet-lite0"))
    inputs = navigator_inputs(pairs.current[:2], "efficientnet_lite0")
    assert inputs.min() >= -1.0 and net(inputs, inputs).shape == (2, 3)


def test_early_fusion_sees_both_views_in_its_first_convolution(tmp_path: Path) -> None:
    import torch

    torch.manual_seed(0)
    late = VisualNavigator("resnet18", hidden=16, fusion="late")
    early = VisualNavigator("resnet18", hidden=16, fusion="early")
    assert early.encoder.conv1.in_channels == 6 and late.encoder.conv1.in_channels == 3
    x = torch.randn(2, 3, 64, 64)
    y = torch.randn(2, 3, 64, 64)
    assert early(x, y).shape == late(x, y).shape == (2, 3)
    # ImageNet weights are split between the two views: the same view twice looks as before
    lite = VisualNavigator(
        "efficientnet_lite0", hidden=16, pretrained=Path("imagenet-lite0"), fusion="late"
    )
    lite_early = VisualNavigator(
        "efficientnet_lite0", hidden=16, pretrained=Path("imagenet-lite0"), fusion="early"
    )
    lite.eval(), lite_early.eval()
    with torch.no_grad():
        features = lite.encoder(x)
        torch.testing.assert_close(lite_early.encoder(torch.cat([x, x], 1)), features)
    with pytest.raises(Exception, match="fusion 'middle'"):
        NavigatorConfig(fusion="middle")


def test_a_navigator_saved_before_fusion_existed_loads_as_siamese(
    mini_dataset: Path, tmp_path: Path
) -> None:
    import torch

    train_navigator(CONFIG.replace(epochs=1, fusion="late"), mini_dataset, tmp_path / "nav")
    state = load_checkpoint(tmp_path / "nav" / "best.pt")
    del state["config"]["fusion"]
    torch.save(state, tmp_path / "nav" / "best.pt")
    policy = load_navigator(tmp_path / "nav")
    assert policy.config.fusion == "late" and policy.model.fusion == "late"
