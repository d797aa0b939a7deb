"""Training configuration: presets (``cpu``, ``gpu``, ``paper``) as frozen dataclasses."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

from seannet.errors import ModelError

__all__ = ["PRESETS", "TrainConfig", "preset"]


@dataclass(frozen=True)
class TrainConfig:
    """Everything a training run depends on; stored in every checkpoint."""

    model: str = (
        "seannet"  # seannet | resnet18 | resnet34 | resnet50 | resnext50 | vgg16 | googlenet
    )
    # SeanNet's image network: "resnet" (of ``depth``) or "efficientnet_lite0" (the `lite` extra)
    backbone: str = "resnet"
    depth: int = 50  # SeanNet's ResNet depth (18 / 34 / 50)
    image_size: int = 224  # square input size; boxes are scaled with the image
    roi_size: int = 14  # RoIAlign output; 14 on the 14 x 14 C4 map of a 224 input
    # SeanNet's x_v: "c4_head" (the paper: the head on every RoI crop) or "c5" (RoIAlign on
    # the 5th-stage map computed once per image: no head pass per object)
    visual_features: str = "c4_head"
    embed_dim: int = 2048
    # cells per side of SeanNet's layout pathway (the scene graph's boxes slot by slot,
    # seannet.layers.SlotLayout); 0 leaves the paper's graph branch (GCN pathways only)
    layout_grid: int = 32
    # the pathway's M x grid^2 coordinates folded into this many by a count sketch (0: kept
    # as they are). On medium's val triplets the boxes alone rank 80.3 % at grid 8, 82.3 % at
    # 32 unsketched (262,144 numbers per view) and 82.1 % at 32 sketched to 16,384
    layout_sketch: int = 16384
    dropout: float = 0.2  # on the GCN layers (paper §V-B)
    epochs: int = 60
    batch_size: int = 14  # the paper's SeanNet batch
    lr: float = 0.01  # SGD (paper §V-B)
    # learning rate of the layers SeanNet adds (object fcn, GCN, fusion) relative to ``lr``
    new_layers_lr_scale: float = 1.0
    momentum: float = 0.9
    lr_decay: float = 0.7  # x0.7 ...
    decay_every: int = 10  # ... every 10 epochs
    margin: float = 0.1  # triplet loss margin
    num_workers: int = 2  # DataLoader workers
    max_train_batches: int = 0  # per epoch; 0 = the whole split (a CPU budget knob)
    max_val_triplets: int = 0  # validated per epoch, evenly spaced; 0 = the whole split
    seed: int = 0

    def __post_init__(self) -> None:
        positive = ("depth", "image_size", "roi_size", "embed_dim", "epochs", "batch_size")
        for name in positive:
            if getattr(self, name) < 1:
                raise ModelError(f"train.{name} must be >= 1, got {getattr(self, name)}")
        if self.visual_features not in ("c5", "c4_head"):
            raise ModelError(
                f"train.visual_features {self.visual_features!r}: expected 'c5' or 'c4_head'"
            )
        if self.backbone not in ("resnet", "efficientnet_lite0"):
            raise ModelError(
                f"train.backbone {self.backbone!r}: expected 'resnet' or 'efficientnet_lite0'"
            )
        if self.depth not in (18, 34, 50):
            raise ModelError(f"train.depth {self.depth}: expected 18, 34 or 50")
        if not 0.0 <= self.dropout < 1.0:
            raise ModelError(f"train.dropout must be within [0, 1), got {self.dropout}")
        if self.layout_grid < 0 or self.layout_sketch < 0:
            raise ModelError(
                f"train.layout_grid and train.layout_sketch must be >= 0, got "
                f"{self.layout_grid} and {self.layout_sketch}"
            )
        if self.new_layers_lr_scale <= 0:
            raise ModelError(
                f"train.new_layers_lr_scale must be > 0, got {self.new_layers_lr_scale}"
            )
        if self.lr <= 0 or self.margin < 0 or self.decay_every < 1 or self.num_workers < 0:
            raise ModelError("train: lr > 0, margin >= 0, decay_every >= 1, num_workers >= 0")

    @property
    def image_family(self) -> str:
        """The image network's family, which fixes the input normalisation."""
        lite = "efficientnet_lite0"
        return lite if lite in (self.model, self.backbone) else "resnet"

    @classmethod
    def from_dict(cls, raw: dict[str, Any]) -> TrainConfig:
        """The config a checkpoint stored (:meth:`to_dict`). Checkpoints written before the
        layout pathway existed lack ``layout_grid`` (their models had none: 0), those written
        before its sketch lack ``layout_sketch`` (their pathways kept every coordinate: 0)."""
        return cls(**{"layout_grid": 0, "layout_sketch": 0, **raw})

    def replace(self, **changes: Any) -> TrainConfig:
        """A copy with some fields changed (validated again)."""
        return dataclasses.replace(self, **changes)

    def to_dict(self) -> dict[str, Any]:
        """Plain form for checkpoints and reports."""
        return dataclasses.asdict(self)


PRESETS: dict[str, TrainConfig] = {
    # The paper: ResNet-50 at 224 px, 60 epochs, SGD 0.01 x0.7 every 10 epochs, margin 0.1.
    "paper": TrainConfig(),
    # Two CPU cores in about half an hour for SeanNet: ResNet-18 at 112 px (C4 7 x 7,
    # RoIAlign 7), 5 epochs of 24 batches of 16 triplets with the paper's x0.7 decay every 2.
    # Measured here: a SeanNet step takes 9.5 s, a ResNet-18 baseline step 2.0 s. Loader
    # workers would only compete with torch for the two cores.
    "cpu": TrainConfig(
        depth=18,
        image_size=112,
        roi_size=7,
        visual_features="c5",
        # with 1 the GCN pathways moved ~10x less than the backbone in the first batches
        # (bench/branch_motion.py); 10 brings object fcn, GCN and fusion to its order
        new_layers_lr_scale=10.0,
        epochs=5,
        batch_size=16,
        decay_every=2,
        max_train_batches=24,
        max_val_triplets=160,
        num_workers=0,
    ),
    # One GPU (run on an H100 with 16 cores, docs/results.md): ResNet-18 at the datasets'
    # 224 px, x_v from the 5th-stage map, the cpu preset's schedule; loader workers decode the
    # PNGs in parallel (the runs there were still loader-bound).
    "gpu": TrainConfig(
        depth=18,
        roi_size=14,
        visual_features="c5",
        new_layers_lr_scale=10.0,
        epochs=5,
        batch_size=16,
        decay_every=2,
        max_val_triplets=320,
        num_workers=12,
    ),
}


def preset(name: str) -> TrainConfig:
    """A preset by name.

    Raises:
        ModelError: unknown preset.
    """
    try:
        return PRESETS[name]
    except KeyError:
        raise ModelError(f"unknown preset {name!r}; expected one of {', '.join(PRESETS)}") from None
