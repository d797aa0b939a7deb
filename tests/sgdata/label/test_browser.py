"""The real page end to end in Debian's headless Chromium: boxes, classes, relations, export."""

from __future__ import annotations

import os
from pathlib import Path

import pyarrow.parquet as pq

from sgdata.validate import validate_dataset

from ...cli_runner import run_cli
from .browser import app_server, fresh_page, needs_chromium
from .browser import drag as _drag
from .browser import saved as _saved
from .conftest import make_photo

pytestmark = needs_chromium


def test_label_two_photos_in_the_browser_and_export(chromium, tmp_path: Path) -> None:  # noqa: ANN001
    photos, out = tmp_path / "photos", tmp_path / "ds"
    photos.mkdir()
    make_photo(photos / "p1.png", 320, 240, seed=1)
    make_photo(photos / "p2.png", 320, 240, seed=2)
    (photos / "readme.txt").write_text("skip me")
    size = (320, 240)
    with app_server(photos, out) as url, fresh_page(chromium) as page:
        page.goto(url + "/")
        page.wait_for_selector("#photos li")
        assert "readme.txt" in page.locator("#skipped").text_content()
        # the list renders before the first photo has loaded: wait for the photo itself
        page.wait_for_selector('body[data-photo="p1.png"]')
        # photo 1: room, a table and a mug standing on it
        page.fill("#room-id", "kitchen_real")
        page.locator("#room-id").press("Enter")
        page.select_option("#room-type", "kitchen")
        _saved(page)
        _drag(page, [40, 100, 280, 230], size)
        page.keyboard.type("diningt")
        page.wait_for_selector("#class-suggest li.active")
        assert page.locator("#class-suggest li.active").inner_text() == "DiningTable"
        page.keyboard.press("Enter")
        _drag(page, [120, 60, 170, 105], size)
        page.keyboard.type("mu")
        page.keyboard.press("Enter")
        rel = page.locator('#arrows .rel[data-src="1"][data-dst="0"]')
        rel.wait_for()
        assert rel.get_attribute("data-type") == "on"
        assert rel.get_attribute("data-status") == "pending"
        rel.locator("text.hit").dispatch_event("pointerdown")
        page.keyboard.press("Enter")  # accept "mug on table"
        page.wait_for_selector('#arrows .rel[data-src="1"][data-status="accepted"]')
        _saved(page)
        if os.environ.get("SGDATA_LABEL_SCREENSHOT"):
            page.screenshot(path=os.environ["SGDATA_LABEL_SCREENSHOT"])
        # photo 2: a book inside a shelving unit (not a container: proposed "on"), retyped
        # to "in" with the I key
        page.keyboard.press("ArrowRight")
        page.wait_for_selector('body[data-photo="p2.png"]')
        page.fill("#room-id", "kitchen_real")
        page.locator("#room-id").press("Enter")
        page.select_option("#room-type", "kitchen")
        _drag(page, [20, 20, 300, 220], size)
        page.keyboard.type("ShelvingU")
        page.keyboard.press("Enter")
        _drag(page, [100, 120, 140, 160], size)
        page.keyboard.type("Book")
        page.keyboard.press("Enter")
        page.wait_for_selector('#arrows .rel[data-src="3"][data-type="on"][data-status="pending"]')
        page.locator("#stage").focus()
        page.keyboard.press("Tab")
        page.keyboard.press("i")
        page.wait_for_selector('#arrows .rel[data-type="in"][data-status="accepted"]')
        _saved(page)
        # back to photo 1: its boxes and accepted relation come back from the server
        page.keyboard.press("ArrowLeft")
        page.wait_for_selector('body[data-photo="p1.png"]')
        page.wait_for_selector('#arrows .rel[data-type="on"][data-status="accepted"]')
        assert page.locator("#boxes .box").count() == 2
    done = run_cli("sgdata", "label", photos, "--out", out, "--export")
    assert done.returncode == 0, done.stderr
    assert validate_dataset(out).ok
    rows = {
        r["obs_id"]: r
        for r in pq.read_table(out / "observations/test/kitchen_real.parquet").to_pylist()
    }
    assert set(rows) == {"kitchen_real/p1", "kitchen_real/p2"}
    p1, p2 = rows["kitchen_real/p1"], rows["kitchen_real/p2"]
    assert [(o["instance"], o["class_name"]) for o in p1["objects"]] == [
        (0, "DiningTable"),
        (1, "Mug"),
    ]
    for got, want in zip(p1["objects"], ([40, 100, 280, 230], [120, 60, 170, 105]), strict=True):
        assert all(abs(g - w) <= 1 for g, w in zip(got["box2d"], want, strict=True))
    assert [(r["src"], r["dst"], r["type"]) for r in p1["relations"]] == [(1, 0, 0)]
    # new boxes of photo 2 take ids the room has not used (0 and 1 are photo 1's table and mug)
    assert [(o["instance"], o["class_name"]) for o in p2["objects"]] == [
        (2, "ShelvingUnit"),
        (3, "Book"),
    ]
    assert [(r["src"], r["dst"], r["type"]) for r in p2["relations"]] == [(3, 2, 1)]
    assert p1["domain"] == "real" and p1["image"]["bytes"] == (photos / "p1.png").read_bytes()
