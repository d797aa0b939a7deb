"""Offscreen renderer: RGB (pyrender over EGL) and exact per-pixel instance ids for one room.

The RGB pass draws the room's structure and all objects merged into one world-space mesh:
on llvmpipe pyrender's per-node Python overhead (uniforms and lights bound per primitive)
cost more than the rasterising itself, and merging took a 68-object kitchen from 8 to 20 RGB
frames/s. A new layout of the same room (:meth:`Renderer.update_poses`) re-merges the kept
object meshes under the new transforms (numpy only, no recipe or USD work) and uploads them
to the id pass; only a different instance set rebuilds everything.

Instance ids come from one of two id passes (``id_pass``), both exact (no blended values):

- ``"raster"`` (default): the RGB pass's own triangles drawn in one call with each object's
  dense index + 1 as a flat 24-bit colour (structure faces the codes after them, one per
  part of :mod:`sgdata.render.structure`, so walls occlude and are told apart), into a
  single-sample framebuffer, so no value is ever blended (:mod:`sgdata.render.id_pass`,
  :mod:`sgdata.render.target`). Decoded codes are still validated against the known range
  on every view and a bad one raises ``RenderError``.
- ``"raycast"``: open3d's ``RaycastingScene`` casts one ray through the centre of every
  pixel (the rasteriser's sample point) and a lookup table maps the hit triangle to its
  object: integers all the way.

Raycasting was measured at 15 ids/s against pyrender's SEG pass's 20 (a generated 68-object
kitchen, 224², one thread; rays that all hit something are slower than open3d's ~140/s on
sparse scenes), and the one-draw raster pass is faster still, hence raster by default (see
docs/benchmarks.md). The two agree except on pixels whose centre lies exactly on a shared edge.

EGL: ``PYOPENGL_PLATFORM`` is set to ``egl`` (unless the caller already set it) by
:func:`use_egl_platform`, called when the first :class:`Renderer` is built, never at import.
On a machine with several GPUs pyrender 0.1.45 picks the EGL device by the environment
variable ``EGL_DEVICE_ID`` (an index into ``eglQueryDevicesEXT``, default 0; see
``pyrender/platforms/egl.py``). Set it per worker *before* the worker builds its renderer, e.g.
``EGL_DEVICE_ID=1``; ``CUDA_VISIBLE_DEVICES`` does not affect EGL device enumeration. On a
CPU-only machine Mesa's llvmpipe is used; it spreads one render over all cores unless
``LP_NUM_THREADS`` is set (DESIGN §9: two workers with ``LP_NUM_THREADS=1`` beat one default).
An EGL context does not survive ``fork``: build renderers inside each worker (spawn).

Textures: faces a stage dresses in a texture (:attr:`MeshData.face_texture`) are drawn as the
texture image (sRGB, repeat wrapping, trilinear mipmaps) times their face colour; the merged
mesh becomes one primitive per texture file (plus one for untextured faces), in file order, so
the draw order stays fixed. Each image is decoded and uploaded once per renderer.
``textures=False`` draws the same faces in their flat colours. A stage's
:class:`~sgdata.usd.meshes.Lighting` scales the lights and colours them (ambient included).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from sgdata.errors import RenderError
from sgdata.render.camera import CameraConfig
from sgdata.render.id_pass import MergedIdPass
from sgdata.render.primitives import (
    merged_world,
    mesh_primitives,
    same_mesh,
    same_shape,
    texture,
)
from sgdata.render.structure import face_parts
from sgdata.render.target import use_single_sample_target
from sgdata.render.uniforms import cache_uniform_locations
from sgdata.room_parts import DOOR, STRUCTURE_PARTS
from sgdata.usd.meshes import Lighting, MeshData, SceneGeometry

__all__ = ["RenderedView", "Renderer", "ceiling_light_pose", "use_egl_platform"]

_EGL_HINT = (
    "cannot start an EGL (headless OpenGL) context: {why}; install the Debian packages "
    "libegl1 libegl-mesa0 libgl1-mesa-dri libgles2 (or a GPU driver's EGL) and retry"
)


def use_egl_platform() -> None:
    """Select PyOpenGL's EGL platform (the one place sgdata touches the environment).

    Must run before pyrender/OpenGL is first imported; a value the caller already set (for
    example ``osmesa``) is left alone.

    llvmpipe forced to 128-bit vectors (``LP_NATIVE_VECTOR_WIDTH=128``) on a CPU with AVX
    aborts drawing a primitive with vertex colours, normals and a texture, as every textured
    one of ours is (Mesa 22.3, ``scripts/llvmpipe_width128_repro.py``). A CPU without AVX draws
    at that width with SSE4.1 code and does not abort, so a forced 128 gets that CPU's
    features too (x86 only; a value the caller set is kept).
    """
    os.environ.setdefault("PYOPENGL_PLATFORM", "egl")
    if os.environ.get("LP_NATIVE_VECTOR_WIDTH") == "128":
        os.environ.setdefault("GALLIUM_OVERRIDE_CPU_CAPS", "sse4.1")


@dataclass
class RenderedView:
    """One rendered view. ``instance`` holds instance ids, -1 for background and structure;
    ``structure`` the part of the room's structure seen (:data:`STRUCTURE_PARTS` k + 1), 0
    for an object or nothing."""

    rgb: np.ndarray  # (H, W, 3) uint8, sRGB
    instance: np.ndarray  # (H, W) int32
    depth: np.ndarray | None  # (H, W) float32 metres along the view axis, 0 where empty
    structure: np.ndarray | None = None  # (H, W) uint8


_SEG_LIMIT = 1 << 24  # 24-bit colour codes


class Renderer:
    """Renders views of one loaded room; keep one alive per worker and reuse it.

    Args:
        camera: the camera model (defaults to :class:`CameraConfig`).
        id_pass: ``"raster"`` (pyrender SEG pass, default) or ``"raycast"`` (open3d); both
            exact, see the module docstring.
        ambient: ambient light level (linear, 0..1).
        key_intensity: intensity of the head light that travels with the camera.
        fill_intensity: intensity of the point light under the ceiling's centre.
        textures: draw the textures a stage binds (False: flat face colours only).

    Raises:
        RenderError: EGL cannot start (names the packages to install).
    """

    _open = 0  # renderers of this process with a live GL context (see close)

    def __init__(
        self,
        camera: CameraConfig | None = None,
        *,
        id_pass: Literal["raycast", "raster"] = "raster",
        ambient: float = 0.35,
        key_intensity: float = 2.2,
        fill_intensity: float = 5.0,
        textures: bool = True,
    ) -> None:
        if id_pass not in ("raycast", "raster"):
            raise RenderError(f"id_pass={id_pass!r}: expected 'raycast' or 'raster'")
        self.camera = camera if camera is not None else CameraConfig()
        self.id_pass = id_pass
        self.ambient = float(ambient)
        self.key_intensity = float(key_intensity)
        self.fill_intensity = float(fill_intensity)
        self.textures = bool(textures)
        self._lighting = Lighting()
        self._texture_cache: dict[str, Any] = {}  # file -> pyrender.Texture, decoded once
        use_egl_platform()
        try:
            import pyrender  # late: needs PYOPENGL_PLATFORM, and must not load at sgdata import

            self._pr = pyrender
            self._gl = pyrender.OffscreenRenderer(self.camera.width, self.camera.height)
            self._gl._renderer._sorted_mesh_nodes = self._draw_order
            self._target = use_single_sample_target(self._gl._renderer)
            cache_uniform_locations(self._gl._renderer)
            self._ids = MergedIdPass(self._gl._renderer, self._target, self._gl._platform)
            Renderer._open += 1
        except Exception as exc:  # any failure here is an environment problem, not a bug
            why = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
            raise RenderError(_EGL_HINT.format(why=why)) from None
        self._instances: tuple[int, ...] | None = None
        self._meshes: list[MeshData] = []
        self._structure: tuple[MeshData, ...] = ()
        self._scene: Any = None
        self._rank: dict[Any, int] = {}  # mesh node -> the order it was added in
        self._merged_node: Any = None
        self._instance_lut = np.full(1, -1, dtype=np.int32)  # id pass code -> instance
        self._part_lut = np.zeros(1, dtype=np.uint8)  # id pass code -> structure part
        self._door: MeshData | None = None
        self._rays_cam = self._camera_rays()
        self._rc: Any = None
        self._matrices: list[np.ndarray] = []
        self._face_owner = np.zeros(0, dtype=np.int32)

    # -- scene management -------------------------------------------------------------------

    @property
    def instances(self) -> tuple[int, ...]:
        """Instance ids of the loaded objects, in scene order."""
        return self._instances or ()

    def load(self, scene: SceneGeometry) -> None:
        """Build the scene of a room: the structure and all objects merged into one
        world-space mesh (pyrender's per-node overhead dominates on llvmpipe), drawn by the
        RGB pass and, as codes, by the id pass."""
        pr = self._pr
        n = len(scene.objects)
        if n + 1 + len(STRUCTURE_PARTS) >= _SEG_LIMIT:
            limit = _SEG_LIMIT - 2 - len(STRUCTURE_PARTS)
            raise RenderError(f"{n} objects in one scene: the id pass encodes at most {limit}")
        self._structure, self._door = scene.structure, scene.door
        self._meshes = [obj.mesh for obj in scene.objects]
        self._matrices = [np.asarray(o.matrix) for o in scene.objects]
        self._instances = tuple(int(o.instance) for o in scene.objects)
        # codes: 0 nothing drawn, 1..n the objects, then one per structure part
        parts = len(STRUCTURE_PARTS)
        self._instance_lut = np.array((-1, *self._instances, *[-1] * parts), dtype=np.int32)
        self._part_lut = np.r_[np.zeros(n + 1), np.arange(1, parts + 1)].astype(np.uint8)
        # a dim hallway grey behind the door gap rather than a black hole
        sc = pr.Scene(bg_color=[0.45, 0.45, 0.48, 1.0], ambient_light=[self.ambient] * 3)
        self._scene, self._rank = sc, {}
        for m in scene.structure:
            self._add(pr.Mesh(self._primitives(m, double_sided=True)))
        self._merge_objects(scene)
        self._cam_node = sc.add(self._camera_model())
        # Key light rides with the camera (faces towards the viewer always read), fill light
        # hangs under the ceiling's centre so tops and fronts of boxes differ in shade. One
        # light of each type: pyrender keeps lights in sets and binds them in set order, so
        # two lights of one type would be summed in an order that varies between processes
        # (seen: +-1 levels over 769 pixels of a view), breaking byte-identical datasets.
        self._key = pr.DirectionalLight(color=np.ones(3), intensity=self.key_intensity)
        self._key_node = sc.add(self._key)
        self._fill = pr.PointLight(color=np.ones(3), intensity=self.fill_intensity)
        sc.add(self._fill, pose=ceiling_light_pose(scene))
        self._set_lighting(scene.lighting)
        self._rc = None  # built on the first raycast id pass

    def _merge_objects(self, scene: SceneGeometry) -> None:
        """All objects in one world-space mesh: the RGB scene's node and the id pass's codes
        (face ``f`` of object ``k`` carries ``k + 1``)."""
        merged = merged_world(scene.objects)
        self._merged_node = self._add(self._pr.Mesh(self._primitives(merged)))
        counts = [len(o.mesh.faces) for o in scene.objects]
        owner = np.repeat(np.arange(1, len(counts) + 1, dtype=np.uint32), counts)
        self._ids.load(self._structure_codes(), merged, owner, textured=self.textures)

    def _structure_codes(self) -> list[tuple[MeshData, np.ndarray]]:
        """Each structure mesh (the door's opening last) with its faces' id pass codes."""
        n = len(self._meshes)
        meshes = [*self._structure, *([self._door] if self._door is not None else [])]
        parts = face_parts(self._structure)
        if self._door is not None:
            parts.append(np.full(len(self._door.faces), DOOR, np.uint8))
        return [(m, n + p.astype(np.uint32)) for m, p in zip(meshes, parts, strict=True)]

    def _add(self, node_or_mesh: Any, **kwargs: Any) -> Any:
        """Add to the scene, remembering the order (the draw order's tie-break)."""
        node = self._scene.add(node_or_mesh, **kwargs)
        self._rank[node] = len(self._rank)
        return node

    def _draw_order(self, scene: Any) -> list[Any]:
        """The mesh nodes in the order pyrender draws them: opaque before transparent, far to
        near, and, at equal distance, in the order they were added.

        pyrender keeps mesh nodes in a set and sorts them by distance alone, so nodes at the
        same distance (the structure and the merged objects all sit at the origin) were drawn
        in an order that followed memory addresses and changed from run to run. Coplanar faces
        (a painting flush with its wall, a rug on the floor) then z-fought differently: one
        pixel of one view in ~50 differed between two identical runs. This replaces pyrender's
        ``Renderer._sorted_mesh_nodes`` on this renderer's instance only.
        """
        eye = scene.get_pose(scene.main_camera_node)[:3, 3]

        def key(node: Any) -> tuple[bool, float, int]:
            far = -float(np.linalg.norm(scene.get_pose(node)[:3, 3] - eye))
            return (bool(node.mesh.is_transparent), far, self._rank.get(node, -1))

        return sorted(scene.mesh_nodes, key=key)

    def update_poses(self, scene: SceneGeometry) -> bool:
        """Move the loaded objects to a new layout of the same room.

        Returns ``False`` when only poses and looks changed (the merged mesh is re-merged from
        the new meshes, with their colours and textures, and uploaded to the id pass; the
        light is set), ``True`` when the instance set, an object's shape or the
        structure differed and the scenes were rebuilt.
        """
        same = (
            self._scene is not None
            and tuple(int(o.instance) for o in scene.objects) == self._instances
            and len(scene.structure) == len(self._structure)
            and all(same_shape(o.mesh, m) for o, m in zip(scene.objects, self._meshes, strict=True))
            and all(same_mesh(a, b) for a, b in zip(scene.structure, self._structure, strict=True))
            and _same_door(scene.door, self._door)
        )
        if not same:
            self.load(scene)
            return True
        self._meshes = [obj.mesh for obj in scene.objects]
        self._matrices = [np.asarray(o.matrix) for o in scene.objects]
        self._scene.remove_node(self._merged_node)
        self._rank.pop(self._merged_node, None)
        self._merge_objects(scene)
        self._set_lighting(scene.lighting)
        self._rc = None  # rebuilt lazily with the new world vertices
        return False

    def _camera_model(self) -> Any:
        return self._pr.PerspectiveCamera(
            yfov=self.camera.yfov,
            aspectRatio=self.camera.width / self.camera.height,
            znear=self.camera.znear,
            zfar=self.camera.zfar,
        )

    # -- rendering --------------------------------------------------------------------------

    def render(
        self,
        x: float,
        y: float,
        theta: float,
        *,
        rng: np.random.Generator | None = None,
        depth: bool = True,
    ) -> RenderedView:
        """RGB, instance ids and depth from the agent pose (x, y, heading ``theta`` rad).

        ``rng`` jitters light intensities by up to +-20 % (off when None), on top of the
        stage's own light. ``depth=False`` skips reading depth back (the view's depth is None).
        """
        rgb, metres = self.render_rgb(x, y, theta, rng=rng, depth=depth)
        code = self._codes(x, y, theta, self.id_pass)
        return RenderedView(
            rgb=rgb, instance=self._instance_lut[code], depth=metres, structure=self._part_lut[code]
        )

    def render_rgb(
        self,
        x: float,
        y: float,
        theta: float,
        *,
        rng: np.random.Generator | None = None,
        depth: bool = True,
    ) -> tuple[np.ndarray, np.ndarray | None]:
        """The RGB pass only: (rgb uint8 HxWx3, depth float32 HxW or None if not ``depth``)."""
        self._require_scene()
        scale = self._lighting.intensity
        key, fill = self.key_intensity * scale, self.fill_intensity * scale
        if rng is not None:
            key *= float(rng.uniform(0.8, 1.2))
            fill *= float(rng.uniform(0.8, 1.2))
        self._key.intensity, self._fill.intensity = key, fill
        pose = self.camera.pose_matrix(x, y, theta)
        self._scene.set_pose(self._cam_node, pose)
        key_pose = pose.copy()  # tilt the head light 15 deg further down than the view
        key_pose[:3, :3] = pose[:3, :3] @ _rot_x(-math.radians(15.0))
        self._scene.set_pose(self._key_node, key_pose)
        self._target.depth = depth
        rgb, metres = self._gl.render(self._scene, flags=self._pr.RenderFlags.NONE)
        return np.ascontiguousarray(rgb), metres

    def render_ids(
        self,
        x: float,
        y: float,
        theta: float,
        *,
        id_pass: Literal["raycast", "raster"] | None = None,
    ) -> np.ndarray:
        """The id pass only: (H, W) int32 instance ids, -1 for background and structure.

        ``id_pass`` overrides the renderer's default for this call.
        """
        code = self._codes(x, y, theta, self.id_pass if id_pass is None else id_pass)
        return self._instance_lut[code]

    def render_structure(self, x: float, y: float, theta: float) -> np.ndarray:
        """The id pass only: (H, W) uint8 structure parts, as :attr:`RenderedView.structure`."""
        return self._part_lut[self._codes(x, y, theta, self.id_pass)]

    def _codes(self, x: float, y: float, theta: float, method: str) -> np.ndarray:
        """(H, W) id pass codes (indices into the instance and part tables)."""
        self._require_scene()
        if method == "raycast":
            if self._rc is None:
                self._build_raycaster(self._matrices)
            return self._raycast_index(x, y, theta)
        if method == "raster":
            return self._raster_index(x, y, theta)
        raise RenderError(f"id_pass={method!r}: expected 'raycast' or 'raster'")

    def close(self) -> None:
        """Free the GL context (also done when the renderer is garbage-collected).

        pyrender's own close terminates the EGL display, which every renderer of the process
        shares (``eglTerminate`` is not reference-counted): closing one renderer broke the
        others. Here the display is terminated only by the last open renderer.
        """
        if self._gl is None:
            return
        Renderer._open -= 1
        platform = self._gl._platform
        if Renderer._open > 0 and getattr(platform, "_egl_context", None) is not None:
            from OpenGL.EGL import eglDestroyContext

            platform.make_current()
            self._gl._renderer.delete()
            eglDestroyContext(platform._egl_display, platform._egl_context)
            platform._egl_context = None  # pyrender then skips the context, keeps the display
            platform._egl_display = None
            self._gl._renderer = self._gl._platform = None
        else:
            self._gl.delete()
        self._gl = None

    def __enter__(self) -> Renderer:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # -- internals --------------------------------------------------------------------------

    def _set_lighting(self, lighting: Lighting) -> None:
        """The stage's light: colours of the key, fill and ambient light (intensities are
        scaled in :meth:`render_rgb`)."""
        self._lighting = lighting
        color = np.asarray(lighting.color, dtype=np.float64)
        self._key.color = color
        self._fill.color = color
        self._scene.ambient_light = self.ambient * lighting.intensity * color

    def _primitives(self, mesh: MeshData, *, double_sided: bool = False) -> list[Any]:
        """The RGB primitives of a mesh (textured unless ``textures`` is off)."""
        texture_of = self._texture if self.textures else None
        return mesh_primitives(self._pr, mesh, texture_of, double_sided=double_sided)

    def _texture(self, path: str) -> Any:
        """The pyrender texture of an image file, decoded once per renderer."""
        if path not in self._texture_cache:
            self._texture_cache[path] = texture(self._pr, path)
        return self._texture_cache[path]

    def _require_scene(self) -> None:
        if self._scene is None:
            raise RenderError("no scene loaded: call Renderer.load(scene) before rendering")

    def _raster_index(self, x: float, y: float, theta: float) -> np.ndarray:
        pose = self.camera.pose_matrix(x, y, theta)
        projection = self._cam_node.camera.get_projection_matrix(
            width=self.camera.width, height=self.camera.height
        )
        code = self._ids.draw(np.linalg.inv(pose), projection)  # V and P as pyrender's
        if int(code.max()) >= len(self._instance_lut):
            raise RenderError("id pass returned an unknown colour code (blended ids?)")
        return code

    def _camera_rays(self) -> np.ndarray:
        """Per-pixel ray directions through pixel centres in (right, up, forward) coords."""
        cam = self.camera
        u = np.arange(cam.width) + 0.5
        v = np.arange(cam.height) + 0.5
        uu, vv = np.meshgrid(u, v)
        f = cam.focal
        d = np.stack(
            [(uu - cam.width / 2.0) / f, (cam.height / 2.0 - vv) / f, np.ones_like(uu)], axis=-1
        )
        return d.reshape(-1, 3)

    def _build_raycaster(self, matrices: list[np.ndarray]) -> None:
        import open3d as o3d  # late: heavy, only needed for this id pass

        verts, faces, owner, offset = [], [], [], 0
        meshes = [(m, np.eye(4), codes) for m, codes in self._structure_codes()] + [
            (mesh, np.asarray(mat), np.full(len(mesh.faces), k + 1))
            for k, (mesh, mat) in enumerate(zip(self._meshes, matrices, strict=True))
        ]
        for mesh, mat, codes in meshes:
            v = np.asarray(mesh.vertices, dtype=np.float64) @ mat[:3, :3].T + mat[:3, 3]
            verts.append(v)
            faces.append(np.asarray(mesh.faces, dtype=np.int64) + offset)
            owner.append(np.asarray(codes, dtype=np.int32))
            offset += len(v)
        rc = o3d.t.geometry.RaycastingScene()
        if offset:
            rc.add_triangles(
                o3d.core.Tensor(np.concatenate(verts).astype(np.float32)),
                o3d.core.Tensor(np.concatenate(faces).astype(np.uint32)),
            )
        self._o3d = o3d
        self._rc = rc
        # index 0 = miss (INVALID_ID maps to the extra last entry), else owner code
        self._face_owner = np.concatenate([*owner, np.zeros(1, dtype=np.int32)])

    def _raycast_index(self, x: float, y: float, theta: float) -> np.ndarray:
        cam = self.camera
        basis = self.camera.basis(theta)
        rays = np.empty((len(self._rays_cam), 6), dtype=np.float32)
        rays[:, :3] = (x, y, cam.eye_height)
        rays[:, 3:] = self._rays_cam @ basis
        hit = self._rc.cast_rays(self._o3d.core.Tensor(rays), nthreads=1)
        prim = hit["primitive_ids"].numpy().astype(np.int64)
        prim[prim >= len(self._face_owner) - 1] = len(self._face_owner) - 1  # misses
        return self._face_owner[prim].reshape(cam.height, cam.width)


def _same_door(a: MeshData | None, b: MeshData | None) -> bool:
    return a is b or (a is not None and b is not None and same_mesh(a, b))


def ceiling_light_pose(scene: SceneGeometry) -> np.ndarray:
    """A pose 0.3 m under the centre of the structure's top (the ceiling): where the renderer
    hangs its fill light (and bench/render.py's plain pyrender its point light)."""
    pose = np.eye(4)
    if scene.structure:
        points = np.concatenate([m.vertices for m in scene.structure])
        lo, hi = points.min(axis=0), points.max(axis=0)
        pose[:3, 3] = ((lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, hi[2] - 0.3)
    else:
        pose[:3, 3] = (0.0, 0.0, 2.5)
    return pose


def _rot_x(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])
