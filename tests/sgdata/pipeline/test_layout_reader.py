"""A room's layouts read one ahead on a background thread (sgdata.pipeline.layout_reader): what
reading them in turn gives, a bad layout raised for that layout, nothing read once it ends."""

from __future__ import annotations

import shutil
import threading
from pathlib import Path

import pytest

from sgdata.errors import UsdError
from sgdata.pipeline.layout_reader import LayoutReader, reading_pool
from sgdata.scene_files import layout_file
from sgdata.usd.layout_meshes import LayoutMeshes
from sgdata.usd.room_io import read_scene

from ..usd.test_layout_meshes import assert_same, room_dirs


def layouts(room_dir: Path) -> list[Path]:
    return [layout_file(room_dir, k) for k in range(len(list(room_dir.glob("layout_*.usda"))))]


def _reading_threads() -> int:
    return sum(t.name.startswith("sgdata-read") for t in threading.enumerate())


def test_the_reader_gives_what_reading_each_layout_in_turn_gives(mini_dataset: Path) -> None:
    before = _reading_threads()  # a worker's pool of an in-process run may be alive already
    pool = reading_pool()
    try:
        for room_dir in room_dirs(mini_dataset):
            paths = layouts(room_dir)
            assert len(paths) >= 2
            meshes = LayoutMeshes()
            with LayoutReader(paths, pool) as reader:
                for path in paths:
                    assert_same(reader.next(), read_scene(path, meshes), str(path))
                with pytest.raises(IndexError, match=f"all {len(paths)} layouts were read"):
                    reader.next()
        # the room after a room shares the worker's one thread
        assert _reading_threads() == before + 1
    finally:
        pool.shutdown(wait=True)


def test_a_bad_layout_fails_its_own_turn_and_the_one_before_still_reads(
    mini_dataset: Path, tmp_path: Path
) -> None:
    room_dir = Path(shutil.copytree(room_dirs(mini_dataset)[0], tmp_path / "room"))
    shutil.copytree(mini_dataset / "scenes" / "textures", tmp_path / "textures")
    paths = layouts(room_dir)
    paths[1].write_text("#usda 1.0\n(\n  this is not usd\n", encoding="utf-8")
    pool = reading_pool()
    try:
        with LayoutReader(paths, pool) as reader:
            room, _ = reader.next()  # layout 1 is read meanwhile, and fails
            assert room.objects
            with pytest.raises(UsdError, match="layout_1.usda"):
                reader.next()
    finally:
        pool.shutdown(wait=True)


def test_leaving_early_waits_for_the_read_in_flight(mini_dataset: Path) -> None:
    paths = layouts(room_dirs(mini_dataset)[0])
    pool = reading_pool()
    try:
        with pytest.raises(RuntimeError, match="render failed"), LayoutReader(paths, pool) as r:
            r.next()  # starts reading the second layout
            raise RuntimeError("render failed")
        assert r._pending is None
        # the worker's thread is idle: the next room's read starts at once
        assert pool.submit(lambda: 1).result(timeout=5) == 1
    finally:
        pool.shutdown(wait=True)
