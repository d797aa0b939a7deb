"""SeanNet test fixtures: a small real dataset generated once per session."""

from __future__ import annotations

from pathlib import Path

import pytest

from sgdata.config import load_config
from sgdata.generate import generate_dataset

# One bathroom in train and one in test, two layouts, 96 px views: about 20 s to generate.
MINI_TOML = """\
[dataset]
name = "seannet-test-mini"
version = "0.0.1"
seed = 3

[rooms]
types = ["bathroom"]
train = 1
val = 0
test = 1

[layouts]
count = 2

[camera]
width = 96
height = 96

[triplets]
train = 12
val = 0
test = 8
"""


@pytest.fixture(scope="session")
def mini_dataset(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Root of a generated mini dataset (train and test splits, real Parquet and PNG)."""
    base = tmp_path_factory.mktemp("mini_dataset")
    config = base / "mini.toml"
    config.write_text(MINI_TOML)
    root = base / "data"
    generate_dataset(load_config(config), root, workers=2)
    return root
