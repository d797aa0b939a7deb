"""Stage 3, training: ``TrainConfig`` and its presets, the one training loop and the one
evaluation loop, run directories (checkpoints, restoring a run), ``train``, and the budget
(batches a budget of one thread's seconds buys, load-robust) with what a step costs: its table
and its profile part by part."""

from sgdata.lazy_face import lazy_face

_EXPORTS = {
    "Calibration": ".budget",
    "calibrate": ".budget",
    "calibrate_batches": ".budget",
    "PRESETS": ".config",
    "TrainConfig": ".config",
    "preset": ".config",
    "collect": ".loop",
    "train_one_epoch": ".loop",
    "BEST": ".runs",
    "HISTORY": ".runs",
    "LAST": ".runs",
    "build_for_dataset": ".runs",
    "device_for_run": ".runs",
    "restore_run": ".runs",
    "profile_step": ".step_profile",
    "step_table": ".step_table",
    "train": ".train",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_face(__name__, _EXPORTS)
