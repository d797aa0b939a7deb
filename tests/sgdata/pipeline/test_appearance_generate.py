"""Generation with textures and per-layout appearance: every row records its light, which
matches its layout's USD and lies in the configured ranges; the same config gives the same
bytes with 1 or 2 workers and another hash seed; texture images are listed in the manifest."""

from __future__ import annotations

import hashlib
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pyarrow.compute as pc

from sgdata.dataset import Dataset
from sgdata.pipeline.config import load_config
from sgdata.pipeline.generate import LEDGER, generate_dataset
from sgdata.usd.prims import LIGHT_INTENSITY, LIGHT_TEMPERATURE
from sgdata.usd.stage import open_stage

# Two small textured rooms (2 workers really run in parallel), 48 px views, few triplets.
SMALL_TOML = """\
[dataset]
name = "textured"
seed = 11
[rooms]
types = ["bathroom"]
train = 1
val = 1
test = 0
[layouts]
count = 2
[camera]
width = 48
height = 48
[triplets]
train = 8
val = 4
test = 0
[appearance]
texture_size = 64
light_intensity = [0.5, 0.7]
color_temperature = [3000.0, 5000.0]
"""


def _digests(root: Path) -> dict[str, str]:
    return {
        p.relative_to(root).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(root.rglob("*"))
        if p.is_file() and LEDGER not in p.parts
    }


def test_textured_generate_is_byte_identical_across_workers_and_hash_seeds(
    tmp_path: Path,
) -> None:
    config = tmp_path / "textured.toml"
    config.write_text(SMALL_TOML)
    one = tmp_path / "one"
    generate_dataset(load_config(config), one, workers=1)
    two = tmp_path / "two"
    env = {**os.environ, "PYTHONHASHSEED": "4242"}
    cli = [sys.executable, "-m", "sgdata_cli.sgdata_app", "generate", str(config), str(two)]
    result = subprocess.run(
        [*cli, "--workers", "2"], env=env, capture_output=True, text=True, timeout=600
    )
    assert result.returncode == 0, result.stderr
    digests = _digests(one)
    assert digests == _digests(two)
    textures = [p for p in digests if p.startswith("scenes/textures/")]
    assert textures and all(p.endswith("_64px.png") for p in textures)
    listed = {f["path"] for f in json.loads((one / "dataset.json").read_text())["files"]}
    assert set(textures) <= listed
    views = Dataset.open(one).observations("train", columns=["light_intensity", "textures"])
    assert pc.all(views.column("textures")).as_py()
    lights = views.column("light_intensity").to_numpy()
    assert ((lights >= np.float32(0.5)) & (lights <= np.float32(0.7))).all()


def test_rows_record_their_layouts_light(mini_dataset: Path) -> None:
    """The mini dataset uses the default [appearance]: textures on, light drawn per layout."""
    dataset = Dataset.open(mini_dataset)
    config = json.loads((mini_dataset / "dataset.json").read_text())["config"]["appearance"]
    lo, hi = config["light_intensity"]
    k_lo, k_hi = config["color_temperature"]
    seen: dict[str, tuple[float, float]] = {}
    for split in ("train", "val", "test"):
        columns = ["scene", "textures", "light_intensity", "light_temperature"]
        for row in dataset.observations(split, columns=columns).to_pylist():
            assert row["textures"] is True
            if row["scene"] not in seen:
                stage = open_stage(mini_dataset / row["scene"])
                root = stage.GetPrimAtPath("/Room")
                seen[row["scene"]] = (
                    float(np.float32(root.GetAttribute(LIGHT_INTENSITY).Get())),
                    float(np.float32(root.GetAttribute(LIGHT_TEMPERATURE).Get())),
                )
            assert (row["light_intensity"], row["light_temperature"]) == seen[row["scene"]]
            assert np.float32(lo) <= row["light_intensity"] <= np.float32(hi)
            assert k_lo <= row["light_temperature"] <= k_hi
    by_room: dict[str, set] = {}
    for scene, light in seen.items():
        by_room.setdefault(scene.split("/")[1], set()).add(light)
    assert all(len(lights) > 1 for lights in by_room.values())  # layouts differ in light
