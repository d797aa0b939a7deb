"""Stage 6, navigation (paper §VI): motion on the grid, maps of views, the localizer (a run or
any method) and ``seannet localize``, the visual navigator and its training, episodes and
``seannet navigate``."""

from sgdata.lazy_face import lazy_face

_EXPORTS = {
    "Localizer": ".localizer",
    "load_localizer": ".localizer",
    "open_localizer": ".localizer",
    "TopoMap": ".maps",
    "build_maps": ".maps",
    "NavigationTestConfig": ".config",
    "NavigatorConfig": ".config",
    "run_navigation": ".benchmark",
    "navigation_test": ".method_navigation",
    "load_navigator": ".navigator",
    "train_navigator": ".navigator_training",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_face(__name__, _EXPORTS)
