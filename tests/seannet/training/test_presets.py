"""Training presets: the cpu preset trains seannet-fc512, the paper's SeanNet stays elsewhere."""

from __future__ import annotations

import pytest

from seannet.errors import ModelError
from seannet.model.factory import build_model
from seannet.training.config import DEFAULT_PRESET, PRESETS, preset


def test_the_cpu_preset_trains_the_512_wide_gcn_fc() -> None:
    assert DEFAULT_PRESET == "cpu"  # what a command trains with when no preset is named
    cpu = preset("cpu")
    assert cpu.model.name == "seannet-fc512"
    model = build_model(cpu.model.replace(embed_dim=64), num_slots=16)
    first, last = model.gcn.fc[0], model.gcn.fc[2]
    assert (first.out_features, last.in_features) == (512, 512)
    # the paper's 4,096-wide SeanNet stays the model of the paper and gpu presets
    assert preset("paper").model.name == preset("gpu").model.name == "seannet"
    assert preset("paper").model.graph_hidden == preset("gpu").model.graph_hidden == 4096


def test_cpu_and_gpu_share_one_schedule() -> None:
    cpu, gpu = preset("cpu"), preset("gpu")
    shared = ("epochs", "batch_size", "decay_every", "new_layers_lr_scale", "lr", "lr_decay")
    assert all(getattr(cpu, k) == getattr(gpu, k) for k in shared)
    assert (cpu.model.depth, cpu.model.visual_features) == (gpu.model.depth, "c5")
    assert cpu.max_train_batches == 24 and gpu.max_train_batches == 0  # all, on a GPU


def test_the_smoke_preset_is_the_cpu_preset_at_64_px() -> None:
    cpu, smoke = preset("cpu"), preset("smoke")
    assert (smoke.model.image_size, smoke.model.roi_size) == (64, 4)
    assert smoke.replace(image_size=112, roi_size=7) == cpu  # nothing else differs


def test_an_unknown_preset_names_the_known_ones() -> None:
    with pytest.raises(ModelError, match=", ".join(PRESETS)):
        preset("laptop")
