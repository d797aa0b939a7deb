"""Model specs, ``NAME[@net][+imagenet][+boxes|+box-kernel]``: the bundled models they may
name (:data:`MODELS`, one entry each) and the one parser that resolves a spec, once, at the
edge (:func:`parse_spec` -> :class:`ResolvedSpec`); every layer below takes the resolved spec.

Plain data, no torch: the CLI prints its help from here, so naming a model loads nothing. The
image networks come from the registry (:data:`seannet.weights.NETWORKS`); the SeanNet
ablations and the scene terms are listed here, once.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from seannet.errors import ModelError
from seannet.weights import IMAGE_ENCODERS, NETWORKS

__all__ = [
    "ABLATIONS",
    "ABLATION_FIELDS",
    "IMAGENET",
    "MODELS",
    "MODEL_NAMES",
    "SCENE_TERMS",
    "SEANNET",
    "ModelEntry",
    "ResolvedSpec",
    "parse_spec",
    "scene_term",
    "spec_help",
]

SEANNET = "seannet"
# SeanNet ablations by model name (paper-style "what each branch adds"): SeanNet kwargs
ABLATIONS: dict[str, dict[str, Any]] = {
    "seannet-image": {"branches": "image"},
    "seannet-graph": {"branches": "graph"},
    "seannet-noword": {"object_inputs": ("visual", "box")},
    "seannet-novisual": {"object_inputs": ("box", "word")},
    "seannet-nobox": {"object_inputs": ("visual", "word")},
    "seannet-nolayout": {"layout_grid": 0},  # the paper's graph branch: GCN pathways only
    "seannet-fc512": {},  # its GCN fc width is a config field: ABLATION_FIELDS
}
# ablations that are a ModelConfig field set to another value: the config holds the value
# (ModelConfig applies it), so the config a run saves is the model it built
ABLATION_FIELDS: dict[str, dict[str, Any]] = {
    # a 512-wide GCN fc instead of the paper's 4,096: a CPU step near ResNet-18's
    "seannet-fc512": {"graph_hidden": 512},
}


@dataclass(frozen=True)
class ModelEntry:
    """One bundled model: what every layer below a spec asks of its name (the model's
    builder, the benchmark's box sweep) is a field here, not a branch on the name."""

    name: str  # "seannet", an ablation, or an image encoder of the registry
    seannet: bool  # SeanNet or an ablation of it (else a whole image encoder)
    # SeanNet's constructor arguments the ablation changes (:data:`ABLATIONS`)
    kwargs: dict[str, Any] = field(default_factory=dict)
    # ModelConfig fields the ablation sets (:data:`ABLATION_FIELDS`): its config holds them
    fields: dict[str, Any] = field(default_factory=dict)
    # its vectors read the visible objects' boxes (the box-noise sweep applies): SeanNet's
    # graph branch and layout pathway do; the image branch alone and the encoders do not
    uses_boxes: bool = False


# every bundled model by name: SeanNet, its ablations, the registry's image encoders
MODELS: dict[str, ModelEntry] = {
    e.name: e
    for e in (
        ModelEntry(SEANNET, seannet=True, uses_boxes=True),
        *(
            ModelEntry(
                name,
                seannet=True,
                kwargs=kwargs,
                fields=ABLATION_FIELDS.get(name, {}),
                uses_boxes=kwargs.get("branches") != "image",
            )
            for name, kwargs in ABLATIONS.items()
        ),
        *(ModelEntry(name, seannet=False) for name in IMAGE_ENCODERS),
    )
}
MODEL_NAMES = tuple(MODELS)
IMAGENET = "+imagenet"
# what a model spec may add to its image similarity, ``S + lambda * S_scene``, lambda on val
SCENE_TERMS = {
    "+boxes": "the hand-made box overlap (seannet.evaluation.box_overlap)",
    "+box-kernel": "the box kernel learned on the train triplets (seannet.evaluation.box_kernel)",
}


@dataclass(frozen=True)
class ResolvedSpec:
    """A spec resolved against the registries, once (:func:`parse_spec`): the model's entry,
    its image network, its weights, its scene term. No training config yet:
    ``compare.model_spec`` sets it on one."""

    spec: str  # as given, e.g. "seannet@lite0+imagenet+boxes"
    entry: ModelEntry  # the model: "seannet", an ablation, or an image encoder of the registry
    # the image network (a registry name): the encoder, SeanNet's ``@net``, or "" (SeanNet on
    # its config's backbone)
    network: str
    imagenet: bool  # start from the network's ImageNet weights that install offline
    scene: str  # the scene term of :data:`SCENE_TERMS` added to the similarity, or ""

    @property
    def name(self) -> str:
        """The model's name (its entry's)."""
        return self.entry.name

    @property
    def uses_boxes(self) -> bool:
        """Whether the method's vectors read the boxes: the model's, or a scene term's."""
        return self.entry.uses_boxes or bool(self.scene)

    @property
    def trained(self) -> str:
        """The spec of the trained network (its run directory): the spec minus its scene term;
        ``resnet18``, ``resnet18+boxes`` and ``resnet18+box-kernel`` share one run."""
        return self.spec.removesuffix(self.scene)

    @property
    def pretrained(self) -> str | None:
        """The ``pretrained`` value of the offline ImageNet weights, or None (random init)."""
        return NETWORKS[self.network].offline if self.imagenet and self.network else None

    def model_fields(self) -> dict[str, Any]:
        """The :class:`~seannet.model.config.ModelConfig` fields the spec sets."""
        fields: dict[str, Any] = {"name": self.name}
        if self.entry.seannet and self.network:
            record = NETWORKS[self.network]
            fields["backbone"] = record.family
            if record.depth:
                fields["depth"] = record.depth
        return fields


def scene_term(spec: str) -> str:
    """The scene term a model spec ends with: a key of :data:`SCENE_TERMS`, or ``""``."""
    return next((term for term in SCENE_TERMS if spec.endswith(term)), "")


def _c4_networks() -> list[str]:
    return [r.alias or r.name for r in NETWORKS.values() if r.c4_channels]


def _offline_networks() -> list[str]:
    return [r.name for r in NETWORKS.values() if r.offline]


def parse_spec(spec: str) -> ResolvedSpec:
    """Resolve ``NAME[@net][+imagenet][+boxes|+box-kernel]`` against the registries: the one
    parse of a spec, where a command or a file hands it in.

    ``NAME`` is ``seannet``, an ablation of :data:`ABLATIONS` or an image encoder of the
    registry; ``@net`` puts a SeanNet model on another image network with a C4 map (a registry
    name, or its alias: ``@lite0``, ``@resnet18``); ``+imagenet`` starts that network from the
    ImageNet weights that install offline; the scene term adds the box overlap or kernel.

    Raises:
        ModelError: an unknown name or network, ``@`` after an image encoder, or
            ``+imagenet`` on a network with no offline weights; the message lists the choices.
    """
    text = spec.strip()
    scene = scene_term(text)
    trained = text.removesuffix(scene)
    imagenet = trained.endswith(IMAGENET)
    name, at, net = trained.removesuffix(IMAGENET).partition("@")
    entry = MODELS.get(name)
    if entry is None:
        raise ModelError(f"model {spec!r}: unknown name {name!r}; {spec_help()}")
    seannet = entry.seannet
    if at:
        if not seannet:
            raise ModelError(f"model {spec!r}: '@' follows a seannet model, not {name!r}")
        record = next((r for r in NETWORKS.values() if net in (r.name, r.alias)), None)
        if not net or record is None or not record.c4_channels:
            raise ModelError(
                f"model {spec!r}: '@{net}' is no network SeanNet can sit on; expected one of "
                f"{', '.join(_c4_networks())}"
            )
        network_name = record.name
    else:
        network_name = "" if seannet else name
    if imagenet and not (network_name and NETWORKS[network_name].offline):
        offline = ", ".join(_offline_networks())
        raise ModelError(
            f"model {spec!r}: +imagenet needs a network whose ImageNet weights install offline "
            f"({offline}, or seannet@<one of them>); {network_name or SEANNET} has none"
        )
    return ResolvedSpec(text, entry, network_name, imagenet, scene)


def spec_help() -> str:
    """One paragraph naming what a spec may hold (CLI help and error messages print it)."""
    return (
        f"a spec is NAME[@net][{IMAGENET}][{'|'.join(SCENE_TERMS)}]: NAME one of "
        f"{', '.join(MODEL_NAMES)}; @net (after a seannet model) one of "
        f"{', '.join(_c4_networks())}; {IMAGENET} for {', '.join(_offline_networks())}"
    )
