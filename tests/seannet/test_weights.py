"""The image networks' facts (seannet.weights) against the datasets they read."""

from __future__ import annotations

from seannet.weights import IMAGE_SIZE
from sgdata.render.camera import VIEW_SIZE, CameraConfig


def test_a_default_view_is_the_networks_input_size() -> None:
    # two homes on two sides of the layering (sgdata renders, seannet reads): held equal here
    assert VIEW_SIZE == IMAGE_SIZE
    assert (CameraConfig().width, CameraConfig().height) == (IMAGE_SIZE, IMAGE_SIZE)
