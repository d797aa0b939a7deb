"""The detector: FCOS (Tian et al., https://arxiv.org/abs/1904.01355, torchvision's) on
EfficientNet-Lite0's stride 8 / 16 / 32 maps and a small feature pyramid.

A one-stage, anchor-free detector is what two CPU cores can train within an evidence unit's
45 minutes: Faster R-CNN's region head costs several times more a view. ImageNet weights come
only from the `lite` extra's Lite0 file; without it the backbone starts from random init.
"""

from __future__ import annotations

from collections import OrderedDict
from dataclasses import asdict, dataclass, fields
from typing import Any

from torch import Tensor, nn
from torchvision.models.detection import FCOS
from torchvision.models.detection.anchor_utils import AnchorGenerator
from torchvision.models.detection.fcos import FCOSHead
from torchvision.ops import FeaturePyramidNetwork

from seannet.errors import ModelError
from seannet.model.backbones import Lite0Pyramid
from seannet.weights import LITE0, LITE0_WEIGHTS, NETWORKS

__all__ = ["DetectorConfig", "build_detector"]


@dataclass(frozen=True)
class DetectorConfig:
    """How the detector is built and trained; stored in its run's ``detector.json``."""

    size: int = 320  # views are resized to size x size: small objects gain pixels
    fpn_channels: int = 64
    head_convs: int = 2  # convs of each FCOS tower (torchvision's default 4 costs twice)
    pretrained: str | None = LITE0_WEIGHTS  # None: random init
    epochs: int = 8
    batch_size: int = 8
    lr: float = 0.01
    weight_decay: float = 1e-4
    warmup_steps: int = 200
    epoch_views: int = 0  # train views an epoch draws (0: all): more, shorter epochs to choose from
    val_views: int = 400  # val views scored after each epoch to choose the epoch (0: all)
    seed: int = 0

    def __post_init__(self) -> None:
        for name in ("size", "fpn_channels", "head_convs", "epochs", "batch_size"):
            if getattr(self, name) < 1:
                raise ModelError(f"detector {name}={getattr(self, name)}; expected >= 1")
        for name in ("epoch_views", "val_views"):
            if getattr(self, name) < 0:
                raise ModelError(f"detector {name}={getattr(self, name)}; expected >= 0 (0: all)")
        if self.fpn_channels % 32:
            raise ModelError(
                f"detector fpn_channels={self.fpn_channels}; expected a multiple of 32 "
                "(FCOS's group norm has 32 groups)"
            )
        if not self.lr > 0:
            raise ModelError(f"detector lr={self.lr}; expected > 0")
        if self.pretrained not in (None, LITE0_WEIGHTS):
            raise ModelError(
                f"detector pretrained={self.pretrained!r}; expected {LITE0_WEIGHTS} or none"
            )

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> DetectorConfig:
        known = {f.name for f in fields(cls)}
        return cls(**{k: v for k, v in data.items() if k in known})


class _PyramidBackbone(nn.Module):
    """Lite0's three maps through a feature pyramid: what torchvision's FCOS expects (an
    ordered dict of maps of ``out_channels`` channels each)."""

    def __init__(self, config: DetectorConfig) -> None:
        super().__init__()
        self.body = Lite0Pyramid(pretrained=config.pretrained)
        self.fpn = FeaturePyramidNetwork(self.body.channels, config.fpn_channels)
        self.out_channels = config.fpn_channels
        # batches of 8 give BatchNorm noisy statistics: ImageNet's are kept as they are
        self.frozen_norm = config.pretrained is not None
        if self.frozen_norm:
            for m in self.body.modules():
                if isinstance(m, nn.BatchNorm2d):
                    m.requires_grad_(False)

    def train(self, mode: bool = True) -> _PyramidBackbone:
        super().train(mode)
        if self.frozen_norm:
            for m in self.body.modules():
                if isinstance(m, nn.BatchNorm2d):
                    m.eval()
        return self

    def forward(self, x: Tensor) -> OrderedDict[str, Tensor]:
        maps = self.body(x)
        return self.fpn(OrderedDict((str(i), m) for i, m in enumerate(maps)))


def build_detector(config: DetectorConfig, num_classes: int) -> FCOS:
    """FCOS for ``num_classes`` dataset classes (labels 1..num_classes, COCO's category ids:
    the class index + 1; 0 is background), with Lite0's input normalisation.

    Level sizes 8 / 16 / 32 are the maps' strides: FCOS gives each level the objects of
    4x to 8x its size (the first takes everything smaller, the last everything larger).
    """
    record = NETWORKS[LITE0]
    levels = len(Lite0Pyramid.STRIDES)
    return FCOS(
        _PyramidBackbone(config),
        num_classes=num_classes + 1,
        min_size=config.size,
        max_size=config.size,
        image_mean=list(record.mean),
        image_std=list(record.std),
        anchor_generator=AnchorGenerator(
            sizes=tuple((s,) for s in Lite0Pyramid.STRIDES), aspect_ratios=((1.0,),) * levels
        ),
        head=FCOSHead(config.fpn_channels, 1, num_classes + 1, num_convs=config.head_convs),
        score_thresh=0.05,
        detections_per_img=100,
    )
