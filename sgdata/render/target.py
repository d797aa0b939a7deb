"""The framebuffer pyrender draws into: one sample per pixel, read back without a blit.

pyrender draws every pass into a 4x multisampled framebuffer, blits it (colour and depth) into
a single-sample one and reads both back, depth converted to metres. sgdata used to draw with
``GL_MULTISAMPLE`` disabled (llvmpipe's multisampling was not deterministic: one edge pixel
differed between fresh processes in 2 of 7 runs), so every sample of a pixel received the same
fragment and the resolve only averaged equal values: the four samples, the blits and the
depth read-back were work whose result a single-sample buffer gives directly (with no sample
buffers, GL rasterises single-sample whatever ``GL_MULTISAMPLE`` says).
:func:`use_single_sample_target` replaces the two methods of one pyrender renderer that build
and read that framebuffer; RGB and ids are the same bytes (checked on 120
generated views and in tests/sgdata/render/test_target.py), depth agrees to float32 rounding
(it is now taken at the pixel centre, pyrender's blit took the first sample's). Depth is read
only when :attr:`SingleSampleTarget.depth` is set: generation keeps none.
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["SingleSampleTarget", "use_single_sample_target"]


class SingleSampleTarget:
    """Builds and reads pyrender's main framebuffer with one sample per pixel.

    Attributes:
        depth: read the depth buffer back too (metres along the view axis, 0 where empty);
            when False the renderer's depth result is None.
    """

    def __init__(self, renderer: Any) -> None:
        self._r = renderer
        self.depth = True

    def configure(self) -> None:
        """pyrender's ``_configure_main_framebuffer``: one colour and one depth renderbuffer;
        the multisampled names point at the same framebuffer, which pyrender binds to draw."""
        from OpenGL import GL

        r = self._r
        if r._main_fb is not None and tuple(r._main_fb_dims) != (
            r.viewport_width,
            r.viewport_height,
        ):
            r._delete_main_framebuffer()
        if r._main_fb is not None:
            return
        r._main_cb, r._main_db = GL.glGenRenderbuffers(2)
        for buffer, kind in ((r._main_cb, GL.GL_RGBA), (r._main_db, GL.GL_DEPTH_COMPONENT24)):
            GL.glBindRenderbuffer(GL.GL_RENDERBUFFER, buffer)
            GL.glRenderbufferStorage(GL.GL_RENDERBUFFER, kind, r.viewport_width, r.viewport_height)
        r._main_fb = GL.glGenFramebuffers(1)
        GL.glBindFramebuffer(GL.GL_DRAW_FRAMEBUFFER, r._main_fb)
        for attachment, buffer in (
            (GL.GL_COLOR_ATTACHMENT0, r._main_cb),
            (GL.GL_DEPTH_ATTACHMENT, r._main_db),
        ):
            GL.glFramebufferRenderbuffer(
                GL.GL_DRAW_FRAMEBUFFER, attachment, GL.GL_RENDERBUFFER, buffer
            )
        # pyrender deletes both names of each pair; deleting a name twice is a no-op in GL
        r._main_fb_ms, r._main_cb_ms, r._main_db_ms = r._main_fb, r._main_cb, r._main_db
        r._main_fb_dims = (r.viewport_width, r.viewport_height)

    def read(self, scene: Any, flags: Any) -> tuple[np.ndarray, np.ndarray | None]:
        """pyrender's ``_read_main_framebuffer`` for RGB and SEG passes: (rgb, depth or None)."""
        from OpenGL import GL

        width, height = self._r._main_fb_dims
        GL.glBindFramebuffer(GL.GL_READ_FRAMEBUFFER, self._r._main_fb)
        color = GL.glReadPixels(0, 0, width, height, GL.GL_RGB, GL.GL_UNSIGNED_BYTE)
        rgb = np.frombuffer(color, dtype=np.uint8).reshape(height, width, 3)[::-1]
        if not self.depth:
            return rgb, None
        raw = GL.glReadPixels(0, 0, width, height, GL.GL_DEPTH_COMPONENT, GL.GL_FLOAT)
        ndc = np.frombuffer(raw, dtype=np.float32).reshape(height, width)[::-1]
        return rgb, _metres(ndc, scene.main_camera_node.camera)


def _metres(depth: np.ndarray, camera: Any) -> np.ndarray:
    """Depth-buffer values to metres along the view axis, 0 where nothing was drawn (pyrender's
    own conversion, in float32 as it does it)."""
    empty = depth == 1.0
    z = 2.0 * depth - 1.0
    near, far = camera.znear, camera.zfar
    out = np.zeros_like(z)
    hit = ~empty
    if far is None:
        out[hit] = 2 * near / (1.0 - z[hit])
    else:
        out[hit] = (2.0 * near * far) / (far + near - z[hit] * (far - near))
    return out


def use_single_sample_target(renderer: Any) -> SingleSampleTarget:
    """Make one pyrender ``Renderer`` draw into and read from a single-sample framebuffer."""
    target = SingleSampleTarget(renderer)
    renderer._configure_main_framebuffer = target.configure
    renderer._read_main_framebuffer = target.read
    return target
