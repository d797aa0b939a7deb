"""Training configuration: presets (``cpu``, ``gpu``, ``paper``) as frozen dataclasses."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

from seannet.errors import ModelError
from seannet.model.config import MODEL_FIELDS, ModelConfig

__all__ = ["DEFAULT_PRESET", "PRESETS", "TrainConfig", "preset"]


@dataclass(frozen=True)
class TrainConfig:
    """Everything a training run depends on; stored in every checkpoint. The model's own
    hyper-parameters live in :class:`~seannet.model.config.ModelConfig` (``model``)."""

    model: ModelConfig = ModelConfig()
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
        if not isinstance(self.model, ModelConfig):
            raise ModelError(f"train.model must be a ModelConfig, got {type(self.model).__name__}")
        for name in ("epochs", "batch_size"):
            if getattr(self, name) < 1:
                raise ModelError(f"train.{name} must be >= 1, got {getattr(self, name)}")
        if self.new_layers_lr_scale <= 0:
            raise ModelError(
                f"train.new_layers_lr_scale must be > 0, got {self.new_layers_lr_scale}"
            )
        if self.lr <= 0 or self.margin < 0 or self.decay_every < 1 or self.num_workers < 0:
            raise ModelError("train: lr > 0, margin >= 0, decay_every >= 1, num_workers >= 0")

    @classmethod
    def from_dict(cls, raw: dict[str, Any]) -> TrainConfig:
        """The config a checkpoint stored (:meth:`to_dict`). Checkpoints written before
        ``ModelConfig`` held the model's fields at the top level with ``model`` its name;
        those written before the layout pathway lack ``layout_grid`` (their models had none:
        0), those written before its sketch lack ``layout_sketch`` (unsketched: 0)."""
        raw = dict(raw)
        model = raw.pop("model")
        if isinstance(model, str):  # the flat form
            legacy = {"layout_grid": 0, "layout_sketch": 0}
            model = {
                "name": model,
                **legacy,
                **{k: raw.pop(k) for k in list(raw) if k in MODEL_FIELDS},
            }
        return cls(model=ModelConfig(**model), **raw)

    def replace(self, **changes: Any) -> TrainConfig:
        """A copy with some fields changed (validated again). Fields of the model may be
        given here too (``depth=18``); ``model`` takes a ModelConfig or a model name."""
        model = changes.pop("model", self.model)
        if isinstance(model, str):
            model = self.model.replace(name=model)
        model_changes = {k: changes.pop(k) for k in list(changes) if k in MODEL_FIELDS}
        if model_changes:
            model = model.replace(**model_changes)
        return dataclasses.replace(self, model=model, **changes)

    def to_dict(self) -> dict[str, Any]:
        """Plain form for checkpoints and reports."""
        return dataclasses.asdict(self)


# The schedule the cpu and gpu presets share: ResNet-18, x_v from the 5th-stage map, 5 epochs
# of batches of 16 with the paper's x0.7 decay every 2 epochs.
_SHORT_SCHEDULE: dict[str, Any] = {
    "depth": 18,
    "visual_features": "c5",
    # with 1 the GCN pathways moved ~10x less than the backbone in the first batches
    # (bench/branch_motion.py); 10 brings object fcn, GCN and fusion to its order
    "new_layers_lr_scale": 10.0,
    "epochs": 5,
    "batch_size": 16,
    "decay_every": 2,
}

# The preset a command trains with when none is named: this project's machines have no GPU
DEFAULT_PRESET = "cpu"

# The default: two CPU cores in about half an hour for SeanNet, the short schedule at 112 px
# (C4 7 x 7, RoIAlign 7), 24 batches an epoch. Its model is seannet-fc512 (the GCN's fc 512
# wide, not the paper's 4,096): a step near ResNet-18's (docs/benchmarks.md, "A training
# step"), as accurate under wave 3's protocol (docs/training.md, presets). Loader workers
# would only compete with torch for the two cores.
_CPU = TrainConfig().replace(
    model="seannet-fc512",
    **_SHORT_SCHEDULE,
    image_size=112,
    roi_size=7,
    max_train_batches=24,
    max_val_triplets=160,
    num_workers=0,
)

PRESETS: dict[str, TrainConfig] = {
    # The paper: ResNet-50 at 224 px, 60 epochs, SGD 0.01 x0.7 every 10 epochs, margin 0.1.
    "paper": TrainConfig(),  # every default: ModelConfig's and the fields above
    DEFAULT_PRESET: _CPU,
    # One GPU (run on an H100 with 16 cores, docs/results.md): the short schedule at the
    # datasets' 224 px with the paper's SeanNet; loader workers decode the PNGs in parallel
    # (the runs there were still loader-bound).
    "gpu": TrainConfig().replace(
        **_SHORT_SCHEDULE,
        roi_size=14,
        max_val_triplets=320,
        num_workers=12,
    ),
    # A smoke run: the cpu preset at 64 px (C5 2 x 2, RoIAlign 4), a third of cpu's pixels
    # (the tests' tiny protocol: 13.1 s against 28.6 s at 112 px). It checks that a chain (a
    # method in the benchmark, a protocol, navigation) runs on your data; its figures are not
    # comparable with cpu's. The test suite trains with it.
    "smoke": _CPU.replace(image_size=64, roi_size=4),
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
