"""Driving the labeling page in Debian's headless Chromium: launch, draw, wait for a save."""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from pathlib import Path

import pytest

from .server_process import label_server

CHROMIUM = "/usr/bin/chromium"
ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
]
needs_chromium = pytest.mark.skipif(not Path(CHROMIUM).exists(), reason="needs Debian's chromium")


@contextlib.contextmanager
def labeling_page(
    photos: Path, out: Path, *extra: str, viewport: tuple[int, int] = (1400, 800), init: str = ""
) -> Iterator:
    """A page on a fresh ``sgdata label`` server, loaded; ``init`` runs before the page's JS."""
    from playwright.sync_api import sync_playwright

    with label_server(photos, out, *extra) as (url, _), sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=CHROMIUM, args=ARGS)
        try:
            page = browser.new_page(viewport={"width": viewport[0], "height": viewport[1]})
            page.failed = []  # URLs answered >= 400 (a missing favicon shows up here)
            page.on("response", lambda r: r.status >= 400 and page.failed.append(r.url))
            if init:
                page.add_init_script(init)
            page.goto(url + "/")
            page.wait_for_selector('#status[data-state="loaded"]')
            yield page
        finally:
            browser.close()


def drag(page, box: list[int], photo_size: tuple[int, int]) -> None:
    """Draw ``box`` (image pixels) with the mouse on the overlay."""
    r = page.locator("#overlay").bounding_box()
    sx, sy = r["width"] / photo_size[0], r["height"] / photo_size[1]
    page.mouse.move(r["x"] + box[0] * sx, r["y"] + box[1] * sy)
    page.mouse.down()
    page.mouse.move(r["x"] + (box[0] + box[2]) / 2 * sx, r["y"] + (box[1] + box[3]) / 2 * sy)
    page.mouse.move(r["x"] + box[2] * sx, r["y"] + box[3] * sy)
    page.mouse.up()


def click_at(page, x: float, y: float, photo_size: tuple[int, int]) -> None:
    """Click the photo at image pixel (x, y)."""
    r = page.locator("#overlay").bounding_box()
    page.mouse.click(
        r["x"] + x * r["width"] / photo_size[0], r["y"] + y * r["height"] / photo_size[1]
    )


def saved(page) -> None:
    page.wait_for_selector('#status[data-state="saved"]')


def set_room(page, room: str = "kitchen_real", kind: str = "kitchen") -> None:
    page.fill("#room-id", room)
    page.locator("#room-id").press("Enter")
    page.select_option("#room-type", kind)
    saved(page)


def box_with_class(page, box: list[int], size: tuple[int, int], typed: str) -> None:
    """Draw a box, type a class and press Enter; waits for the save."""
    drag(page, box, size)
    page.keyboard.type(typed)
    page.keyboard.press("Enter")
    saved(page)
