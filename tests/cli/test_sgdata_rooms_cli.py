"""The sgdata command end to end, as a user runs it (the console script's entry point, in-process:
tests/cli_runner.py; the installed script itself runs in the labeling server's and the kill -9
tests)."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from ..cli_runner import Done, run_cli


def run(*args: str) -> Done:
    return run_cli("sgdata", *args)


def assert_one_line_error(result: Done, needle: str) -> None:
    assert result.returncode == 2, result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert needle in lines[0]
    assert "Traceback" not in result.stderr


def test_rooms_layouts_preview(tmp_path: Path) -> None:
    out = tmp_path / "scenes"
    result = run("rooms", str(out), "--type", "bedroom", "--count", "2", "--seed", "4")
    assert result.returncode == 0, result.stderr
    assert "bedroom_000" in result.stdout and "bedroom_001" in result.stdout
    room_dir = out / "bedroom_001"
    result = run("layouts", str(room_dir), "--count", "3", "--seed", "1")
    assert result.returncode == 0, result.stderr
    assert "% moved" in result.stdout
    assert sorted(p.name for p in room_dir.iterdir()) == [
        "layout_0.usda",
        "layout_1.usda",
        "layout_2.usda",
        "room.usda",
    ]
    png = tmp_path / "top.png"
    result = run("preview", str(room_dir / "layout_2.usda"), "--compare", "-o", str(png))
    assert result.returncode == 0, result.stderr
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (("rooms", "{tmp}/x", "--type", "garage"), "unknown room type 'garage'"),
        (("rooms", "{tmp}/x", "--count", "0"), "--count must be >= 1"),
        (("rooms", "{tmp}/a_file"), "is a file"),
        (("layouts", "{tmp}/nowhere"), "not a directory"),
        (("preview", "{tmp}/nothing.usda"), "nothing.usda"),
    ],
)
def test_bad_input_is_one_line_exit_2(tmp_path: Path, args: tuple[str, ...], needle: str) -> None:
    (tmp_path / "a_file").write_text("not a directory")
    result = run(*(a.format(tmp=tmp_path) for a in args))
    assert_one_line_error(result, needle)
    assert not (tmp_path / "x").exists()


def test_malformed_catalog(tmp_path: Path) -> None:
    catalog = tmp_path / "catalog.toml"
    shipped = (Path(__file__).parents[2] / "assets" / "catalog.toml").read_text()
    catalog.write_text(shipped.replace('dynamics = "high"', 'dynamics = "fast"', 1))
    result = run("rooms", str(tmp_path / "x"), "--catalog", str(catalog))
    assert_one_line_error(result, "field 'dynamics' is 'fast'")
    catalog.write_text("[classes.Mug\n")
    assert_one_line_error(
        run("rooms", str(tmp_path / "x"), "--catalog", str(catalog)), "not valid TOML"
    )
    assert not (tmp_path / "x").exists()


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (("generate", "huge", "{tmp}/d"), "expected one of tiny, small, medium, paper"),
        (("generate", "{tmp}/bad.toml", "{tmp}/d"), "unknown key 'roomz'"),
        (("generate", "tiny", "{tmp}/a_file"), "is a file"),
    ],
)
def test_generate_bad_input(tmp_path: Path, args: tuple[str, ...], needle: str) -> None:
    (tmp_path / "bad.toml").write_text("[roomz]\n")
    (tmp_path / "a_file").write_text("x")
    assert_one_line_error(run(*(a.format(tmp=tmp_path) for a in args)), needle)
    assert not (tmp_path / "d").exists()


def test_unwritable_output(tmp_path: Path) -> None:
    if os.geteuid() == 0:
        target = Path("/proc/sgdata-out")  # root ignores permission bits; /proc refuses mkdir
    else:
        locked = tmp_path / "locked"
        locked.mkdir(mode=0o500)
        target = locked / "out"
    result = run("rooms", str(target))
    assert_one_line_error(result, str(target))
