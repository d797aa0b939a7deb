"""Stage 4, evaluation: metrics from a split's embeddings, retrieval, ``seannet eval`` and
``seannet compare`` (selection on val, test read once, intervals over rooms and seeds)."""

from sgdata.lazy_face import lazy_face

_EXPORTS = {
    "compare_models": ".compare",
    "evaluate_run": ".run_eval",
    "embed_split": ".metrics",
    "triplet_metrics": ".metrics",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_face(__name__, _EXPORTS)
