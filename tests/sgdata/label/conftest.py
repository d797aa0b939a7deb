"""Shared factories of the labeling tests: a photos directory with small generated photos."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from .browser import ARGS, CHROMIUM


def make_photo(path: Path, width: int = 320, height: int = 240, seed: int = 0) -> Path:
    """A small PNG (or JPEG by suffix) with a few coloured rectangles."""
    rng = np.random.default_rng(seed)
    pixels = np.full((height, width, 3), 200, dtype=np.uint8)
    for _ in range(4):
        u, v = int(rng.integers(0, width - 40)), int(rng.integers(0, height - 40))
        pixels[v : v + 40, u : u + 60] = rng.integers(0, 255, 3, dtype=np.uint8)
    Image.fromarray(pixels).save(path)
    return path


@pytest.fixture
def photos_dir(tmp_path: Path) -> Path:
    """Two 320x240 PNG photos, a JPEG and two files that are not photos."""
    root = tmp_path / "photos"
    root.mkdir()
    make_photo(root / "a.png", seed=1)
    make_photo(root / "b.png", seed=2)
    make_photo(root / "c.jpg", width=200, height=100, seed=3)
    (root / "notes.txt").write_text("not a photo\n")
    (root / "broken.png").write_bytes(b"\x89PNG not really")
    return root


@pytest.fixture(scope="session")
def chromium() -> Iterator:
    """One headless Chromium for the whole test session; each test opens its own context."""
    from playwright.sync_api import sync_playwright

    with sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=CHROMIUM, args=ARGS)
        yield browser
        browser.close()
