"""Files on disk: one atomic-write protocol, a file's SHA-256, TOML read into one-line errors."""

from __future__ import annotations

import hashlib
import os
import stat
from pathlib import Path

import pytest

from sgdata.errors import CatalogError, ConfigError
from sgdata.fileio import (
    atomic_file,
    atomic_write_text,
    parse_toml,
    process_umask,
    read_toml,
    sha256_file,
)


def test_atomic_file_renames_on_success_and_leaves_nothing_on_failure(tmp_path: Path) -> None:
    target = tmp_path / "sub" / "out.bin"
    with atomic_file(target) as tmp:
        assert tmp.parent == target.parent and tmp.name.startswith(".out.bin.")
        tmp.write_bytes(b"new")
    assert target.read_bytes() == b"new"
    with pytest.raises(RuntimeError), atomic_file(target) as tmp:
        tmp.write_bytes(b"half")
        raise RuntimeError("killed")
    assert target.read_bytes() == b"new" and os.listdir(target.parent) == ["out.bin"]


@pytest.mark.parametrize("mask", [0o022, 0o077, 0o002])
def test_written_files_take_the_mode_the_umask_gives(tmp_path: Path, mask: int) -> None:
    """Not mkstemp's private 0600: another user, a container's uid or a web server reads a
    dataset as a plain ``open`` would have let it."""
    old = os.umask(mask)
    try:
        assert process_umask() == mask
        atomic_write_text(tmp_path / "out.txt", "x")
    finally:
        os.umask(old)
    assert stat.S_IMODE((tmp_path / "out.txt").stat().st_mode) == 0o666 & ~mask


def test_a_generated_dataset_is_readable_as_the_umask_says(mini_dataset: Path) -> None:
    modes = {stat.S_IMODE(p.stat().st_mode) for p in mini_dataset.rglob("*") if p.is_file()}
    assert modes == {0o666 & ~process_umask()}  # tables, images, USD, manifest and card alike


def test_sha256_file_gives_digest_and_size(tmp_path: Path) -> None:
    path = tmp_path / "a.txt"
    atomic_write_text(path, "héllo")
    data = "héllo".encode()
    assert sha256_file(path) == (hashlib.sha256(data).hexdigest(), len(data))


def test_read_toml_maps_every_failure_to_one_line(tmp_path: Path) -> None:
    good = tmp_path / "good.toml"
    good.write_text('a = 1\n[b]\nc = "d"\n')
    assert read_toml(good, "class file") == {"a": 1, "b": {"c": "d"}}
    with pytest.raises(ConfigError, match=r"missing\.toml: class file not found$"):
        read_toml(tmp_path / "missing.toml", "class file")
    bad = tmp_path / "bad.toml"
    bad.write_text("a = = 1\n")
    with pytest.raises(CatalogError, match=r"bad\.toml: not valid TOML \(.*line 1") as info:
        read_toml(bad, "catalog file", error=CatalogError)
    assert "\n" not in str(info.value)
    latin = tmp_path / "latin.toml"
    latin.write_bytes('a = "\xe9"\n'.encode("latin-1"))
    with pytest.raises(ConfigError, match="cannot read the class map"):
        read_toml(latin, "class map")
    with pytest.raises(ConfigError, match="^tiny: not valid TOML"):
        parse_toml("[x", "tiny")
