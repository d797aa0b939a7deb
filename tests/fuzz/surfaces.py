"""Every fuzzed input surface, by name: add a surface's module here and it is fuzzed."""

from __future__ import annotations

from . import (
    surface_assets,
    surface_configs,
    surface_datasets,
    surface_detector_coco,
    surface_exports,
    surface_label_files,
    surface_label_server,
    surface_methods,
    surface_proposers,
    surface_usd_rooms,
)
from .harness import Surface

__all__ = ["SURFACES"]

SURFACES: dict[str, Surface] = {
    module.SURFACE.name: module.SURFACE
    for module in (
        surface_usd_rooms,
        surface_configs,
        surface_label_files,
        surface_label_server,
        surface_datasets,
        surface_assets,
        surface_methods,
        surface_exports,
        surface_proposers,
        surface_detector_coco,
    )
}
