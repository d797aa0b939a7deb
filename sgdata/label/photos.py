"""The photos directory: which files are PNG/JPEG photos to label, and safe access to them.

Only regular files directly in the directory are photos; a name is looked up in the scanned
index, never joined onto a path, so ``../``, encoded traversal, absolute paths and symlinks
that lead outside the directory cannot reach anything else.
"""

from __future__ import annotations

import io
from dataclasses import dataclass, field
from pathlib import Path

from PIL import Image, ImageOps, UnidentifiedImageError

from sgdata.errors import ConfigError

__all__ = ["Photo", "PhotoIndex", "scan_photos", "photo_bytes"]

# Pillow format -> the dataset's image_format.
FORMATS = {"PNG": "png", "JPEG": "jpeg"}
MAX_SIDE = 32767  # camera.width / height and box2d are int16 in the schema
_EXIF_ORIENTATION = 0x0112


@dataclass(frozen=True)
class Photo:
    """One photo to label; sizes are as displayed (after the EXIF orientation)."""

    name: str  # file name inside the photos directory
    path: Path  # resolved path, inside the directory
    format: str  # png | jpeg
    width: int
    height: int
    transposed: bool  # the EXIF orientation rotates or mirrors the stored pixels


@dataclass(frozen=True)
class PhotoIndex:
    """The photos of a directory, by name and in sorted order, and what was skipped."""

    root: Path
    photos: dict[str, Photo]
    skipped: list[tuple[str, str]] = field(default_factory=list)  # (name, why)

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


def scan_photos(root: Path) -> PhotoIndex:
    """Index the PNG and JPEG photos directly in ``root``; anything else is listed as skipped.

    Raises:
        ConfigError: ``root`` does not exist or is not a directory.
    """
    root = Path(root)
    if not root.is_dir():
        what = "is not a directory" if root.exists() else "does not exist"
        raise ConfigError(f"{root}: {what}; expected a directory of PNG or JPEG photos")
    base = root.resolve()
    photos, skipped = {}, []
    for entry in sorted(base.iterdir(), key=lambda p: p.name):
        if entry.name.startswith("."):
            continue
        why = _why_not(base, entry)
        if why is None:
            photo = _read(entry)
            if isinstance(photo, str):
                why = photo
            else:
                photos[entry.name] = photo
        if why is not None:
            skipped.append((entry.name, why))
    return PhotoIndex(base, photos, skipped)


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


def _read(path: Path) -> Photo | str:
    try:
        with Image.open(path) as image:
            fmt = FORMATS.get(image.format or "")
            if fmt is None:
                return f"a {image.format} image; expected PNG or JPEG"
            width, height = image.size
            orientation = image.getexif().get(_EXIF_ORIENTATION, 1)
    except (UnidentifiedImageError, OSError, ValueError, Image.DecompressionBombError):
        return "not an image"
    transposed = orientation in (5, 6, 7, 8)
    if transposed:
        width, height = height, width
    if max(width, height) > MAX_SIDE:
        return f"{width}x{height} pixels; the dataset stores at most {MAX_SIDE} a side"
    return Photo(path.name, path.resolve(), fmt, width, height, orientation not in (1, None))


def photo_bytes(photo: Photo) -> tuple[bytes, str]:
    """The bytes to store for ``photo`` and their format.

    The file's own bytes when they are plain RGB as displayed; otherwise (an EXIF rotation,
    alpha, palette, grey or 16-bit pixels) the pixels as shown, re-encoded as RGB PNG.
    """
    data = photo.path.read_bytes()
    with Image.open(io.BytesIO(data)) as image:
        if image.mode == "RGB" and not photo.transposed:
            return data, photo.format
        shown = ImageOps.exif_transpose(image).convert("RGB")
    buffer = io.BytesIO()
    shown.save(buffer, format="PNG", optimize=False, compress_level=6)
    return buffer.getvalue(), "png"
