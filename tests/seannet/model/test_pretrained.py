"""``--pretrained PATH``: local torchvision state_dicts checked by SHA-256, never downloaded."""

from __future__ import annotations

from pathlib import Path

import pytest
import torch
from torchvision import models

from seannet import ImageEncoder, ModelError, SeanNet, build_model
from seannet.model.pretrained import load_pretrained, load_state_dict_file
from seannet.weights import NETWORKS, NetworkRecord
from sgdata.fileio import sha256_file


@pytest.fixture(scope="module")
def resnet18_file(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict]:
    torch.manual_seed(1)
    state = models.resnet18(weights=None).state_dict()
    path = tmp_path_factory.mktemp("weights") / "resnet18-local.pth"
    torch.save(state, path)
    return path, state


def test_known_hashes_are_torchvisions() -> None:
    weights = {
        "resnet18": [models.ResNet18_Weights.IMAGENET1K_V1],
        "resnet34": [models.ResNet34_Weights.IMAGENET1K_V1],
        "resnet50": list(models.ResNet50_Weights),
        "resnext50": list(models.ResNeXt50_32X4D_Weights),
        "vgg16": [models.VGG16_Weights.IMAGENET1K_V1],
        "googlenet": list(models.GoogLeNet_Weights),
    }
    for arch, ws in weights.items():
        expected = {w.url.rsplit("/", 1)[1]: w.url.rsplit("-", 1)[1][:-4] for w in ws}
        assert NETWORKS[arch].files == expected


def test_right_hash_loads_the_weights(resnet18_file: tuple[Path, dict]) -> None:
    path, state = resnet18_file
    digest = sha256_file(path)[0]
    model = ImageEncoder("resnet18", pretrained=path, pretrained_sha256=digest)
    got = model.encoder.state_dict()
    assert all(torch.equal(got[k], v) for k, v in state.items() if not k.startswith("fc."))
    # SeanNet's backbone and head come from the same file (layer3 in backbone, layer4 in head)
    net = build_model("seannet", depth=18, num_slots=8, pretrained=path, pretrained_sha256=digest)
    assert isinstance(net, SeanNet)
    assert torch.equal(net.backbone[6][0].conv1.weight, state["layer3.0.conv1.weight"])
    assert torch.equal(net.head[0][1].bn2.running_var, state["layer4.1.bn2.running_var"])
    # a torchvision-style 8-hex prefix is accepted too
    ImageEncoder("resnet18", pretrained=path, pretrained_sha256=digest[:8].upper())


def test_wrong_hash_names_expected_and_actual(resnet18_file: tuple[Path, dict]) -> None:
    path, _ = resnet18_file
    actual = sha256_file(path)[0]
    wrong = "0" * 64
    with pytest.raises(ModelError) as err:
        ImageEncoder("resnet18", pretrained=path, pretrained_sha256=wrong)
    msg = str(err.value)
    assert f"expected {wrong}" in msg and f"actual {actual}" in msg and "\n" not in msg
    with pytest.raises(ModelError, match="not 8 to 64 hex digits"):
        ImageEncoder("resnet18", pretrained=path, pretrained_sha256="xyz")


def test_unknown_file_without_hash_is_refused(resnet18_file: tuple[Path, dict]) -> None:
    path, _ = resnet18_file
    actual = sha256_file(path)[0]
    with pytest.raises(ModelError, match=f"sha256 {actual} matches no known resnet18.*f37072fd"):
        ImageEncoder("resnet18", pretrained=path)


def test_known_prefix_is_accepted(
    resnet18_file: tuple[Path, dict], monkeypatch: pytest.MonkeyPatch
) -> None:
    path, state = resnet18_file
    local = NetworkRecord("resnet18", {"local.pth": sha256_file(path)[0][:8]})
    monkeypatch.setitem(NETWORKS, "resnet18", local)
    model = load_pretrained(models.resnet18(weights=None), path, arch="resnet18")
    assert torch.equal(model.conv1.weight, state["conv1.weight"])


def test_not_a_state_dict(tmp_path: Path) -> None:
    listed = tmp_path / "list.pth"
    torch.save([torch.zeros(2)], listed)
    with pytest.raises(ModelError, match="holds a list, not a state_dict"):
        load_state_dict_file(listed, arch="resnet18", sha256=sha256_file(listed)[0])
    text = tmp_path / "notes.pth"
    text.write_text("not weights\n")
    with pytest.raises(ModelError, match="not a torch state_dict file"):
        load_state_dict_file(text, arch="resnet18", sha256=sha256_file(text)[0])
    with pytest.raises(ModelError, match="no such file"):
        load_state_dict_file(tmp_path / "absent.pth", arch="resnet18")


def test_weights_of_another_architecture_do_not_fit(tmp_path: Path) -> None:
    path = tmp_path / "linear.pth"
    torch.save(torch.nn.Linear(3, 2).state_dict(), path)
    with pytest.raises(ModelError, match=r"do not fit resnet18: \d+ missing .*2 unexpected"):
        ImageEncoder("resnet18", pretrained=path, pretrained_sha256=sha256_file(path)[0])


def test_an_expected_sha256_that_cannot_be_used_is_refused(tmp_path: Path) -> None:
    """`seannet train --pretrained-sha256` was once accepted and silently ignored."""
    from seannet.model.pretrained import check_pretrained_request

    with pytest.raises(ModelError, match="given without --pretrained"):
        check_pretrained_request(None, "ab" * 32)
    with pytest.raises(ModelError, match="expected 8 to 64 hex digits"):
        check_pretrained_request(tmp_path / "w.pth", "WRONG")
    check_pretrained_request(tmp_path / "w.pth", "ab" * 32)  # usable: no error
    check_pretrained_request(None, None)
