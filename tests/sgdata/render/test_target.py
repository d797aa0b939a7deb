"""The single-sample framebuffer and the remembered uniform locations give the pixels of
pyrender's own multisampled framebuffer and setter."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from sgdata.render.renderer import Renderer


@pytest.fixture
def pyrender_own(monkeypatch: pytest.MonkeyPatch, tiny_room: Any) -> Any:
    """A renderer drawing through pyrender's 4x multisampled framebuffer and blits, with
    ``GL_MULTISAMPLE`` turned off as sgdata drew before the single-sample target, and
    pyrender's own uniform setter."""
    import pyrender.renderer as pyrender_renderer
    from OpenGL.GL import GL_MULTISAMPLE, glDisable

    original = pyrender_renderer.glEnable

    def enable(capability: int) -> None:
        (glDisable if capability == GL_MULTISAMPLE else original)(capability)

    monkeypatch.setattr(pyrender_renderer, "glEnable", enable)
    renderer = Renderer()
    del renderer._gl._renderer._configure_main_framebuffer  # pyrender's methods again
    del renderer._gl._renderer._read_main_framebuffer
    del renderer._gl._renderer._program_cache.get_program
    renderer.load(tiny_room.geometry)
    yield renderer
    renderer.close()


def test_same_pixels_and_depth_as_pyrenders_framebuffer(
    pyrender_own: Any, tiny_renderer: Renderer, tiny_view: Any
) -> None:
    x, y, theta = tiny_view
    for pose in ((x, y, theta), (x + 0.3, y - 0.2, theta + 0.7), (x, y, theta + np.pi)):
        ours, theirs = tiny_renderer.render(*pose), pyrender_own.render(*pose)
        assert ours.rgb.tobytes() == theirs.rgb.tobytes()
        # depth at the pixel centre, where pyrender's blit took the first sample's (off the
        # centre): equal to float32 rounding, 0 where nothing was drawn in both
        assert ours.depth is not None and np.array_equal(ours.depth > 0, theirs.depth > 0)
        assert np.allclose(ours.depth, theirs.depth, rtol=1e-5, atol=0)
        assert (ours.depth > 0).mean() > 0.9  # the walls are in view
    remembering = [
        "set_uniform" in vars(program)
        for r in (tiny_renderer, pyrender_own)
        for program in r._gl._renderer._program_cache._program_cache.values()
    ]
    assert remembering.count(True) >= 1 and remembering.count(False) >= 1  # ours, pyrender's


def test_depth_is_read_only_when_asked(tiny_renderer: Renderer, tiny_view: Any) -> None:
    rgb, depth = tiny_renderer.render_rgb(*tiny_view, depth=False)
    assert depth is None
    assert rgb.tobytes() == tiny_renderer.render_rgb(*tiny_view)[0].tobytes()
    assert tiny_renderer.render(*tiny_view, depth=False).depth is None
