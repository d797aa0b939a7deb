"""The photos directory: which files are PNG/JPEG photos to label, and safe access to them.

Only regular files directly in the directory are photos; a name is looked up in the scanned
index, never joined onto a path, so ``../``, encoded traversal, absolute paths and symlinks
that lead outside the directory cannot reach anything else. Every photo is fully decoded when
it is scanned, so a truncated or corrupt file is skipped with its real reason before anyone
labels it; a rescan decodes only the files that changed.
"""

from __future__ import annotations

import contextlib
import io
import threading
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from PIL import Image, ImageOps, UnidentifiedImageError

from sgdata.errors import ConfigError

__all__ = [
    "DEFAULT_MAX_PIXELS",
    "Photo",
    "PhotoIndex",
    "photo_bytes",
    "scan_photos",
    "shown_pixels",
]

# Pillow format -> the dataset's image_format.
FORMATS = {"PNG": "png", "JPEG": "jpeg"}
MAX_SIDE = 32767  # camera.width / height and box2d are int16 in the schema
_EXIF_ORIENTATION = 0x0112
# Pillow's own decompression-bomb limit (a 16-bit-side photo of 178 MP); --max-pixels raises it.
DEFAULT_MAX_PIXELS = 2 * 89_478_485
# Pillow's guard is a process global; this module checks the size itself and lifts Pillow's
# guard only while it holds this lock.
_PILLOW_GUARD = threading.Lock()


@dataclass(frozen=True)
class Photo:
    """One photo to label; sizes are as displayed (after the EXIF orientation)."""

    name: str  # file name inside the photos directory
    path: Path  # resolved path, inside the directory
    format: str  # png | jpeg
    width: int
    height: int
    transposed: bool  # the EXIF orientation rotates or mirrors the stored pixels
    stamp: tuple[int, int] = (0, 0)  # (mtime_ns, size) when scanned: a rescan skips it if equal


@dataclass(frozen=True)
class PhotoIndex:
    """The photos of a directory, by name and in sorted order, and what was skipped."""

    root: Path
    photos: dict[str, Photo]
    skipped: list[tuple[str, str]] = field(default_factory=list)  # (name, why)
    max_pixels: int = DEFAULT_MAX_PIXELS
    # name -> (stamp, Photo or why skipped): what a rescan reuses for unchanged files
    seen: dict[str, tuple[tuple[int, int], Photo | str]] = field(default_factory=dict)

    def get(self, name: str) -> Photo | None:
        """The photo called ``name``, re-checked to lie inside the root; None otherwise."""
        photo = self.photos.get(name)
        if photo is None:
            return None
        try:
            resolved = photo.path.resolve(strict=True)
        except OSError:
            return None
        return photo if resolved.parent == self.root and resolved.is_file() else None


def scan_photos(
    root: Path, *, max_pixels: int = DEFAULT_MAX_PIXELS, previous: PhotoIndex | None = None
) -> PhotoIndex:
    """Index the PNG and JPEG photos directly in ``root``; anything else is listed as skipped.

    Args:
        max_pixels: larger photos are skipped (a guard against decompression bombs).
        previous: an earlier scan of ``root``; files unchanged since are not decoded again.

    Raises:
        ConfigError: ``root`` does not exist or is not a directory, or ``max_pixels`` < 1.
    """
    root = Path(root)
    if not root.is_dir():
        what = "is not a directory" if root.exists() else "does not exist"
        raise ConfigError(f"{root}: {what}; expected a directory of PNG or JPEG photos")
    if max_pixels < 1:
        raise ConfigError(f"--max-pixels {max_pixels}: expected a positive pixel count")
    base = root.resolve()
    old = previous.seen if previous is not None and previous.max_pixels == max_pixels else {}
    photos, skipped, seen = {}, [], {}
    for entry in sorted(base.iterdir(), key=lambda p: p.name):
        if entry.name.startswith("."):
            continue
        why = _why_not(base, entry)
        if why is None:
            stat = entry.stat()
            stamp = (stat.st_mtime_ns, stat.st_size)
            cached = old.get(entry.name)
            found = cached[1] if cached and cached[0] == stamp else _read(entry, stamp, max_pixels)
            seen[entry.name] = (stamp, found)
            if isinstance(found, str):
                why = found
            else:
                photos[entry.name] = found
        if why is not None:
            skipped.append((entry.name, why))
    return PhotoIndex(base, photos, skipped, max_pixels, seen)


@contextlib.contextmanager
def _own_size_check() -> Iterator[None]:
    with _PILLOW_GUARD:
        saved = Image.MAX_IMAGE_PIXELS
        Image.MAX_IMAGE_PIXELS = None
        try:
            yield
        finally:
            Image.MAX_IMAGE_PIXELS = saved


def _why_not(base: Path, entry: Path) -> str | None:
    try:
        resolved = entry.resolve(strict=True)
    except OSError:
        return "a broken link"
    if resolved.parent != base:
        return "a link to outside the photos directory"
    if not resolved.is_file():
        return "not a file"
    return None


def _read(path: Path, stamp: tuple[int, int], max_pixels: int) -> Photo | str:
    try:
        with _own_size_check(), Image.open(path) as image:
            fmt = FORMATS.get(image.format or "")
            if fmt is None:
                return f"a {image.format} image; expected PNG or JPEG"
            width, height = image.size
            if width * height > max_pixels:
                return (
                    f"{width}x{height} = {width * height:,} pixels, over the {max_pixels:,} "
                    f"allowed (a guard against decompression bombs); to label it, start "
                    f"`sgdata label` with --max-pixels {width * height}"
                )
            try:
                image.load()  # decode every pixel now: a truncated file fails here, not later
                # after load: a PNG's EXIF chunk may sit after its pixels, so reading it decodes
                orientation = image.getexif().get(_EXIF_ORIENTATION, 1)
            except (OSError, ValueError, SyntaxError) as exc:
                return f"cannot be decoded ({exc}); re-copy or re-export the photo"
    except (UnidentifiedImageError, OSError, ValueError):
        return "not an image"
    transposed = orientation in (5, 6, 7, 8)
    if transposed:
        width, height = height, width
    if max(width, height) > MAX_SIDE:
        return f"{width}x{height} pixels; the dataset stores at most {MAX_SIDE} a side"
    transformed = orientation not in (1, None)
    return Photo(path.name, path.resolve(), fmt, width, height, transformed, stamp)


def photo_bytes(photo: Photo) -> tuple[bytes, str]:
    """The bytes to store for ``photo`` and their format.

    The file's own bytes when they are plain RGB as displayed; otherwise (an EXIF rotation,
    alpha, palette, grey or 16-bit pixels) the pixels as shown, re-encoded as RGB PNG.
    """
    data = photo.path.read_bytes()
    with _own_size_check(), Image.open(io.BytesIO(data)) as image:
        if image.mode == "RGB" and not photo.transposed:
            return data, photo.format
        shown = ImageOps.exif_transpose(image).convert("RGB")
    buffer = io.BytesIO()
    shown.save(buffer, format="PNG", optimize=False, compress_level=6)
    return buffer.getvalue(), "png"


def shown_pixels(photo: Photo) -> np.ndarray:
    """The photo's pixels as the page shows them: (height, width, 3) uint8 RGB, the EXIF
    orientation applied (what a detector proposing boxes on it must see)."""
    with _own_size_check(), Image.open(photo.path) as image:
        return np.asarray(ImageOps.exif_transpose(image).convert("RGB"))
