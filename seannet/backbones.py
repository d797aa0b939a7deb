"""Image networks: ResNet split at C4 for SeanNet, and whole torchvision encoders for baselines.

Every network is built with ``weights=None`` (random init, nothing downloaded); ImageNet
weights come only from a local file via ``pretrained`` (see :mod:`seannet.pretrained`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from torch import nn
from torchvision import models

from seannet.errors import ModelError
from seannet.pretrained import load_pretrained

__all__ = [
    "RESNET_DEPTHS",
    "ENCODER_NAMES",
    "C4_STRIDE",
    "ResNetSplit",
    "resnet_c4",
    "image_encoder",
]

RESNET_DEPTHS: dict[int, Callable[..., models.ResNet]] = {
    18: models.resnet18,
    34: models.resnet34,
    50: models.resnet50,
}
C4_STRIDE = 16  # stem /4, layer2 /2, layer3 /2: the C4 map is 1/16 of the input

# baseline name -> (torchvision builder, native feature width after dropping the classifier)
_ENCODERS: dict[str, tuple[Callable[..., nn.Module], int]] = {
    "resnet18": (models.resnet18, 512),
    "resnet34": (models.resnet34, 512),
    "resnet50": (models.resnet50, 2048),
    "resnext50": (models.resnext50_32x4d, 2048),
    "vgg16": (models.vgg16, 4096),
    "googlenet": (models.googlenet, 1024),
}
ENCODER_NAMES = tuple(_ENCODERS)


@dataclass(frozen=True, eq=False)
class ResNetSplit:
    """A ResNet cut after its 4th stage (paper §IV-A: ResNet-50-C4 backbone + head).

    ``backbone`` maps (B, 3, H, W) to the C4 map (B, c4_channels, H/16, W/16); ``head``
    (5th stage + global average pool) maps any (N, c4_channels, h, w) to (N, head_dim).
    """

    backbone: nn.Sequential
    head: nn.Sequential
    c4_channels: int  # 1024 for ResNet-50, 256 for ResNet-18/34
    head_dim: int  # 2048 for ResNet-50, 512 for ResNet-18/34
    stride: int = C4_STRIDE


def resnet_c4(
    depth: int = 50, *, pretrained: Path | None = None, sha256: str | None = None
) -> ResNetSplit:
    """A torchvision ResNet-``depth`` split into a C4 backbone and its head.

    Args:
        depth: 18, 34 or 50.
        pretrained: a local torchvision ResNet state_dict to load before splitting.
        sha256: expected digest of ``pretrained`` (default: torchvision's known weights).

    Raises:
        ModelError: an unsupported depth, or pretrained weights that fail their checks.
    """
    if depth not in RESNET_DEPTHS:
        raise ModelError(f"ResNet depth={depth}; expected one of {sorted(RESNET_DEPTHS)}")
    net = RESNET_DEPTHS[depth](weights=None)
    if pretrained is not None:
        load_pretrained(net, pretrained, arch=f"resnet{depth}", sha256=sha256)
    backbone = nn.Sequential(
        net.conv1, net.bn1, net.relu, net.maxpool, net.layer1, net.layer2, net.layer3
    )
    head = nn.Sequential(net.layer4, net.avgpool, nn.Flatten(1))
    head_dim = net.fc.in_features
    return ResNetSplit(backbone, head, c4_channels=head_dim // 2, head_dim=head_dim)


def image_encoder(
    name: str, *, pretrained: Path | None = None, sha256: str | None = None
) -> tuple[nn.Module, int]:
    """A torchvision classifier without its last classification layer, and its output width.

    ResNet/ResNeXt and GoogLeNet lose ``fc`` (pooled features: 512, 2048 or 1024); VGG-16 loses
    its last linear layer (fc7 features, 4096). GoogLeNet is built with ``aux_logits=False``;
    with ``pretrained`` it is built as torchvision builds its ImageNet model (aux heads to
    load the file, then dropped; ``transform_input=True`` since those weights expect it).

    Args:
        name: one of :data:`ENCODER_NAMES`.
        pretrained: a local torchvision state_dict for that architecture.
        sha256: expected digest of ``pretrained`` (default: torchvision's known weights).

    Shapes:
        - **input**: :math:`(B, 3, H, W)`; GoogLeNet needs H, W >= 64-ish, VGG/ResNet >= 32
        - **output**: :math:`(B, \\text{width})`

    Raises:
        ModelError: an unknown name, or pretrained weights that fail their checks.
    """
    if name not in _ENCODERS:
        raise ModelError(f"image encoder {name!r}; expected one of {', '.join(ENCODER_NAMES)}")
    builder, width = _ENCODERS[name]
    if name == "googlenet":
        with_file = pretrained is not None
        net = builder(
            weights=None, aux_logits=with_file, transform_input=with_file, init_weights=True
        )
    else:
        net = builder(weights=None)
    if pretrained is not None:
        load_pretrained(net, pretrained, arch=name, sha256=sha256)
    if name == "googlenet":
        net.aux_logits, net.aux1, net.aux2 = False, None, None
    if name == "vgg16":
        net.classifier = net.classifier[:-1]  # keep fc6-ReLU-Dropout-fc7-ReLU-Dropout
    else:
        net.fc = nn.Identity()
    return net, width
