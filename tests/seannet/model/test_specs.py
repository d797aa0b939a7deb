"""seannet.weights (one record per network) and seannet.model.specs (the one spec parser):
every list of names is read off the registry, and a bad spec names the choices."""

from __future__ import annotations

import pytest

from seannet.errors import ModelError
from seannet.model.config import BACKBONES, ModelConfig
from seannet.model.specs import (
    ABLATION_FIELDS,
    ABLATIONS,
    MODEL_NAMES,
    SCENE_TERMS,
    parse_spec,
    spec_help,
)
from seannet.weights import IMAGE_ENCODERS, LITE0, LITE0_WEIGHTS, NETWORKS, network, network_table


def test_every_list_of_names_is_read_off_the_registry() -> None:
    from seannet.model.backbones import ENCODER_NAMES, RESNET_DEPTHS

    assert ENCODER_NAMES == IMAGE_ENCODERS == tuple(NETWORKS)
    assert sorted(RESNET_DEPTHS) == [18, 34, 50]
    assert set(BACKBONES) == {"resnet", LITE0}
    assert MODEL_NAMES == ("seannet", *ABLATIONS, *IMAGE_ENCODERS)
    table = network_table()
    for name in NETWORKS:
        assert f"`{name}`" in table
    for name in MODEL_NAMES:
        assert name in spec_help()


@pytest.mark.parametrize(
    ("spec", "fields", "pretrained", "scene"),
    [
        ("seannet", {"name": "seannet"}, None, ""),
        ("seannet-graph@lite0", {"name": "seannet-graph", "backbone": LITE0}, None, ""),
        ("seannet@resnet18+boxes", {"name": "seannet", "backbone": "resnet", "depth": 18}, None,
         "+boxes"),
        ("seannet@lite0+imagenet+box-kernel", {"name": "seannet", "backbone": LITE0},
         LITE0_WEIGHTS, "+box-kernel"),
        ("efficientnet_lite0+imagenet", {"name": LITE0}, LITE0_WEIGHTS, ""),
        ("resnet18+boxes", {"name": "resnet18"}, None, "+boxes"),
    ],
)  # fmt: skip
def test_specs_parse_against_the_registry(
    spec: str, fields: dict, pretrained: str | None, scene: str
) -> None:
    parsed = parse_spec(spec)
    assert parsed.model_fields() == fields
    assert (parsed.pretrained, parsed.scene) == (pretrained, scene)
    assert parsed.trained == spec.removesuffix(scene)
    ModelConfig().replace(**fields)  # a valid config


@pytest.mark.parametrize(
    ("spec", "names"),
    [
        ("resnet19", "resnet18"),  # an unknown name lists the models
        ("resnet18@lite0", "seannet"),  # '@' only after a seannet model
        ("seannet@vgg16", "lite0"),  # vgg16 has no C4 map: the choices are listed
        ("seannet+imagenet", LITE0),  # no offline weights for the default ResNet
        ("resnet18+imagenet", LITE0),
    ],
)
def test_a_bad_spec_is_one_line_naming_the_choices(spec: str, names: str) -> None:
    with pytest.raises(ModelError) as error:
        parse_spec(spec)
    message = str(error.value)
    assert spec in message and names in message and "\n" not in message


def test_network_lookup_by_name_or_alias() -> None:
    assert network("lite0") is network(LITE0) is NETWORKS[LITE0]
    with pytest.raises(ModelError, match="resnet18"):
        network("alexnet")
    assert set(SCENE_TERMS) == {"+boxes", "+box-kernel"}


def test_the_docs_table_is_the_registry() -> None:
    from pathlib import Path

    docs = (Path(__file__).parents[3] / "docs" / "training.md").read_text()
    assert network_table() in docs, "docs/training.md: paste `seannet networks` again"


def test_an_ablation_of_a_config_field_stores_the_model_it_builds() -> None:
    """seannet-fc512's config says 512, the width of the model built from it, the width saved in
    a checkpoint and read back; an old config that said 4,096 is read as what it built."""
    from seannet.model.factory import build_model
    from seannet.training.config import TrainConfig, preset

    assert ABLATION_FIELDS["seannet-fc512"] == {"graph_hidden": 512}
    config = preset("cpu").replace(embed_dim=64)
    assert config.model.name == "seannet-fc512" and config.model.graph_hidden == 512
    model = build_model(config.model, num_slots=16)
    assert model.gcn.fc[0].out_features == config.model.graph_hidden
    saved = config.to_dict()
    assert saved["model"]["graph_hidden"] == 512
    assert TrainConfig.from_dict(saved).model == config.model
    saved["model"]["graph_hidden"] = 4096  # what configs saved before 2026-12-02 said
    assert TrainConfig.from_dict(saved).model.graph_hidden == 512
    # naming the paper's SeanNet gives its fc back; a width the ablation contradicts is refused
    assert config.replace(model="seannet").model.graph_hidden == 4096
    with pytest.raises(ModelError, match="seannet-fc512.*graph_hidden 512, got 1024"):
        ModelConfig(name="seannet-fc512", graph_hidden=1024)
