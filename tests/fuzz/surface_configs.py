"""Surface: TOML configs, every key of every table wrong-typed, out of range, unknown or missing."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from sgdata.pipeline.config import config_to_dict, load_config

from .harness import Surface
from .mutations import mutated, to_toml

# every key sgdata reads, at its preset value or a valid one: the mutations reach each one
BASE = config_to_dict(load_config("tiny"))
BASE["rooms"] |= {
    "files": ["a.usda", {"path": "b.usda", "split": "test", "id": "b-1", "type": "kitchen"}],
    "classes": "classes.toml",
    "max_room_size": 30.0,
    "max_object_size": 5.0,
}
BASE["dynamics"]["classes"] = {
    "Mug": {"move_chance": 0.5, "radius_factor": 1.0, "yaw_sigma_deg": 5.0}
}


def feed(doc: Any, work: Path, session: None) -> None:
    path = work / "config.toml"
    path.write_text(to_toml(doc) if isinstance(doc, dict) else f"x = {json.dumps(doc)}\n")
    config = load_config(path)
    # an accepted config goes into the manifest: it must be finite JSON
    json.dumps(config_to_dict(config), allow_nan=False)


SURFACE = Surface(name="toml configs", inputs=mutated(BASE, most=4), feed=feed)
