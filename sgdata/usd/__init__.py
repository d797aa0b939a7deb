"""The USD stage: rooms as stages, layouts as layers, mesh records read back for rendering."""

from sgdata.lazy_face import lazy_face

_EXPORTS = {
    "DEFAULT_COLOR": ".geometry",
    "read_geometry": ".geometry",
    "PLACEMENT_TOLERANCE": ".layout_layers",
    "read_layout_provenance": ".layout_layers",
    "write_layout": ".layout_layers",
    "MeshData": ".meshes",
    "ObjectGeometry": ".meshes",
    "SceneGeometry": ".meshes",
    "merge_meshes": ".meshes",
    "Geometry": ".room_io",
    "OBJECTS": ".room_io",
    "ROOT": ".room_io",
    "STRUCTURE": ".room_io",
    "catalog_geometry": ".room_io",
    "check_stage": ".room_io",
    "object_path": ".room_io",
    "open_layer": ".room_io",
    "open_stage": ".room_io",
    "read_room": ".room_io",
    "validate_stage": ".room_io",
    "write_room": ".room_io",
    "write_text_atomic": ".room_io",
    "layout_indices": ".scene_dirs",
    "load_base": ".scene_dirs",
    "load_layout": ".scene_dirs",
    "write_layouts": ".scene_dirs",
    "write_rooms": ".scene_dirs",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_face(__name__, _EXPORTS)
