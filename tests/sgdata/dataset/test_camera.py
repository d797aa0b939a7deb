"""The camera per view (format 2.2.0): K and the camera-to-world pose stored with each view
agree with the renderer that drew it, put 3D boxes around their 2D boxes, reach the COCO
export, and leave the dataset's recipe as it was."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np

from sgdata.dataset import Dataset
from sgdata.dataset.manifest import read_manifest
from sgdata.label.coco_export import export_coco
from sgdata.pinhole import OPENGL_FROM_OPENCV
from sgdata.render.camera import CameraConfig

COLUMNS = ["obs_id", "x", "y", "theta", "camera", "objects", "intrinsics", "camera_to_world"]


def _project(points: np.ndarray, k: list[float], pose: np.ndarray) -> np.ndarray:
    """(N, 3) room points -> (N, 3) of pixel u, v and depth along the camera's +Z."""
    fx, fy, cx, cy = k
    cam = (points - pose[:3, 3]) @ pose[:3, :3]  # R^T (X - t), row by row
    return np.stack(
        [cx + fx * cam[:, 0] / cam[:, 2], cy + fy * cam[:, 1] / cam[:, 2], cam[:, 2]], 1
    )


def _corners(low: list[float], high: list[float]) -> np.ndarray:
    return np.array([[x, y, z] for x in (low[0], high[0]) for y in (low[1], high[1])
                     for z in (low[2], high[2])])  # fmt: skip


def test_k_and_the_pose_are_the_renderers_and_box_the_objects(mini_dataset: Path) -> None:
    rows = Dataset.open(mini_dataset).observations("train", columns=COLUMNS).to_pylist()
    boxed = 0
    for row in rows:
        cam = row["camera"]
        config = CameraConfig(width=cam["width"], height=cam["height"], hfov_deg=cam["hfov_deg"],
                              eye_height=cam["eye_height"], pitch_deg=cam["pitch_deg"])  # fmt: skip
        k, pose = row["intrinsics"], np.array(row["camera_to_world"]).reshape(4, 4)
        assert k == [config.focal, config.focal, cam["width"] / 2, cam["height"] / 2]
        np.testing.assert_allclose(pose[:3, 3], (row["x"], row["y"], cam["eye_height"]))
        np.testing.assert_allclose(pose[:3, :3].T @ pose[:3, :3], np.eye(3), atol=1e-12)
        assert np.linalg.det(pose[:3, :3]) > 0 and pose[3].tolist() == [0, 0, 0, 1]
        # the renderer's own camera (OpenGL axes) is the stored one turned
        np.testing.assert_allclose(config.pose_matrix(row["x"], row["y"], row["theta"]),
                                   pose @ OPENGL_FROM_OPENCV, atol=1e-12)  # fmt: skip
        for obj in row["objects"]:
            corners = _corners(obj["box3d_min"], obj["box3d_max"])
            mine = _project(corners, k, pose)
            theirs = config.project(corners, row["x"], row["y"], row["theta"])
            np.testing.assert_allclose(mine, theirs, rtol=1e-9, atol=1e-6)
            if (mine[:, 2] <= config.znear).any():
                continue  # a corner behind the camera: its projection bounds nothing
            # what is seen of the object lies inside its whole box's projection
            u1, v1, u2, v2 = obj["box2d"]
            assert mine[:, 0].min() - 1 <= u1 <= u2 <= mine[:, 0].max() + 1, row["obs_id"]
            assert mine[:, 1].min() - 1 <= v1 <= v2 <= mine[:, 1].max() + 1, row["obs_id"]
            boxed += 1
    assert boxed > 20


def test_the_coco_export_carries_each_views_camera(mini_dataset: Path, tmp_path: Path) -> None:
    export_coco(mini_dataset, tmp_path / "coco", split="val")
    images = json.loads((tmp_path / "coco/annotations/instances_val.json").read_text())["images"]
    rows = Dataset.open(mini_dataset).observations("val", columns=COLUMNS).to_pylist()
    stored = {r["obs_id"]: r for r in rows}
    assert len(images) == len(rows)
    for image in images:
        row = stored[image["obs_id"]]
        fx, fy, cx, cy = row["intrinsics"]
        assert image["intrinsics"] == [[fx, 0.0, cx], [0.0, fy, cy], [0.0, 0.0, 1.0]]
        assert np.array(image["camera_to_world"]).reshape(-1).tolist() == row["camera_to_world"]


def test_a_format_that_only_adds_the_camera_keeps_the_recipe(mini_dataset: Path) -> None:
    manifest = read_manifest(mini_dataset)
    assert manifest.format_version == "2.3.0"  # the camera (2.2.0), the structure mask (2.3.0)
    recipe = manifest.recipe_fingerprint()
    for version in ("2.2.0", "2.1.0"):  # the records of such a dataset still count
        older = dataclasses.replace(manifest, format_version=version)
        assert older.recipe_fingerprint() == recipe
    other = dataclasses.replace(manifest, format_version="2.0.1")  # other views: other recipe
    assert other.recipe_fingerprint() != recipe
