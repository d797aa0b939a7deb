"""Views per second: bare pyrender passes (RGB, id) against the full view pipeline, and
plain pyrender (one node per object, an RGB and a SEG pass) on the same views.

    python bench/render.py --rooms 2 --views 40   # generated rooms (sgdata.world.rooms + usd)
    LP_NUM_THREADS=1 python bench/render.py --rooms 4 --json   # one thread, machine-readable

Prints frames per second of the RGB pass, the id pass, both (what the pipeline must do) and
the full pipeline (render -> annotate -> slots -> relations), and the pipeline's ratio to the
bare passes (target >= 0.85). Generated rooms are written textured (``[appearance]``
defaults): ``rgb``, ``pipeline`` and ``naive`` (plain pyrender) draw them flat, as before
textures existed; ``rgb_textured``, ``pipeline_textured`` and ``naive_textured`` draw their
textures, on the same views, flat and textured measured in turn twice (ABAB) so that a busy
machine skews both alike; ``textured/flat`` is the pipeline's ratio (target >= 0.8: at most
20 % slower), ``textured: pipeline/naive`` the headline against plain pyrender on the default
(textured) views (target >= 2).
"""

from __future__ import annotations

import argparse
import atexit
import json
import shutil
import tempfile
from pathlib import Path

import numpy as np

from sgdata.annotate.annotator import ViewAnnotator
from sgdata.annotate.records import ViewPose
from sgdata.annotate.slots import SlotTable
from sgdata.bench import sample_poses, views_per_second
from sgdata.render.camera import CameraConfig
from sgdata.render.renderer import Renderer
from sgdata.usd.meshes import SceneGeometry
from sgdata.world.scene import Room


