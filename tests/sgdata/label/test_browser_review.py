"""The page in Chromium on what a new user ran into: fast undo, big photos, covered boxes,
unknown classes, carry over, and the ready-to-export marker."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from PIL import Image, ImageDraw

from ...cli_runner import run_cli
from .browser import box_with_class, click_at, drag, labeling_page, needs_chromium, saved, set_room
from .conftest import make_photo

pytestmark = needs_chromium
SIZE = (320, 240)
# Every save's answer arrives 400 ms late (the server has stored it already): the window in
# which a fast undo used to send a stale revision.
SLOW_SAVES = """
const realFetch = window.fetch;
window.fetch = async (url, options) => {
  const response = await realFetch(url, options);
  if (options && options.method === "PUT") await new Promise((ok) => setTimeout(ok, 400));
  return response;
};
"""


def _photos(tmp_path: Path, *names: str) -> Path:
    root = tmp_path / "photos"
    root.mkdir()
    for k, name in enumerate(names):
        make_photo(root / name, *SIZE, seed=k)
    return root


def _stored(out: Path, name: str) -> dict:
    return json.loads((out / "labels" / f"{name}.json").read_text())


def _selected(page) -> str | None:
    found = page.locator("#box-list li.selected")
    return found.get_attribute("data-id") if found.count() else None


def test_fast_undo_after_a_draw_is_saved_not_refused(chromium, tmp_path: Path) -> None:
    photos, out = _photos(tmp_path, "p1.png"), tmp_path / "ds"
    with labeling_page(chromium, photos, out, init=SLOW_SAVES) as page:
        set_room(page)
        drag(page, [40, 40, 200, 200], SIZE)
        page.keyboard.press("Escape")  # leave the class field
        page.keyboard.press("Control+z")  # while the draw's save is in flight
        page.wait_for_timeout(1500)
        saved(page)
        assert _stored(out, "p1.png")["objects"] == []
        assert "boxes" not in page.locator('#photos li[data-name="p1.png"]').inner_text()
        page.keyboard.press("Control+y")
        page.keyboard.press("Control+z")
        page.keyboard.press("Control+y")
        page.wait_for_timeout(2000)
        saved(page)
        assert len(_stored(out, "p1.png")["objects"]) == 1
        assert "1 boxes" in page.locator('#photos li[data-name="p1.png"]').inner_text()


def test_text_is_readable_on_a_phone_sized_photo(chromium, tmp_path: Path) -> None:
    photos, out = tmp_path / "photos", tmp_path / "ds"
    photos.mkdir()
    image = Image.new("RGB", (6000, 4000), (180, 170, 160))
    ImageDraw.Draw(image).rectangle([500, 2500, 5500, 3900], fill=(120, 80, 40))
    image.save(photos / "phone.jpg", quality=80)
    size = (6000, 4000)
    with labeling_page(chromium, photos, out) as page:
        box_with_class(page, [500, 2500, 5500, 3900], size, "DiningT")
        box_with_class(page, [2000, 1500, 2600, 2700], size, "Mug")
        page.wait_for_selector("#arrows .rel text")
        heights = page.evaluate(
            """() => [...document.querySelectorAll('#boxes text, #arrows text')]
                 .map((t) => t.getBoundingClientRect().height)"""
        )
        assert len(heights) == 3 and min(heights) >= 12, heights  # screen pixels


def test_a_box_under_a_later_bigger_box_can_be_selected(chromium, tmp_path: Path) -> None:
    photos, out = _photos(tmp_path, "p1.png"), tmp_path / "ds"
    with labeling_page(chromium, photos, out) as page:
        box_with_class(page, [100, 100, 150, 150], SIZE, "Mug")  # id 0
        box_with_class(page, [50, 50, 250, 230], SIZE, "DiningT")  # id 1, drawn over it
        page.wait_for_selector("#arrows .rel")  # an arrow now runs through the mug's centre
        click_at(page, 125, 125, SIZE)
        assert _selected(page) == "0"
        click_at(page, 125, 125, SIZE)  # again: the box beneath
        assert _selected(page) == "1"
        click_at(page, 125, 125, SIZE)
        assert _selected(page) == "0"
        page.keyboard.press("n")  # keyboard: next box in the list
        assert _selected(page) == "1"
        page.locator('#box-list li[data-id="0"]').click()
        assert _selected(page) == "0"
        assert _stored(out, "p1.png")["objects"][0]["box"] == [100, 100, 150, 150]  # not moved


def test_carry_over_asks_before_replacing_labels(chromium, tmp_path: Path) -> None:
    photos, out = _photos(tmp_path, "p1.png", "p2.png"), tmp_path / "ds"
    with labeling_page(chromium, photos, out) as page:
        set_room(page)
        box_with_class(page, [10, 10, 100, 100], SIZE, "Chair")
        page.keyboard.press("ArrowRight")
        page.wait_for_selector('body[data-photo="p2.png"]')
        set_room(page)
        box_with_class(page, [50, 50, 300, 200], SIZE, "Sofa")
        asked = []
        page.once("dialog", lambda d: (asked.append(d.message), d.dismiss()))
        page.keyboard.press("c")
        page.wait_for_selector('#status[data-state="carry over cancelled"]')
        assert asked and asked[0].startswith("Replace the 1 box(es) of this photo")
        assert [o["class_name"] for o in _stored(out, "p2.png")["objects"]] == ["Sofa"]
        page.once("dialog", lambda d: d.accept())
        page.keyboard.press("c")
        page.wait_for_selector('#box-list li:has-text("Chair")')
        saved(page)
        assert [o["class_name"] for o in _stored(out, "p2.png")["objects"]] == ["Chair"]


# The box's save answers after the class is looked up, as it did on a loaded machine.
LATE_SAVES = """
const plainFetch = window.fetch;
window.fetch = async (path, options) => {
  const answer = await plainFetch(path, options);
  if (options && options.method === "PUT") await new Promise((done) => setTimeout(done, 700));
  return answer;
};
"""


def test_unknown_class_is_said_with_the_closest_names(chromium, tmp_path: Path) -> None:
    """The message stays when the box's save lands after it: "saved" does not hide it."""
    photos, out = _photos(tmp_path, "p1.png"), tmp_path / "ds"
    with labeling_page(chromium, photos, out, init=LATE_SAVES) as page:
        drag(page, [40, 40, 200, 200], SIZE)
        page.keyboard.type("Mugg")
        page.keyboard.press("Enter")
        page.wait_for_selector('#status[data-state="error"]')
        page.wait_for_selector('#problems:has-text("box 0 has no class")')  # the save landed
        status = page.locator("#status")
        assert status.get_attribute("data-state") == "error"
        assert "closest: Mug" in status.inner_text() and '"Mugg" = "Mug"' in status.inner_text()


