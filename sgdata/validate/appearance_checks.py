"""Appearance checks: each synthetic row's ``textures`` flag and light against the manifest
config's ``[appearance]`` (format 1.1): light intensity and colour temperature within the
configured ranges when layouts draw them, the default light when they do not."""

from __future__ import annotations

from typing import Any

import numpy as np

from sgdata.validate.loading import SplitTables, column_numpy
from sgdata.validate.problems import Collector

__all__ = ["check_appearance"]


def check_appearance(tables: SplitTables, raw: dict[str, Any], out: Collector) -> None:
    """``rows.appearance``: synthetic rows carry ``textures`` and ``light_intensity``; with
    ``randomize`` the light lies within ``light_intensity`` and ``color_temperature`` (as
    float32, how the rows store it), without it the light is the default (1, null); no row is
    textured when ``textures`` is off. Datasets without an ``[appearance]`` section (format
    1.0) are skipped."""
    obs = tables.observations
    config = (raw.get("config") or {}).get("appearance")
    if obs is None or not isinstance(config, dict) or "textures" not in obs.column_names:
        return
    synthetic = column_numpy(obs, "domain") == "synthetic"
    out.count("rows.appearance", int(synthetic.sum()))
    textures = obs.column("textures")
    intensity = obs.column("light_intensity")
    problems: list[tuple[np.ndarray, str, Any]] = [
        (textures.is_null().to_numpy(zero_copy_only=False), "textures", "null in a synthetic row"),
        (
            intensity.is_null().to_numpy(zero_copy_only=False),
            "light_intensity",
            "null in a synthetic row",
        ),
    ]
    if not config.get("textures", True):
        on = column_numpy(obs, "textures", False).astype(bool)
        problems.append((on, "textures", "true, but the config's appearance.textures is false"))
    scale = column_numpy(obs, "light_intensity", np.nan).astype(np.float32)
    temp = column_numpy(obs, "light_temperature", np.nan).astype(np.float32)
    if config.get("randomize", False):
        problems.append(_outside(scale, config.get("light_intensity"), "light_intensity"))
        missing = np.isnan(temp)
        problems.append((missing, "light_temperature", "null; the config draws it per layout"))
        bad, field, message = _outside(temp, config.get("color_temperature"), "light_temperature")
        problems.append((bad & ~missing, field, message))
    else:
        default = ~np.isnan(scale) & (scale != np.float32(1.0))
        problems.append((default, "light_intensity", lambda v: f"{v}: expected 1 (randomize off)"))
        problems.append(
            (~np.isnan(temp), "light_temperature", lambda v: f"{v}: expected null (randomize off)")
        )
    values = {"light_intensity": scale, "light_temperature": temp}
    for bad, field, message in problems:
        for r in np.flatnonzero(bad & synthetic):
            f, row = tables.where(r)
            text = message(values[field][r]) if callable(message) else message
            out.add("rows.appearance", tables.files[f], text, row=int(row), field=field)


def _outside(values: np.ndarray, bounds: Any, field: str) -> tuple[np.ndarray, str, Any]:
    """Rows whose value lies outside ``bounds`` (compared at float32, NaN counts as inside)."""
    if not isinstance(bounds, list | tuple) or len(bounds) != 2:
        return np.zeros(len(values), dtype=bool), field, ""
    lo, hi = np.float32(bounds[0]), np.float32(bounds[1])
    with np.errstate(invalid="ignore"):
        bad = (values < lo) | (values > hi)
    return bad, field, lambda v: f"{v}: outside the configured [{bounds[0]}, {bounds[1]}]"
