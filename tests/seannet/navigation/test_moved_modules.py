"""The navigation modules renamed on 2026-12-02 still import from their old paths, with a
DeprecationWarning, for one release."""

from __future__ import annotations

import importlib
import sys

import pytest

MOVED = {
    "seannet.navigation.navigate": "seannet.navigation.benchmark",
    "seannet.navigation.localize": "seannet.navigation.map_localization",
    "seannet.navigation.train_navigator": "seannet.navigation.navigator_training",
}


@pytest.mark.parametrize("old", sorted(MOVED))
def test_old_path_warns_and_gives_the_same_names(old: str, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delitem(sys.modules, old, raising=False)  # import afresh, put back after
    with pytest.warns(DeprecationWarning, match=MOVED[old]):
        module = importlib.import_module(old)
    new = importlib.import_module(MOVED[old])
    assert module.__all__ == new.__all__
    for name in new.__all__:
        assert getattr(module, name) is getattr(new, name)
