"""Stage 5, methods: the public interface any localization method plugs into (``embed(views)``;
optional ``similarity``, ``fit`` with ``state_dict`` / ``load_state_dict``, ``uses_boxes``), its
registry (a decorator, an import path, the entry-point group ``seannet.methods``), the bundled
networks and reference methods as methods, and ``seannet benchmark`` / ``seannet leaderboard``
(docs/benchmark.md)."""

from sgdata.lazy_face import lazy_face

_EXPORTS = {
    "Budget": ".views",
    "SplitData": ".views",
    "Views": ".views",
    "Method": ".registry",
    "load_method": ".registry",
    "method_names": ".registry",
    "register_method": ".registry",
    "BenchmarkConfig": ".benchmark",
    "benchmark_method": ".benchmark",
    "MethodLocalizer": ".localizer",
    "open_method": ".localizer",
    "save_method": ".localizer",
    "leaderboard": ".cards",
    "read_cards": ".cards",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_face(__name__, _EXPORTS)
