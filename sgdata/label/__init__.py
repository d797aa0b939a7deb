"""The label stage: a local web app to box, class and relate real photos, and their export."""

from sgdata.lazy_face import lazy_face

_EXPORTS = {
    "Box": ".proposals",
    "DEFAULT_RULES": ".proposals",
    "Proposal": ".proposals",
    "ProposalRules": ".proposals",
    "RELATION_NAMES": ".proposals",
    "propose_pair": ".proposals",
    "propose_relations": ".proposals",
    "Photo": ".photos",
    "PhotoIndex": ".photos",
    "photo_bytes": ".photos",
    "scan_photos": ".photos",
    "ClassNames": ".classes",
    "load_class_names": ".classes",
    "Decision": ".models",
    "LabeledObject": ".models",
    "PhotoLabels": ".models",
    "Pose": ".models",
    "ROOM_ID_PATTERN": ".models",
    "ConflictError": ".store",
    "LABELS_DIR": ".store",
    "LabelStore": ".store",
    "MAX_BODY": ".server",
    "create_app": ".server",
    "serve": ".server",
    "ExportSummary": ".export",
    "SOURCE": ".export",
    "export_dataset": ".export",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_face(__name__, _EXPORTS)