def test_ready_marker_counts_photos_ready_to_export(chromium, tmp_path: Path) -> None:
    photos, out = _photos(tmp_path, "p1.png", "p2.png"), tmp_path / "ds"
    with labeling_page(chromium, photos, out) as page:
        assert page.locator("#ready-count").inner_text() == "0/2 ready to export"
        set_room(page)
        box_with_class(page, [40, 100, 280, 230], SIZE, "DiningT")
        box_with_class(page, [120, 60, 170, 105], SIZE, "Mug")
        box_with_class(page, [282, 100, 318, 230], SIZE, "Chair")
        relations = page.locator("#relations").inner_text()
        assert "1 Mug → on 0 DiningTable" in relations
        assert "0 DiningTable ⟷ proximity 2 Chair" in relations
        assert "2 undecided proposal(s)" in page.locator("#problems").inner_text()
        assert page.locator('#photos li[data-name="p1.png"]').get_attribute("data-ready") == "no"
        page.locator("#stage").focus()
        page.keyboard.press("Tab")
        page.keyboard.press("Enter")
        saved(page)
        page.keyboard.press("d")  # the chair is not "close" in the relation's sense
        saved(page)
        page.wait_for_selector('#photos li[data-name="p1.png"][data-ready="yes"]')
        assert page.locator("#ready-count").inner_text() == "1/2 ready to export"
        assert page.locator("#ready").inner_text() == "ready to export"
        assert page.failed == []  # no 404 (favicon) nor any refused request


def test_cup_on_a_saucer_photo_proposes_on(chromium, tmp_path: Path) -> None:
    """scikit-image's coffee photo (CC0), labelled as a person would; the docs' screenshot."""
    import os
    import shutil

    import skimage.data

    photos, out = tmp_path / "photos", tmp_path / "ds"
    photos.mkdir()
    shutil.copy(Path(skimage.data.__file__).parent / "coffee.png", photos / "coffee.png")
    size = (600, 400)
    with labeling_page(chromium, photos, out, viewport=(1280, 560)) as page:
        set_room(page, "cafe_1", "kitchen")
        box_with_class(page, [76, 70, 480, 388], size, "Plate")  # the saucer
        box_with_class(page, [172, 18, 410, 308], size, "Cup")
        box_with_class(page, [325, 66, 425, 326], size, "Spoon")
        cup_on_saucer = page.locator('#arrows .rel[data-src="1"][data-dst="0"]')
        assert cup_on_saucer.get_attribute("data-type") == "on"
        cup_on_saucer.locator("text.hit").click()
        page.keyboard.press("Enter")
        page.wait_for_selector('#arrows .rel[data-src="1"][data-status="accepted"]')
        saved(page)
        page.locator('#box-list li[data-id="1"]').click()  # show a selected box
        if os.environ.get("SGDATA_LABEL_SCREENSHOT"):
            page.screenshot(path=os.environ["SGDATA_LABEL_SCREENSHOT"])


