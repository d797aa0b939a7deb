"""sgdata: generate, validate and serve scene-graph datasets of rooms whose objects move.

The public API, by pipeline stage (see docs/architecture.md):
rooms -> layouts -> poses -> views (render + annotate + relations) -> triplets -> dataset.
Importing sgdata starts no renderer and changes no environment variable.
"""

from .catalog import Catalog, ClassSpec, load_catalog
from .config import GenerateConfig, load_config
from .dataset import Dataset
from .dynamics import DynamicsConfig, Layout, sample_layouts, summarize_layouts
from .errors import (
    CatalogError,
    ConfigError,
    DatasetError,
    RenderError,
    SceneError,
    SgdataError,
    UsdError,
)
from .generate import generate_dataset
from .poses import PoseGrid, pose_grid
from .relations import RelationRules, RelationType, compute_relations
from .render import CameraConfig, Renderer
from .rooms import generate_room
from .scene import Dynamics, Opening, Placement, Room, SceneObject
from .scenes import load_layout, write_layouts, write_rooms
from .slots import SlotTable
from .triplets import Triplet, sample_triplets
from .validate import validate_dataset
from .views import ViewAnnotator, ViewRecord

__version__ = "0.1.0"

__all__ = [
    "CameraConfig",
    "Catalog",
    "CatalogError",
    "ClassSpec",
    "ConfigError",
    "Dataset",
    "DatasetError",
    "Dynamics",
    "DynamicsConfig",
    "GenerateConfig",
    "Layout",
    "Opening",
    "Placement",
    "PoseGrid",
    "RelationRules",
    "RelationType",
    "RenderError",
    "Renderer",
    "Room",
    "SceneError",
    "SceneObject",
    "SgdataError",
    "SlotTable",
    "Triplet",
    "UsdError",
    "ViewAnnotator",
    "ViewRecord",
    "compute_relations",
    "generate_dataset",
    "generate_room",
    "load_catalog",
    "load_config",
    "load_layout",
    "pose_grid",
    "sample_layouts",
    "sample_triplets",
    "summarize_layouts",
    "validate_dataset",
    "write_layouts",
    "write_rooms",
]
