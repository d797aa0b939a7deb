"""Names that moved still import from their old place for one release, with a warning."""

from __future__ import annotations

import importlib
import sys

import pytest

# (old module, old name, new module, new name)
MOVED = [
    ("sgdata.usd.own_rooms", "measure_stage", "sgdata.usd.user_rooms", "measure_stage"),
    ("sgdata.usd.own_layouts", "OwnFrame", "sgdata.usd.user_layouts", "UserFrame"),
    ("sgdata.usd.own_layouts", "own_frame", "sgdata.usd.user_layouts", "user_frame"),
    ("sgdata.usd.own_layouts", "override_own", "sgdata.usd.user_layouts", "override_user"),
    ("sgdata.seeds", "own_room_seed", "sgdata.seeds", "user_room_seed"),
    ("sgdata.dataset.rows", "sha256_file", "sgdata.fileio", "sha256_file"),
    ("sgdata.usd.stage", "write_text_atomic", "sgdata.usd.stage", "write_usd_file"),
    ("sgdata.dataset.manifest", "write_manifest", "sgdata.dataset.publish", "write_manifest"),
    ("sgdata.seeds", "init_seed", "seannet.seeds", "init_seed"),
    ("sgdata.usd.scene_dirs", "layout_path", "sgdata.usd.scene_dirs", "layout_stage_file"),
    ("sgdata.seeds", "episode_seed", "seannet.seeds", "episode_seed"),
]


@pytest.mark.parametrize(("old", "name", "new", "new_name"), MOVED)
def test_a_moved_name_imports_from_its_old_place_with_a_warning(
    old: str, name: str, new: str, new_name: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    if old != new:  # a shim module warns when imported: import it afresh, put back after
        # (a second copy of a real module left behind would give other tests twin classes)
        monkeypatch.delitem(sys.modules, old, raising=False)
    with pytest.warns(DeprecationWarning, match=new.replace(".", r"\.")):
        value = getattr(importlib.import_module(old), name)
    assert value is getattr(importlib.import_module(new), new_name)
