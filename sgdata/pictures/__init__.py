"""Pictures for people: top-down previews, annotated-view overlays and ``sgdata report``."""

from sgdata.lazy_face import lazy_face

_EXPORTS = {
    "RELATION_COLORS": ".overlay",
    "draw_overlay": ".overlay",
    "draw_layout_pair": ".preview",
    "draw_room": ".preview",
    "save_png": ".preview",
    "channel_strip": ".channels",
    "colour_depth": ".channels",
    "colour_mask": ".channels",
    "bar_chart": ".report",
    "channel_sheet": ".report",
    "contact_sheet": ".report",
    "write_report": ".report",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_face(__name__, _EXPORTS)