def generated_scenes(n: int, seed: int) -> list[tuple[Room, SceneGeometry]]:
    from sgdata.usd import room_io as usd_io
    from sgdata.usd.geometry import read_geometry
    from sgdata.world.catalog import load_catalog
    from sgdata.world.rooms import generate_room

    catalog = load_catalog()
    types = ["kitchen", "living_room", "bedroom", "bathroom"]
    from sgdata.world.appearance import AppearanceConfig

    out = []
    tmp = Path(tempfile.mkdtemp(prefix="sgdata-bench-"))
    atexit.register(shutil.rmtree, tmp, ignore_errors=True)  # read until the bench ends
    for k in range(n):
        room = generate_room(types[k % len(types)], k // len(types), seed, catalog)
        path = tmp / room.room_id / "room.usda"  # textures shared in tmp/textures
        geometry = usd_io.catalog_geometry(catalog)
        usd_io.write_room(room, path, geometry=geometry, appearance=AppearanceConfig())
        out.append((room, read_geometry(path)))
    return out


class NaivePyrender:
    """pyrender used as its documentation shows: the structure and one node per object (its
    local mesh under its pose, drawn with its textures when ``textured``), two lights, an RGB
    pass and a SEG pass (instance colours), in pyrender's own (multisampled) framebuffer.

    Its GL context lives as long as the process: pyrender's ``delete`` terminates the EGL
    display every renderer of the process shares.
    """

    def __init__(self, camera: CameraConfig) -> None:
        import pyrender as pr

        self.camera, self.pr = camera, pr
        self.gl = pr.OffscreenRenderer(camera.width, camera.height)
        self.textures: dict[str, object] = {}  # file -> pyrender texture, decoded once

    def load(self, geometry: SceneGeometry, *, textured: bool = False) -> None:
        from sgdata.render.primitives import mesh_primitives, texture
        from sgdata.render.renderer import ceiling_light_pose

        pr, camera = self.pr, self.camera

        def texture_of(path: str) -> object:
            if path not in self.textures:
                self.textures[path] = texture(pr, path)
            return self.textures[path]

        def mesh(m: object, **kwargs: bool) -> object:
            return pr.Mesh(mesh_primitives(pr, m, texture_of if textured else None, **kwargs))

        scene = pr.Scene(bg_color=[0.45, 0.45, 0.48, 1.0], ambient_light=[0.35] * 3)
        seg = {}
        for m in geometry.structure:
            seg[scene.add(mesh(m, double_sided=True))] = np.zeros(3)
        for k, obj in enumerate(geometry.objects, 1):
            node = scene.add(mesh(obj.mesh), pose=np.asarray(obj.matrix))
            seg[node] = np.array([k & 255, (k >> 8) & 255, k >> 16])
        cam = pr.PerspectiveCamera(yfov=camera.yfov, aspectRatio=camera.width / camera.height)
        self.cam_node = scene.add(cam)
        scene.add(pr.DirectionalLight(color=np.ones(3), intensity=2.0), parent_node=self.cam_node)
        scene.add(pr.PointLight(color=np.ones(3), intensity=6.0), pose=ceiling_light_pose(geometry))
        self.scene, self.seg = scene, seg

    def view(self, pose: ViewPose) -> tuple[np.ndarray, np.ndarray]:
        self.scene.set_pose(self.cam_node, self.camera.pose_matrix(pose.x, pose.y, pose.theta))
        rgb, _ = self.gl.render(self.scene)
        ids, _ = self.gl.render(self.scene, flags=self.pr.RenderFlags.SEG, seg_node_map=self.seg)
        return rgb, ids


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rooms", type=int, default=1, help="generated rooms to bench")
    ap.add_argument("--views", type=int, default=40, help="views per room and measurement")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--id-pass", choices=["raster", "raycast"], default="raster")
    ap.add_argument("--json", action="store_true", help="print one JSON line of the means")
    args = ap.parse_args()

    scenes = generated_scenes(args.rooms, args.seed)
    classes = sorted({o.class_name for room, _ in scenes for o in room.objects})
    slots = SlotTable.from_counts([(c, 8) for c in classes], num_slots=max(256, 8 * len(classes)))
    renderer = Renderer(id_pass=args.id_pass)
    naive = NaivePyrender(renderer.camera)
    annotator = ViewAnnotator(renderer, slots)
    rng = np.random.default_rng(args.seed)
    keys = (
        "rgb",
        "ids",
        "rgb+ids",
        "pipeline",
        "naive",
        "rgb_textured",
        "pipeline_textured",
        "naive_textured",
    )
    totals: dict[str, list[float]] = {k: [] for k in keys}

    def draw(textured: bool) -> None:
        renderer.textures = textured
        renderer.load(geometry)  # rebuilds the primitives with or without textures

    for room, geometry in scenes:
        annotator.set_layout(room, geometry, 0)
        poses = sample_poses(room, args.views, rng)
        if not poses:
            print(f"{room.room_id}: no reachable cells, skipped")
            continue
        draw(False)
        fps = {
            "rgb": views_per_second(lambda p: renderer.render_rgb(p.x, p.y, p.theta), poses),
            "ids": views_per_second(lambda p: renderer.render_ids(p.x, p.y, p.theta), poses),
            "rgb+ids": views_per_second(lambda p: renderer.render(p.x, p.y, p.theta), poses),
        }
        runs: dict[str, list[float]] = {"pipeline": [], "pipeline_textured": []}
        for textured in (False, True, False, True):  # ABAB: load changes hit both alike
            draw(textured)
            key = "pipeline_textured" if textured else "pipeline"
            runs[key].append(views_per_second(lambda p: annotator.view(p), poses))
        fps["rgb_textured"] = views_per_second(
            lambda p: renderer.render_rgb(p.x, p.y, p.theta), poses
        )
        fps.update({k: float(np.mean(v)) for k, v in runs.items()})
        naive_runs: dict[str, list[float]] = {"naive": [], "naive_textured": []}
        for textured in (False, True, False, True):
            naive.load(geometry, textured=textured)
            naive_runs["naive_textured" if textured else "naive"].append(
                views_per_second(naive.view, poses)
            )
        fps.update({k: float(np.mean(v)) for k, v in naive_runs.items()})
        for key, value in fps.items():
            totals[key].append(value)
        objs = len(geometry.objects)
        tris = sum(len(o.mesh.faces) for o in geometry.objects)
        print(
            f"{room.room_id}: {objs} objects, {tris} triangles | "
            + " | ".join(f"{k} {v:.1f}/s" for k, v in fps.items())
        )
    if totals["pipeline"]:
        mean = {k: float(np.mean(v)) for k, v in totals.items()}
        mean["pipeline/naive"] = mean["pipeline"] / mean["naive"]
        mean["textured: pipeline/naive"] = mean["pipeline_textured"] / mean["naive_textured"]
        mean["pipeline/(rgb+ids)"] = mean["pipeline"] / mean["rgb+ids"]
        mean["textured/flat"] = mean["pipeline_textured"] / mean["pipeline"]
        if args.json:
            print(json.dumps(mean))
        else:
            print("mean: " + " | ".join(f"{k} {v:.2f}" for k, v in mean.items()))
    renderer.close()


if __name__ == "__main__":
    main()
