"""SeanNet: the scene-embedding network, its trainer and its uses (the PyTorch side).

Laid out by stage, imports going downwards only (docs/architecture.md): ``data`` (views and
triplets as tensors) < ``model`` (SeanNet, baselines, layers, loss) < ``training`` (config,
the one training loop, run directories) < ``evaluation`` (metrics, ``seannet eval``,
``compare``) < ``navigation`` (maps, localization, the navigator and its test). This face
re-exports the most used names lazily: ``import seannet`` loads no torch. Importing it reads
the code's commit once (:data:`seannet.provenance.PROCESS`), so what runs record is the code
this process loaded, not whatever HEAD is when they finish.
"""

from seannet import provenance as _provenance  # noqa: F401  (the code state at process start)
from sgdata.lazy_face import lazy_face

_EXPORTS = {
    "CheckpointError": ".errors",
    "DataError": ".errors",
    "ModelError": ".errors",
    "SeannetError": ".errors",
    "ImageTransform": ".data",
    "ObservationDataset": ".data",
    "SceneBatch": ".data",
    "TripletDataset": ".data",
    "collate_triplets": ".data",
    "collate_views": ".data",
    "dataset_identity": ".data",
    "MODEL_NAMES": ".model",
    "ImageEncoder": ".model",
    "ModelConfig": ".model",
    "SeanNet": ".model",
    "TripletLoss": ".model",
    "build_model": ".model",
    "similarity": ".model",
    "PRESETS": ".training",
    "TrainConfig": ".training",
    "preset": ".training",
    "train": ".training",
    "evaluate_run": ".evaluation",
    "compare_models": ".evaluation",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_face(__name__, _EXPORTS)
