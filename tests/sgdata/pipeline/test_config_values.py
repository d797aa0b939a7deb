"""Config values TOML allows but no knob means: refused in one line naming the key."""

from __future__ import annotations

from pathlib import Path

import pytest

from sgdata.errors import ConfigError
from sgdata.pipeline.config import load_config


@pytest.mark.parametrize("value", ["nan", "inf", "-inf"])
def test_a_float_that_is_not_finite_is_refused(tmp_path: Path, value: str) -> None:
    # dynamics.radius_factor = nan was accepted and made a manifest that is not JSON (fuzzing)
    path = tmp_path / "c.toml"
    path.write_text(f"[dynamics]\nradius_factor = {value}\n")
    with pytest.raises(
        ConfigError, match=f"key 'dynamics.radius_factor': expected a finite number, got {value}"
    ):
        load_config(path)
