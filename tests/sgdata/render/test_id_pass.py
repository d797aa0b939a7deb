"""The one-draw id pass against pyrender's SEG pass (one node per object, a colour each)."""

from __future__ import annotations

from typing import Any

import numpy as np

from sgdata.render.primitives import face_order, primitive
from sgdata.render.renderer import Renderer
from sgdata.usd.meshes import MeshData


def seg_pass_ids(renderer: Renderer, geometry: Any, pose: tuple[float, float, float]) -> Any:
    """Instance ids as pyrender's SEG pass draws them, in the renderer's own GL context."""
    import pyrender as pr

    scene = pr.Scene()
    seg = {}
    for mesh in geometry.structure:
        seg[scene.add(pr.Mesh([primitive(pr, mesh, double_sided=True)]))] = np.zeros(3)
    for code, obj in enumerate(geometry.objects, 1):
        node = scene.add(pr.Mesh([primitive(pr, obj.mesh)]), pose=np.asarray(obj.matrix))
        seg[node] = np.array([code & 255, (code >> 8) & 255, code >> 16])
    scene.add(renderer._camera_model(), pose=renderer.camera.pose_matrix(*pose))
    color, _ = renderer._gl.render(scene, flags=pr.RenderFlags.SEG, seg_node_map=seg)
    c = color.astype(np.int64)
    return renderer._instance_lut[c[..., 0] | (c[..., 1] << 8) | (c[..., 2] << 16)]


def test_ids_agree_with_pyrenders_seg_pass(
    tiny_renderer: Renderer, tiny_room: Any, tiny_view: Any
) -> None:
    x, y, theta = tiny_view
    for pose in ((x, y, theta), (x + 0.3, y - 0.2, theta + 0.7), (x - 0.4, y, theta - 0.5)):
        ours = tiny_renderer.render_ids(*pose)
        theirs = seg_pass_ids(tiny_renderer, tiny_room.geometry, pose)
        assert len(np.unique(ours)) >= 3  # objects in view, not only the walls
        # the same triangles, placed on the CPU (float64) rather than by a per-node matrix on
        # the GPU: at most a few edge pixels fall to the other side
        assert (ours != theirs).sum() <= 10


def test_faces_are_drawn_in_the_rgb_primitives_order() -> None:
    vertices = np.zeros((3, 3))
    mesh = MeshData(
        vertices=vertices,
        faces=np.zeros((5, 3), dtype=np.int64),
        face_colors=np.ones((5, 3)),
        uvs=np.zeros((5, 3, 2)),
        face_texture=np.array([1, -1, 0, 1, -1], dtype=np.int32),
        textures=("a.png", "b.png"),
    )
    assert face_order(mesh, True).tolist() == [1, 4, 2, 0, 3]
    assert face_order(mesh, False).tolist() == [0, 1, 2, 3, 4]
