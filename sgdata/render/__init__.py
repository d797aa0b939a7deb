"""The render stage: the camera model and the offscreen renderer (pyrender over EGL)."""

from sgdata.lazy_face import lazy_face

_EXPORTS = {
    "CameraConfig": ".camera",
    "merged_world": ".primitives",
    "primitive": ".primitives",
    "same_mesh": ".primitives",
    "same_shape": ".primitives",
    "subset": ".primitives",
    "RenderedView": ".renderer",
    "Renderer": ".renderer",
    "use_egl_platform": ".renderer",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_face(__name__, _EXPORTS)
