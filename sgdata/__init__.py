"""sgdata: generate, validate and serve scene-graph datasets of rooms whose objects move.

The package is laid out by pipeline stage, data flowing one way (docs/architecture.md):
``world`` -> ``usd`` -> ``render`` -> ``annotate`` -> ``dataset`` -> ``validate``;
``pipeline`` orchestrates, ``pictures`` draws. This face re-exports the most used names
lazily: ``import sgdata`` loads no USD, renderer or torch, and changes no environment variable.
"""

from sgdata.lazy_face import lazy_face

__version__ = "0.1.0"  # the one home of the version (pyproject.toml reads it)
# The release date of __version__: a dataset's croissant.json states it as datePublished (the
# data is a pure function of config, seed and generator, and its files carry no timestamps).
__release_date__ = "2026-12-01"

_EXPORTS = {
    "CatalogError": ".errors",
    "ConfigError": ".errors",
    "DatasetError": ".errors",
    "RenderError": ".errors",
    "SceneError": ".errors",
    "SgdataError": ".errors",
    "UsdError": ".errors",
    "Catalog": ".world",
    "ClassSpec": ".world",
    "Dynamics": ".world",
    "DynamicsConfig": ".world",
    "Layout": ".world",
    "Opening": ".world",
    "Placement": ".world",
    "PoseGrid": ".world",
    "PosesConfig": ".world",
    "Room": ".world",
    "SceneObject": ".world",
    "Triplet": ".world",
    "generate_room": ".world",
    "load_catalog": ".world",
    "pose_grid": ".world",
    "sample_layouts": ".world",
    "sample_triplets": ".world",
    "summarize_layouts": ".world",
    "load_layout": ".usd",
    "write_layouts": ".usd",
    "write_rooms": ".usd",
    "CameraConfig": ".render",
    "Renderer": ".render",
    "RelationRules": ".annotate",
    "RelationType": ".annotate",
    "SlotTable": ".annotate",
    "ViewAnnotator": ".annotate",
    "ViewRecord": ".annotate",
    "compute_relations": ".annotate",
    "Dataset": ".dataset",
    "validate_dataset": ".validate",
    "GenerateConfig": ".pipeline",
    "generate_dataset": ".pipeline",
    "load_config": ".pipeline",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_face(__name__, _EXPORTS)
