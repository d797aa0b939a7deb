"""The textured-draw crash of issue 50, reduced: plain pyrender, one textured box, no sgdata.

    LP_NATIVE_VECTOR_WIDTH=128 python scripts/llvmpipe_width128_repro.py col nor tex   # aborts
    LP_NATIVE_VECTOR_WIDTH=128 python scripts/llvmpipe_width128_repro.py col tex       # fine

Measured 2026-12-04 on llvmpipe (LLVM 15.0.6) of Mesa 22.3.6 (Debian 12): the draw aborts with
heap corruption ("malloc(): invalid size", "double free or corruption") at vector width 128
when one primitive has vertex colours (COLOR_0), normals and a sampled base-colour texture;
any two of the three draw fine, so do all three at the default width 256. Texture size (64 to
1024 px) and channels (RGB, RGBA), lights, double-sidedness and sgdata's own render target,
draw order and uniform cache make no difference. sgdata's textured primitives carry all three
(a texture tinted by a per-face colour), so `sgdata render` and `generate` abort there.
"""

import os
import sys

os.environ.setdefault("PYOPENGL_PLATFORM", "egl")

import numpy as np  # noqa: E402
import pyrender as pr  # noqa: E402
import trimesh  # noqa: E402

parts = set(sys.argv[1:]) or {"col", "nor", "tex"}
box = trimesh.creation.box()
corners = box.vertices[box.faces].reshape(-1, 3).astype(np.float32)
texture = None
if "tex" in parts:
    pixels = np.random.default_rng(0).integers(0, 255, (256, 256, 3)).astype(np.uint8)
    texture = pr.Texture(source=pixels, source_channels="RGB")
fields = {
    "positions": corners,
    "texcoord_0": np.random.default_rng(1).random((len(corners), 2)).astype(np.float32),
    "material": pr.MetallicRoughnessMaterial(baseColorTexture=texture),
}
if "col" in parts:
    fields["color_0"] = np.ones((len(corners), 4), np.float32)
if "nor" in parts:
    fields["normals"] = np.repeat(box.face_normals, 3, axis=0).astype(np.float32)
scene = pr.Scene(ambient_light=[0.3] * 3)
scene.add(pr.Mesh([pr.Primitive(**fields)]))
pose = np.eye(4)
pose[2, 3] = 3.0
scene.add(pr.PerspectiveCamera(yfov=1.0), pose=pose)
rgb, _ = pr.OffscreenRenderer(64, 64).render(scene)
print(f"drew {sorted(parts)}: mean {rgb.mean():.2f}")
