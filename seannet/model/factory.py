"""``build_model``: SeanNet, an ablation or an image baseline by name, from a ModelConfig."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import torch

from seannet.errors import ModelError
from seannet.model.baselines import ImageEncoder
from seannet.model.config import ModelConfig
from seannet.model.seannet import SeanNet
from seannet.model.specs import ABLATIONS, MODEL_NAMES, MODELS
from seannet.model.wordvectors import WordVectorTable
from sgdata.annotate.slots import NUM_SLOTS

__all__ = ["ABLATIONS", "LAYOUT_PRIOR", "MODEL_NAMES", "build_model"]

# the layout pathway's starting class weight by dynamics category: boxes of objects people
# move say little about the pose. On `medium`'s val triplets the layout vector alone ranked
# 70.7 % with every class at 1 and 75.7 % with high-dynamic classes at 0.25, and SeanNet's best
# val epochs averaged 91.0 against 89.8 % over 3 seeds (docs/results.md)
LAYOUT_PRIOR = {"static": 1.0, "low": 1.0, "high": 0.25}


def build_model(
    model: ModelConfig | str = "seannet",
    *,
    num_slots: int = NUM_SLOTS,
    word_vectors: WordVectorTable | None = None,
    class_names: Sequence[str] | None = None,
    class_dynamics: Sequence[str] | None = None,
    pretrained: Path | None = None,
    pretrained_sha256: str | None = None,
    **overrides: Any,
) -> SeanNet | ImageEncoder:
    """SeanNet or an image baseline; every model has ``embed(batch) -> (B, D)``.

    Args:
        model: a :class:`ModelConfig`, or a model name (``"seannet"``, an ablation of
            :data:`ABLATIONS`, a baseline of :data:`seannet.model.backbones.ENCODER_NAMES`)
            with :class:`ModelConfig`'s defaults.
        num_slots: SeanNet's M (the dataset's slot table).
        word_vectors: the class word-vector table (default: the shipped one).
        class_names: class-id order (default: the catalog's ``names()``).
        class_dynamics: each class's dynamics category, in the same order (default: the
            catalog's): SeanNet's layout class weights start at :data:`LAYOUT_PRIOR`.
        pretrained: a local torchvision state_dict file (default: random init, no download).
        pretrained_sha256: its expected SHA-256 (default: the known weights of the network).
        **overrides: :class:`ModelConfig` fields to change (``depth=18``).

    Raises:
        ModelError: an unknown name or a bad hyper-parameter or weights file.
        DataError: the word-vector table lacks a class.
    """
    config = ModelConfig(name=model) if isinstance(model, str) else model
    config = config.replace(**overrides) if overrides else config
    entry = MODELS.get(config.name)
    if entry is None:
        raise ModelError(f"model {config.name!r}; expected one of {', '.join(MODEL_NAMES)}")
    if not entry.seannet:
        return ImageEncoder(
            entry.name,
            embed_dim=config.embed_dim,
            pretrained=pretrained,
            pretrained_sha256=pretrained_sha256,
        )
    if word_vectors is None:
        from seannet.model.wordvectors import load_table

        word_vectors = load_table()
    if class_names is None:
        from sgdata.world.catalog import load_catalog

        catalog = load_catalog()
        class_names = catalog.names()
        class_dynamics = [str(catalog.classes[n].dynamics) for n in class_names]
    layout_weights = None
    if class_dynamics is not None:
        if len(class_dynamics) != len(class_names):
            raise ModelError(f"{len(class_dynamics)} class dynamics for {len(class_names)} classes")
        layout_weights = torch.tensor([LAYOUT_PRIOR[d] for d in class_dynamics])
    return SeanNet(
        word_vectors.matrix(class_names),
        depth=config.depth,
        num_slots=num_slots,
        roi_size=config.roi_size,
        embed_dim=config.embed_dim,
        dropout=config.dropout,
        pretrained=pretrained,
        pretrained_sha256=pretrained_sha256,
        visual_features=config.visual_features,
        layout_weights=layout_weights,
        **{
            "backbone": config.backbone,
            "layout_grid": config.layout_grid,
            "layout_sketch": config.layout_sketch,
            "graph_hidden_dim": config.graph_hidden,
            **entry.kwargs,
        },
    )
