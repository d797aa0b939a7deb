"""The raster id pass in one draw: the RGB pass's own triangles, each carrying its object's code.

pyrender's SEG pass draws one node per object, and on llvmpipe its Python work per node
(program bind, five uniforms, buffer binds, GL state; ~1,000 GL calls for a 60-object room)
cost more than the rasterising. Here the room is two vertex arrays in this renderer's GL
context: the structure, drawn double-sided, then all objects, back faces culled; the same
world-space float32 vertices, in the same order and with the same culling as the RGB pass's
primitives (:func:`sgdata.render.primitives.face_order`), so where two faces tie in depth
the same one wins in both passes. Each vertex carries its object's dense index + 1 as an
unsigned integer (``flat``: never interpolated), written as a 24-bit colour (``k / 255``
converts back to ``k`` exactly), structure faces the code their caller gives them (one per
part: :mod:`sgdata.render.structure`); a draw then a read-back of the colour gives the codes.
The vertex shader computes the position as pyrender's mesh shader does (``P * V * M * inst_m
* position``, here with ``M`` and ``inst_m`` the identity).
"""

from __future__ import annotations

import ctypes
from typing import Any

import numpy as np

from sgdata.render.primitives import face_order
from sgdata.usd.meshes import MeshData

__all__ = ["MergedIdPass"]

_VERTEX = """#version 330 core
layout(location = 0) in vec3 position;
layout(location = 1) in uint code;
uniform mat4 P;
uniform mat4 V;
uniform mat4 M;
uniform mat4 inst_m;
flat out uint v_code;
void main()
{
    gl_Position = P * V * M * inst_m * vec4(position, 1);
    v_code = code;
}
"""

_FRAGMENT = """#version 330 core
flat in uint v_code;
out vec4 frag_color;
void main()
{
    frag_color = vec4(float(v_code & 255u), float((v_code >> 8) & 255u),
                      float((v_code >> 16) & 255u), 255.0) / 255.0;
}
"""


