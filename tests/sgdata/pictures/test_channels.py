"""sgdata.pictures.channels: colourised depth and masks, and the strips render and report draw."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PIL import Image

from sgdata.dataset.channels import class_mask
from sgdata.pictures.channels import (
    DEPTH_RAMP_METRES,
    channel_strip,
    colour_depth,
    colour_mask,
)
from sgdata.pictures.report import write_report

TITLE, GAP = 14, 4  # the strip's title band and the gap between panels, in pixels
NEAR, FAR = (253, 231, 37), (68, 1, 84)  # the ramp's ends


def _luma(rgb: np.ndarray) -> np.ndarray:
    return rgb.astype(np.float64) @ np.array([0.299, 0.587, 0.114])


def test_colour_depth_ramp() -> None:
    metres = np.array([[0.0, 1e-6, 2.0, 4.0], [6.0, DEPTH_RAMP_METRES, 20.0, -1.0]])
    rgb = colour_depth(metres)
    assert rgb.shape == (2, 4, 3) and rgb.dtype == np.uint8
    assert rgb[0, 0].tolist() == [0, 0, 0] and rgb[1, 3].tolist() == [0, 0, 0]  # no hit
    assert tuple(rgb[0, 1]) == NEAR
    assert tuple(rgb[1, 1]) == FAR and tuple(rgb[1, 2]) == FAR  # beyond the ramp: its end
    ramp = _luma(np.array([rgb[0, 1], rgb[0, 2], rgb[0, 3], rgb[1, 0], rgb[1, 1]]))
    assert (np.diff(ramp) < 0).all()  # nearer is brighter


def test_colour_mask_is_a_fixed_colour_per_value() -> None:
    mask = np.array([[0, 1, 2], [3, 2, 0]], dtype=np.uint16)
    rgb = colour_mask(mask)
    assert rgb.shape == (2, 3, 3) and rgb.dtype == np.uint8
    assert rgb[0, 0].tolist() == [0, 0, 0] and rgb[1, 2].tolist() == [0, 0, 0]  # background
    assert rgb[0, 2].tolist() == rgb[1, 1].tolist()  # one value, one colour
    colours = {tuple(rgb[0, 1]), tuple(rgb[0, 2]), tuple(rgb[1, 0])}
    assert len(colours) == 3 and min(min(c) for c in colours) >= 64  # distinct and bright
    # a value's colour does not depend on what else the mask holds (same class, same colour)
    big = np.arange(300, dtype=np.uint16).reshape(15, 20)
    assert colour_mask(big)[0, 2].tolist() == rgb[0, 2].tolist()
    assert np.array_equal(colour_mask(big), colour_mask(big.copy()))


def _view(h: int = 30, w: int = 40) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(3)
    rgb = rng.integers(0, 255, (h, w, 3), dtype=np.uint8)
    instances = np.zeros((h, w), dtype=np.uint16)
    instances[5:15, 5:20], instances[18:28, 22:38] = 1, 2
    depth = np.where(instances > 0, 1.5, 0.0) + np.where(instances == 2, 1.0, 0.0)
    return rgb, depth, instances, np.array([7, 7], dtype=np.int64)


def _panel(strip: Image.Image, k: int, h: int, w: int) -> np.ndarray:
    x = k * (w + GAP)
    return np.asarray(strip)[TITLE : TITLE + h, x : x + w]


def test_channel_strip_panels_sizes_and_background() -> None:
    rgb, depth, instances, class_ids = _view()
    h, w = rgb.shape[:2]
    strip = channel_strip(rgb, depth=depth, instances=instances, class_ids=class_ids)
    assert strip.mode == "RGB" and strip.size == (4 * w + 3 * GAP, h + TITLE)
    pixels = np.asarray(strip)
    assert (pixels[TITLE:, w : w + GAP] == 255).all()  # white between the panels
    assert np.array_equal(_panel(strip, 0, h, w), rgb)
    assert np.array_equal(_panel(strip, 1, h, w), colour_depth(depth))
    assert np.array_equal(_panel(strip, 2, h, w), colour_mask(instances))
    classes = _panel(strip, 3, h, w)
    assert np.array_equal(classes, colour_mask(class_mask(instances, class_ids)))
    assert classes[10, 10].tolist() == classes[20, 30].tolist()  # two objects of one class
    assert (_panel(strip, 1, h, w)[instances == 0] == 0).all()  # no hit: black
    # the same view draws the same bytes
    again = channel_strip(rgb, depth=depth, instances=instances, class_ids=class_ids)
    assert again.tobytes() == strip.tobytes()


def test_channel_strip_leaves_out_what_is_missing() -> None:
    rgb, depth, instances, class_ids = _view()
    h, w = rgb.shape[:2]
    assert channel_strip(rgb, depth=None, instances=None).size == (w, h + TITLE)
    assert channel_strip(rgb, depth=depth, instances=None).size == (2 * w + GAP, h + TITLE)
    no_classes = channel_strip(rgb, depth=None, instances=instances)
    assert no_classes.size == (2 * w + GAP, h + TITLE)


def test_report_shows_the_channels(
    channels_dataset: Path, mini_dataset: Path, tmp_path: Path
) -> None:
    written = write_report(channels_dataset, tmp_path / "rep", triplets=1, seed=1)
    assert tmp_path / "rep/channels.png" in written
    with Image.open(tmp_path / "rep/channels.png") as sheet:
        # three views of 96 px, each RGB | depth | instances | classes
        assert sheet.size == (4 * 96 + 3 * GAP, 3 * (96 + TITLE + 6))
        pixels = np.asarray(sheet.convert("RGB"))
    depth_panel = pixels[TITLE : TITLE + 96, 96 + GAP : 2 * 96 + GAP]
    assert len(np.unique(depth_panel.reshape(-1, 3), axis=0)) > 10  # a ramp, not a flat fill
    again = write_report(channels_dataset, tmp_path / "rep2", triplets=1, seed=1)
    assert (tmp_path / "rep2/channels.png").read_bytes() == (
        tmp_path / "rep/channels.png"
    ).read_bytes()
    assert again == [tmp_path / "rep2" / p.name for p in written]
    # a dataset without channels has no channel sheet
    plain = write_report(mini_dataset, tmp_path / "plain", triplets=1, seed=1)
    assert not (tmp_path / "plain/channels.png").exists() and len(plain) == len(written) - 1
