"""The annotation stage: view records, visible objects and boxes, slots, relations, annotator."""

from sgdata.lazy_face import lazy_face

_EXPORTS = {
    "ViewAnnotator": ".annotator",
    "Annotation": ".boxes",
    "MIN_VISIBLE_PIXELS": ".records",
    "ObjectTable": ".boxes",
    "annotate": ".boxes",
    "ViewPose": ".records",
    "ViewRecord": ".records",
    "RelationRules": ".relations",
    "RelationType": ".relations",
    "Relations": ".relations",
    "compute_relations": ".relations",
    "stored_precision": ".relations",
    "NUM_SLOTS": ".slots",
    "SlotAssignment": ".slots",
    "SlotTable": ".slots",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_face(__name__, _EXPORTS)
