"""A detector's boxes in the labeling page (``sgdata label --detector``): dashed and marked as
proposed until the labeler accepts one (Enter) or deletes it (Del); seannet's trained detector
proposes them on one of its own test views."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
from PIL import Image

from sgdata.label.box_proposer import open_proposer
from sgdata.label.classes import load_class_names

from .browser import labeling_page, needs_chromium, saved

pytestmark = needs_chromium


def test_a_labeler_accepts_one_proposed_box_and_deletes_another(
    chromium, detector_run: Path, tmp_path: Path
) -> None:
    photos, out = tmp_path / "photos", tmp_path / "ds"
    photos.mkdir()
    view = sorted((detector_run / "coco" / "images" / "test").iterdir())[0]
    photo = shutil.copy(view, photos / view.name)
    # a floor that keeps the detector's best three or four boxes
    found = open_proposer(detector_run, min_score=0.0, known=load_class_names(None).all_names())(
        np.asarray(Image.open(photo).convert("RGB"))
    )
    assert len(found) >= 2, found
    floor = found[min(3, len(found) - 1)].score
    shown = [b for b in found if b.score >= floor]
    with labeling_page(chromium, photos, out, detector=detector_run, min_score=floor) as page:
        items = page.locator("#box-list li.proposed")
        assert items.count() == len(shown)
        assert page.locator("#boxes .box.proposed").count() == len(shown)
        assert f"{len(shown)} box(es) proposed by {detector_run}" in page.inner_text(
            "#proposed-note"
        )
        assert "proposed box(es) to accept" in page.inner_text("#problems")
        page.locator("#stage").focus()
        page.keyboard.press("Enter")  # no box selected: Enter accepts nothing, nothing is saved
        assert page.locator("#accept-box").is_disabled()
        first, second = (int(items.nth(k).get_attribute("data-id")) for k in (0, 1))
        items.nth(0).click()
        assert page.locator("#accept-box").is_enabled()
        page.keyboard.press("Enter")
        saved(page)
        page.locator(f'#box-list li[data-id="{second}"]').click()
        page.keyboard.press("Delete")
        saved(page)
        stored = json.loads((out / "labels" / f"{view.name}.json").read_text())
        boxes = {o["id"]: o for o in stored["objects"]}
        assert "proposed" not in boxes[first] and second not in boxes
        assert boxes[first]["class_name"] == shown[0].class_name
        assert list(boxes[first]["box"]) == list(shown[0].box)
        assert len(boxes) == len(shown) - 1
        assert all(o["proposed"] > 0 for k, o in boxes.items() if k != first)
        assert page.locator(f'#boxes .box[data-id="{first}"]').get_attribute("class") == "box"
        if len(shown) > 2:
            page.click("#accept-boxes")
            saved(page)
            stored = json.loads((out / "labels" / f"{view.name}.json").read_text())
            assert all(o.get("proposed") is None for o in stored["objects"])
        assert page.inner_text("#proposed-note") == ""
        assert "proposed box" not in page.inner_text("#problems")
        assert page.failed == []
