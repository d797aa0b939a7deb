"""The model's hyper-parameters and their defaults, in one place (``ModelConfig``)."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

from seannet.errors import ModelError
from seannet.model.specs import ABLATION_FIELDS
from seannet.weights import IMAGE_SIZE, NETWORKS

__all__ = ["BACKBONES", "MODEL_FIELDS", "ModelConfig", "VISUAL_FEATURES"]

VISUAL_FEATURES = ("c4_head", "c5")
# SeanNet's image networks: the families of the registry's networks with a C4 map
BACKBONES = tuple(dict.fromkeys(r.family for r in NETWORKS.values() if r.c4_channels))
_DEPTHS = tuple(r.depth for r in NETWORKS.values() if r.depth)


@dataclass(frozen=True)
class ModelConfig:
    """What builds a model: its name and architecture knobs. Stored in every checkpoint (inside
    :class:`~seannet.training.config.TrainConfig`); :func:`~seannet.model.build_model`,
    :class:`~seannet.model.SeanNet` and the transforms read their defaults from here."""

    # seannet | an ablation (seannet-image, ...) | an image encoder of the registry
    # (seannet.model.specs.MODEL_NAMES lists them)
    name: str = "seannet"
    # SeanNet's image network: "resnet" (of ``depth``) or "efficientnet_lite0" (the `lite` extra)
    backbone: str = "resnet"
    depth: int = 50  # SeanNet's ResNet depth (18 / 34 / 50)
    image_size: int = IMAGE_SIZE  # square input size; boxes are scaled with the image
    roi_size: int = 14  # RoIAlign output; 14 on the 14 x 14 C4 map of a 224 input
    # SeanNet's x_v: "c4_head" (the paper: the head on every RoI crop) or "c5" (RoIAlign on
    # the 5th-stage map computed once per image: no head pass per object)
    visual_features: str = "c4_head"
    embed_dim: int = 2048
    # hidden width of the GCN's fc (M x 24 -> graph_hidden -> embed_dim); 4096 is the paper's,
    # and its 25 M weights are a fifth of a CPU training step (docs/benchmarks-2026-12-02.md,
    # "A training step")
    graph_hidden: int = 4096
    # cells per side of SeanNet's layout pathway (the scene graph's boxes slot by slot,
    # seannet.model.layers.SlotLayout); 0 leaves the paper's graph branch (GCN pathways only)
    layout_grid: int = 32
    # the pathway's M x grid^2 coordinates folded into this many by a count sketch (0: kept
    # as they are; 32 x 32 x 256 slots would be 262,144 numbers per view)
    layout_sketch: int = 16384
    dropout: float = 0.2  # on the GCN layers (paper §V-B)

    def __post_init__(self) -> None:
        self._apply_ablation_fields()
        for name in ("depth", "image_size", "roi_size", "embed_dim", "graph_hidden"):
            if getattr(self, name) < 1:
                raise ModelError(f"model.{name} must be >= 1, got {getattr(self, name)}")
        if self.visual_features not in VISUAL_FEATURES:
            raise ModelError(
                f"model.visual_features {self.visual_features!r}: expected one of "
                f"{', '.join(VISUAL_FEATURES)}"
            )
        if self.backbone not in BACKBONES:
            raise ModelError(
                f"model.backbone {self.backbone!r}: expected one of {', '.join(BACKBONES)}"
            )
        if self.depth not in _DEPTHS:
            raise ModelError(
                f"model.depth {self.depth}: expected one of {', '.join(map(str, _DEPTHS))}"
            )
        if not 0.0 <= self.dropout < 1.0:
            raise ModelError(f"model.dropout must be within [0, 1), got {self.dropout}")
        if self.layout_grid < 0 or self.layout_sketch < 0:
            raise ModelError(
                f"model.layout_grid and model.layout_sketch must be >= 0, got "
                f"{self.layout_grid} and {self.layout_sketch}"
            )

    @property
    def image_family(self) -> str:
        """The image network's family, which fixes the input normalisation."""
        record = NETWORKS.get(self.name)
        return record.family if record is not None else self.backbone

    def _apply_ablation_fields(self) -> None:
        """An ablation of :data:`~seannet.model.specs.ABLATION_FIELDS` sets its fields: a
        field at the default takes the ablation's value (configs saved before 2026-12-02 named
        ``seannet-fc512`` with ``graph_hidden`` 4096 and built 512), another value is refused."""
        for field, value in ABLATION_FIELDS.get(self.name, {}).items():
            given = getattr(self, field)
            if given == value:
                continue
            if given != _DEFAULTS[field]:
                raise ModelError(
                    f"model {self.name!r} has {field} {value}, got {given}: name "
                    f"{self.name!r} alone, or another model with {field} {given}"
                )
            object.__setattr__(self, field, value)  # frozen: set once, while constructing

    def replace(self, **changes: Any) -> ModelConfig:
        """A copy with some fields changed (validated again). Changing the name away from an
        ablation of :data:`~seannet.model.specs.ABLATION_FIELDS` resets the fields it set
        (``seannet-fc512`` -> ``seannet`` is the 4,096-wide fc again) unless given."""
        name = changes.get("name", self.name)
        if name != self.name:
            for field in ABLATION_FIELDS.get(self.name, {}):
                changes.setdefault(field, _DEFAULTS[field])
        return dataclasses.replace(self, **changes)


MODEL_FIELDS = frozenset(f.name for f in dataclasses.fields(ModelConfig))
_DEFAULTS = {f.name: f.default for f in dataclasses.fields(ModelConfig)}
