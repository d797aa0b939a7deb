"""The image-only baselines of the paper (§V): a CNN encoder → scene embedding, same loss."""

from __future__ import annotations

from pathlib import Path

from torch import Tensor, nn

from seannet.data.batch import SceneBatch
from seannet.errors import ModelError
from seannet.model.backbones import ENCODER_NAMES, image_encoder

__all__ = ["ImageEncoder", "ENCODER_NAMES"]


class ImageEncoder(nn.Module):
    r"""A torchvision CNN as a scene encoder: the image alone, no scene graph.

    The paper compares SeanNet with ResNet-50, ResNeXt-50, VGG-16 and GoogLeNet trained with
    the same triplet loss (https://arxiv.org/abs/2110.02276, §V-C). The network's classifier is
    dropped (see :func:`seannet.model.backbones.image_encoder`); where its native feature width
    differs from ``embed_dim`` (ResNet-18/34: 512, GoogLeNet: 1024, EfficientNet-Lite0: 1280,
    VGG-16: 4096), one linear
    layer projects it to ``embed_dim``, the width of SeanNet's fused vector, so the same
    similarity threshold analysis applies. ResNet-50 and ResNeXt-50 (2048) are used as is.

    Args:
        name: ``"resnet18"``, ``"resnet34"``, ``"resnet50"``, ``"resnext50"``, ``"vgg16"``,
            ``"googlenet"`` or ``"efficientnet_lite0"`` (the optional ``lite`` extra).
        embed_dim: width of the embedding (default 2048, as SeanNet's).
        pretrained: a local torchvision state_dict for the network (default: random init);
            for ``efficientnet_lite0`` also ``"imagenet-lite0"``, the ImageNet weights the
            ``lite`` extra installs.
        pretrained_sha256: its expected SHA-256 (default: torchvision's known weights).

    Shapes:
        - **images**: :math:`(B, 3, H, W)`
        - **output**: :math:`(B, \text{embed\_dim})`
    """

    def __init__(
        self,
        name: str,
        *,
        embed_dim: int = 2048,
        pretrained: str | Path | None = None,
        pretrained_sha256: str | None = None,
    ) -> None:
        super().__init__()
        if embed_dim <= 0:
            raise ModelError(f"embed_dim={embed_dim}; expected a positive integer")
        self.name = name
        self.embed_dim = embed_dim
        self.out_dim = embed_dim  # the embedding's width, as SeanNet.out_dim
        self.encoder, self.native_dim = image_encoder(
            name, pretrained=pretrained, sha256=pretrained_sha256
        )
        self.project: nn.Module = (
            nn.Identity() if self.native_dim == embed_dim else nn.Linear(self.native_dim, embed_dim)
        )

    def forward(self, images: Tensor) -> Tensor:
        return self.project(self.encoder(images))

    def embed(self, batch: SceneBatch) -> Tensor:
        """Scene embeddings of a batch's images (its scene graphs are ignored; uint8 images are
        normalised where they are, :meth:`SceneBatch.normalised_images`)."""
        return self(batch.normalised_images())

    def extra_repr(self) -> str:
        return f"name={self.name!r}, native_dim={self.native_dim}, embed_dim={self.embed_dim}"
