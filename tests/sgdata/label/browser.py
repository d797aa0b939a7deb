"""Driving the labeling page in Debian's headless Chromium: serve, draw, wait for a save.

The page's server is the app ``sgdata label`` builds (:func:`sgdata.label.server.create_app`)
under uvicorn, in a thread of the test's own process: these tests are about the page, and
``server_process.py``'s subprocess (the console script's start-up) is tested on its own."""

from __future__ import annotations

import contextlib
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from .server_process import free_port

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
# a browser test's marks: `browser`, and skipped (with its reason) where chromium is missing
needs_chromium = [
    pytest.mark.browser,
    pytest.mark.skipif(not Path(CHROMIUM).exists(), reason="needs Debian's chromium"),
]


@contextlib.contextmanager
def fresh_page(chromium, viewport: tuple[int, int] = (1400, 800)) -> Iterator:  # noqa: ANN001
    """A page in a fresh context of the session's browser (no cookies or storage shared)."""
    context = chromium.new_context(viewport={"width": viewport[0], "height": viewport[1]})
    try:
        yield context.new_page()
    finally:
        context.close()


@contextlib.contextmanager
def app_server(photos: Path, out: Path, **options: object) -> Iterator[str]:
    """The labeling app for ``photos`` and ``out`` (and ``create_app``'s ``options``) served
    on a free loopback port by uvicorn in a thread, as ``sgdata label`` serves it; yields the
    base URL, stops it on exit."""
    import uvicorn

    from sgdata.label.server import LOOPBACK, create_app

    app = create_app(photos, out, allowed_hosts=LOOPBACK, **options)
    port = free_port()
    server = uvicorn.Server(
        uvicorn.Config(app, host="127.0.0.1", port=port, log_level="warning", lifespan="on")
    )
    thread = threading.Thread(target=server.run, name="label-server", daemon=True)
    thread.start()
    try:
        deadline = time.monotonic() + 30
        while not server.started:
            if not thread.is_alive() or time.monotonic() > deadline:
                raise RuntimeError("the labeling app did not start in 30 s")
            time.sleep(0.02)
        yield f"http://127.0.0.1:{port}"
    finally:
        server.should_exit = True
        thread.join(timeout=10)


@contextlib.contextmanager
def labeling_page(
    chromium,  # noqa: ANN001  (playwright's Browser)
    photos: Path,
    out: Path,
    *,
    viewport: tuple[int, int] = (1400, 800),
    init: str = "",
    **options: object,
) -> Iterator:
    """A page on a fresh labeling server (``create_app``'s ``options``), loaded; ``init`` runs
    before the page's JS."""
    with app_server(photos, out, **options) as url, fresh_page(chromium, viewport) as page:
        page.failed = []  # URLs answered >= 400 (a missing favicon shows up here)
        page.on("response", lambda r: r.status >= 400 and page.failed.append(r.url))
        if init:
            page.add_init_script(init)
        page.goto(url + "/")
        page.wait_for_selector('#status[data-state="loaded"]')
        yield page


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