@pytest.mark.slow  # twenty 12-megapixel photos through the page and the export
def test_a_day_of_work_twenty_phone_photos_of_one_room(chromium, tmp_path: Path) -> None:
    """20 phone-sized photos of one room without a reload: carry over, move, fast undo/redo."""
    import pyarrow.parquet as pq

    from sgdata.validate import validate_dataset

    photos, out = tmp_path / "photos", tmp_path / "ds"
    photos.mkdir()
    size = (4032, 3024)
    for k in range(20):
        image = Image.new("RGB", size, (170 + k, 160, 150))
        ImageDraw.Draw(image).rectangle([500, 1500, 3500, 2900], fill=(110, 70, 40))
        image.save(photos / f"IMG_{k:04d}.jpg", quality=85)
    with labeling_page(chromium, photos, out, init=SLOW_SAVES) as page:
        set_room(page, "kitchen_home", "kitchen")
        box_with_class(page, [500, 1500, 3500, 2900], size, "DiningT")
        box_with_class(page, [1500, 1000, 2000, 1600], size, "Mug")
        page.locator("#stage").focus()
        page.keyboard.press("Tab")
        page.keyboard.press("Enter")  # mug on table
        for k in range(1, 20):
            page.keyboard.press("ArrowRight")
            page.wait_for_selector(f'body[data-photo="IMG_{k:04d}.jpg"]')
            page.keyboard.press("c")  # an empty photo: no question asked
            page.wait_for_selector('#box-list li[data-id="1"]')
            page.locator('#box-list li[data-id="1"]').click()
            r = page.locator("#overlay").bounding_box()
            sx = r["width"] / size[0]
            centre = 1750 + 5 * (k - 1) * k  # where the carried-over mug is now
            x, y = r["x"] + centre * sx, r["y"] + 1300 * sx
            page.mouse.move(x, y)
            page.mouse.down()
            page.mouse.move(x + 10 * k * sx, y)
            page.mouse.up()
            page.keyboard.press("Control+z")
            page.keyboard.press("Control+y")
        page.wait_for_timeout(1500)
        saved(page)
        assert page.locator("#ready-count").inner_text() == "20/20 ready to export"
    done = run_cli("sgdata", "label", photos, "--out", out, "--export")
    assert done.returncode == 0, done.stderr
    assert "undecided" not in done.stdout
    report = validate_dataset(out)
    assert report.ok, report.problems
    rows = pq.read_table(out / "observations/test/kitchen_home.parquet").to_pylist()
    assert len(rows) == 20
    for row in rows:
        k = int(row["obs_id"][-4:])
        mug = row["objects"][1]
        assert [o["class_name"] for o in row["objects"]] == ["DiningTable", "Mug"]
        # each photo carries the last one's mug over and moves it 10 k px further right
        assert abs(mug["box2d"][0] - (1500 + 5 * k * (k + 1))) <= 2 * k + 1  # every move kept
        assert [(r["src"], r["dst"], r["type"]) for r in row["relations"]] == [(1, 0, 0)]


def test_undecodable_photo_is_shown_with_its_reason(chromium, tmp_path: Path) -> None:
    photos, out = _photos(tmp_path, "p1.png"), tmp_path / "ds"
    make_photo(photos / "whole.jpg", *SIZE, seed=5)
    data = (photos / "whole.jpg").read_bytes()
    (photos / "cut.jpg").write_bytes(data[: len(data) * 2 // 3])
    (photos / "whole.jpg").unlink()
    with labeling_page(chromium, photos, out) as page:
        assert page.locator("#skipped-box").get_attribute("open") is not None  # shown, not folded
        assert page.locator("#skipped-box summary").inner_text() == "1 skipped file(s)"
        text = page.locator("#skipped").inner_text()
        assert text.startswith("cut.jpg: cannot be decoded (image file is truncated")
        assert [p.get_attribute("data-name") for p in page.locator("#photos li").all()] == [
            "p1.png"
        ]
