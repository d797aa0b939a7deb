"""Stage 1, data: an sgdata dataset's views and triplets as tensors (SceneBatch), the decoded
image cache, live views rendered from a dataset's rooms, and which objects moved."""

from sgdata.lazy_face import lazy_face

_EXPORTS = {
    "NUM_RELATIONS": ".batch",
    "SceneBatch": ".batch",
    "ViewTensors": ".collate",
    "collate_triplets": ".collate",
    "collate_views": ".collate",
    "ObservationDataset": ".datasets",
    "TripletDataset": ".datasets",
    "DataSource": ".opening",
    "dataset_identity": ".opening",
    "open_dataset": ".opening",
    "LiveRooms": ".live_views",
    "moved_instances": ".moved",
    "moved_objects": ".moved",
    "ImageTransform": ".view_inputs",
    "graph_tensors": ".view_inputs",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_face(__name__, _EXPORTS)
