"""Image-only baselines: every encoder's forward shape, projection and batch interface."""

from __future__ import annotations

import pytest
import torch
from torch import nn

from seannet import ImageEncoder, ModelError, SceneBatch, build_model
from seannet.model.backbones import ENCODER_NAMES


def _images_only(b: int, size: int) -> SceneBatch:
    return SceneBatch(
        images=torch.randn(b, 3, size, size),
        boxes=torch.zeros(0, 4),
        box_view=torch.zeros(0, dtype=torch.long),
        class_ids=torch.zeros(0, dtype=torch.long),
        slots=torch.zeros(0, dtype=torch.long),
        adjacency=torch.zeros(b, 3, 4, 4),
    )


# (name, input size, native width); one small run each keeps VGG-16 and GoogLeNet quick
CASES = [
    ("resnet18", 64, 512),
    ("resnet34", 64, 512),
    ("resnet50", 64, 2048),
    ("resnext50", 64, 2048),
    ("vgg16", 32, 4096),
    ("googlenet", 64, 1024),
    # the optional `lite` extra; skipped without it (see tests/seannet/test_backbones_lite.py)
    ("efficientnet_lite0", 64, 1280),
]


def test_every_baseline_is_tested() -> None:
    assert {c[0] for c in CASES} == set(ENCODER_NAMES)


@pytest.mark.parametrize(("name", "size", "native"), CASES)
def test_baseline_embeds_images_to_2048(name: str, size: int, native: int) -> None:
    if name == "efficientnet_lite0":
        pytest.importorskip("efficientnet_lite_pytorch", reason="the optional `lite` extra")
    torch.manual_seed(0)
    model = build_model(name).eval()
    assert isinstance(model, ImageEncoder)
    assert model.native_dim == native
    if native == 2048:
        assert isinstance(model.project, nn.Identity)
    else:
        assert isinstance(model.project, nn.Linear) and model.project.in_features == native
    batch = _images_only(2, size)
    with torch.no_grad():
        out = model.embed(batch)
        assert torch.equal(out, model(batch.images))
    assert out.shape == (2, 2048)
    assert torch.isfinite(out).all()


def test_googlenet_has_no_aux_heads() -> None:
    model = ImageEncoder("googlenet", embed_dim=64)
    assert model.encoder.aux_logits is False
    assert model.encoder.aux1 is None and model.encoder.aux2 is None
    model.train()  # train mode would return aux outputs if they were on
    out = model(torch.randn(2, 3, 64, 64))
    assert isinstance(out, torch.Tensor) and out.shape == (2, 64)


def test_unknown_baseline_names_the_choices() -> None:
    with pytest.raises(ModelError, match="'alexnet'.*resnet18.*googlenet"):
        ImageEncoder("alexnet")
    with pytest.raises(ModelError, match="embed_dim=0"):
        ImageEncoder("resnet18", embed_dim=0)