class MergedIdPass:
    """Draws instance codes of a loaded room into the pyrender renderer's framebuffer.

    Its GL objects live in the renderer's context and go with it.

    Args:
        renderer: pyrender's ``Renderer`` (its framebuffer, built by
            :mod:`sgdata.render.target`, is drawn into and read back).
        target: the :class:`~sgdata.render.target.SingleSampleTarget` of that renderer.
        platform: pyrender's EGL platform (its context is made current around GL calls).
    """

    def __init__(self, renderer: Any, target: Any, platform: Any) -> None:
        self._r, self._target, self._platform = renderer, target, platform
        self._program: int | None = None
        self._uniforms: dict[str, int] = {}  # name -> location in the program
        self._vao: int | None = None
        self._buffers: tuple[int, int] | None = None
        self._ranges: tuple[tuple[int, int, bool], ...] = ()  # (first, count, cull)

    def load(
        self,
        structure: list[tuple[MeshData, np.ndarray]],
        objects: MeshData,
        owner: np.ndarray,
        *,
        textured: bool,
    ) -> None:
        """Upload a room: ``structure`` meshes, each with its faces' codes, drawn
        double-sided, then ``objects`` merged in world space with ``owner[f]`` the code of
        face ``f``; ``textured`` as the RGB pass draws them (it sets the face order)."""
        parts: list[tuple[np.ndarray, np.ndarray]] = []
        ranges, first = [], 0
        for mesh, codes, cull in [(m, c, False) for m, c in structure] + [(objects, owner, True)]:
            order = face_order(mesh, textured)
            faces = np.asarray(mesh.faces, dtype=np.int64)[order]
            tri = np.asarray(mesh.vertices, dtype=np.float64)[faces].reshape(-1, 3)
            code = np.asarray(codes, np.uint32)[order]
            parts.append((tri.astype(np.float32), np.repeat(code.astype(np.uint32), 3)))
            ranges.append((first, 3 * len(order), cull))
            first += 3 * len(order)
        positions = np.ascontiguousarray(np.concatenate([p for p, _ in parts]))
        codes = np.ascontiguousarray(np.concatenate([c for _, c in parts]))
        self._platform.make_current()
        try:
            self._upload(positions, codes)
        finally:
            self._platform.make_uncurrent()
        self._ranges = tuple(ranges)

    def draw(self, view: np.ndarray, projection: np.ndarray) -> np.ndarray:
        """(H, W) int32 codes seen from camera pose inverse ``view`` with ``projection``."""
        from OpenGL import GL

        r = self._r
        self._platform.make_current()
        try:
            self._target.configure()
            GL.glBindFramebuffer(GL.GL_DRAW_FRAMEBUFFER, r._main_fb)
            GL.glViewport(0, 0, r.viewport_width, r.viewport_height)
            GL.glEnable(GL.GL_DEPTH_TEST)
            GL.glDepthMask(GL.GL_TRUE)
            GL.glDepthFunc(GL.GL_LESS)
            GL.glDepthRange(0.0, 1.0)
            GL.glDisable(GL.GL_BLEND)
            GL.glPolygonMode(GL.GL_FRONT_AND_BACK, GL.GL_FILL)
            GL.glClearColor(0.0, 0.0, 0.0, 1.0)
            GL.glClear(GL.GL_COLOR_BUFFER_BIT | GL.GL_DEPTH_BUFFER_BIT)
            GL.glUseProgram(self._program)
            eye = np.eye(4)
            for name, matrix in (("P", projection), ("V", view), ("M", eye), ("inst_m", eye)):
                at = self._uniforms[name]
                GL.glUniformMatrix4fv(at, 1, GL.GL_TRUE, np.asarray(matrix, np.float32))
            GL.glBindVertexArray(self._vao)
            GL.glCullFace(GL.GL_BACK)
            for first, count, cull in self._ranges:
                (GL.glEnable if cull else GL.glDisable)(GL.GL_CULL_FACE)
                if count:
                    GL.glDrawArrays(GL.GL_TRIANGLES, first, count)
            GL.glBindVertexArray(0)
            GL.glUseProgram(0)
            self._target.depth = False
            color, _ = self._target.read(None, None)
        finally:
            self._platform.make_uncurrent()
        c = color.astype(np.int32)
        return c[..., 0] | (c[..., 1] << 8) | (c[..., 2] << 16)

    def _upload(self, positions: np.ndarray, codes: np.ndarray) -> None:
        from OpenGL import GL
        from OpenGL.GL import shaders

        if self._program is None:
            self._program = shaders.compileProgram(
                shaders.compileShader(_VERTEX, GL.GL_VERTEX_SHADER),
                shaders.compileShader(_FRAGMENT, GL.GL_FRAGMENT_SHADER),
                validate=False,  # validation needs a bound VAO; the draw has one
            )
            self._uniforms = {
                name: GL.glGetUniformLocation(self._program, name)
                for name in ("P", "V", "M", "inst_m")
            }
            self._vao = GL.glGenVertexArrays(1)
            self._buffers = tuple(GL.glGenBuffers(2))
        GL.glBindVertexArray(self._vao)
        position_buffer, code_buffer = self._buffers
        GL.glBindBuffer(GL.GL_ARRAY_BUFFER, position_buffer)
        GL.glBufferData(GL.GL_ARRAY_BUFFER, positions.nbytes, positions, GL.GL_STATIC_DRAW)
        GL.glEnableVertexAttribArray(0)
        GL.glVertexAttribPointer(0, 3, GL.GL_FLOAT, GL.GL_FALSE, 0, ctypes.c_void_p(0))
        GL.glBindBuffer(GL.GL_ARRAY_BUFFER, code_buffer)
        GL.glBufferData(GL.GL_ARRAY_BUFFER, codes.nbytes, codes, GL.GL_STATIC_DRAW)
        GL.glEnableVertexAttribArray(1)
        GL.glVertexAttribIPointer(1, 1, GL.GL_UNSIGNED_INT, 0, ctypes.c_void_p(0))
        GL.glBindVertexArray(0)
        GL.glBindBuffer(GL.GL_ARRAY_BUFFER, 0)
