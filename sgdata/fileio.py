"""Atomic file writes and output-directory checks: nothing half-written is ever left behind."""

from __future__ import annotations

import io
import os
import tempfile
from pathlib import Path

from PIL import Image

from sgdata.errors import ConfigError

__all__ = [
    "TEMP_GLOB",
    "atomic_write_bytes",
    "atomic_write_text",
    "prepare_output_dir",
    "remove_stale_temps",
    "save_png",
]

# Temporary files of atomic writes: ".<name>.<random>.tmp" beside the target.
TEMP_GLOB = ".*.tmp"


def prepare_output_dir(path: Path) -> Path:
    """Create ``path`` as a directory if needed and check it is writable.

    Raises:
        ConfigError: ``path`` is an existing file, or cannot be created or written.
    """
    if path.exists() and not path.is_dir():
        raise ConfigError(f"{path}: is a file; expected a directory to write into")
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ConfigError(f"{path}: cannot create the output directory ({exc.strerror})") from None
    if not os.access(path, os.W_OK | os.X_OK):
        raise ConfigError(f"{path}: output directory is not writable")
    return path


def atomic_write_bytes(path: Path, data: bytes) -> None:
    """Write ``data`` to ``path`` through a temporary file in the same directory + rename."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as handle:
            handle.write(data)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def remove_stale_temps(root: Path) -> int:
    """Delete temporary files a killed writer left under ``root``; returns how many."""
    stale = [p for p in root.rglob(TEMP_GLOB) if p.is_file()]
    for path in stale:
        path.unlink(missing_ok=True)
    return len(stale)


def atomic_write_text(path: Path, text: str) -> None:
    """Write UTF-8 ``text`` atomically."""
    atomic_write_bytes(path, text.encode("utf-8"))


def save_png(image: Image.Image, path: Path) -> None:
    """Write a PIL image as PNG atomically (temp file + rename)."""
    buffer = io.BytesIO()
    image.save(buffer, format="PNG")
    atomic_write_bytes(path, buffer.getvalue())
