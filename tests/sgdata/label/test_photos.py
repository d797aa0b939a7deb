"""The photos directory: every photo fully decoded at scan, oversized ones named, rescans."""

from __future__ import annotations

import struct
import zlib
from pathlib import Path

from fastapi.testclient import TestClient

from sgdata.label.photos import scan_photos
from sgdata.label.server import create_app

from .conftest import make_photo


def _big_png(path: Path, side: int) -> Path:
    """A valid 1-bit grey PNG of side x side pixels, written row by row (a few kB on disk)."""

    def chunk(kind: bytes, data: bytes) -> bytes:
        return (
            struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
        )

    row = b"\x00" + b"\xaa" * ((side + 7) // 8)  # filter 0, alternating pixels
    packer = zlib.compressobj(9)
    body = b"".join(packer.compress(row) for _ in range(side)) + packer.flush()
    header = struct.pack(">IIBBBBB", side, side, 1, 0, 0, 0, 0)
    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", body) + chunk(b"IEND", b"")
    path.write_bytes(png)
    return path


def test_a_truncated_jpeg_is_skipped_with_its_reason(tmp_path: Path) -> None:
    make_photo(tmp_path / "whole.jpg", 320, 240, seed=4)
    data = (tmp_path / "whole.jpg").read_bytes()
    (tmp_path / "cut.jpg").write_bytes(data[: len(data) * 2 // 3])
    index = scan_photos(tmp_path)
    assert list(index.photos) == ["whole.jpg"]
    ((name, why),) = index.skipped
    assert name == "cut.jpg" and why.startswith("cannot be decoded (image file is truncated")


def test_a_truncated_png_is_skipped_as_undecodable_not_as_not_an_image(tmp_path: Path) -> None:
    make_photo(tmp_path / "whole.png", 320, 240, seed=5)
    data = (tmp_path / "whole.png").read_bytes()
    (tmp_path / "cut.png").write_bytes(data[: len(data) * 2 // 3])
    ((name, why),) = scan_photos(tmp_path).skipped
    assert name == "cut.png" and why.startswith("cannot be decoded ("), why


def test_an_oversized_png_says_how_to_allow_it(tmp_path: Path) -> None:
    _big_png(tmp_path / "huge.png", 20000)
    ((_, why),) = scan_photos(tmp_path).skipped
    assert "20000x20000 = 400,000,000 pixels" in why and "--max-pixels 400000000" in why
    allowed = scan_photos(tmp_path, max_pixels=400_000_000)
    assert allowed.skipped == [] and allowed.photos["huge.png"].width == 20000


def test_photos_added_while_serving_are_listed(tmp_path: Path) -> None:
    photos = tmp_path / "photos"
    photos.mkdir()
    make_photo(photos / "a.png")
    client = TestClient(create_app(photos, tmp_path / "ds"), base_url="http://127.0.0.1")
    assert [p["name"] for p in client.get("/api/photos").json()["photos"]] == ["a.png"]
    make_photo(photos / "b.png", seed=2)
    assert [p["name"] for p in client.get("/api/photos").json()["photos"]] == ["a.png", "b.png"]
    assert client.get("/photos/b.png").status_code == 200
    (photos / "a.png").unlink()
    assert [p["name"] for p in client.get("/api/photos").json()["photos"]] == ["b.png"]
    assert client.get("/photos/a.png").status_code == 404
