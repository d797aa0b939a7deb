"""Files on disk: atomic writes (nothing half-written is ever left behind), output-directory
checks, a file's SHA-256, and TOML files read into one-line errors.

One protocol writes every file of the project: a temporary file beside the target
(``.<name>.<random>.tmp``, :data:`TEMP_GLOB`), flushed to disk, then renamed over the target
(:func:`atomic_file`); a failure removes the temporary file and leaves the target as it was.
The file gets the mode a plain ``open`` would give it (0666 less the umask: 0644 under 022),
not the temporary file's private 0600, so other users and servers read what they may.
"""

from __future__ import annotations

import hashlib
import io
import os
import tempfile
import tomllib
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Any

from sgdata.errors import ConfigError, SgdataError, one_line

if TYPE_CHECKING:
    from PIL import Image

__all__ = [
    "TEMP_GLOB",
    "atomic_file",
    "atomic_write_bytes",
    "atomic_write_text",
    "parse_toml",
    "prepare_output_dir",
    "read_toml",
    "remove_stale_temps",
    "save_png",
    "sha256_file",
]

# Temporary files of atomic writes: ".<name>.<random>.tmp" beside the target.
TEMP_GLOB = ".*.tmp"
_HASH_CHUNK = 1 << 20  # bytes read at a time when hashing a file


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


def process_umask() -> int:
    """This process's umask: read from ``/proc/self/status`` (Linux), else set and restored."""
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("Umask:"):
                return int(line.split()[1], 8)
    except (OSError, ValueError):
        pass
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


@contextmanager
def atomic_file(path: Path) -> Iterator[Path]:
    """A temporary path beside ``path`` to write; on a clean exit it is synced to disk and
    renamed over ``path``, on any error removed (``path`` untouched).

    Raises:
        OSError: the directory cannot be created or written (callers map it to their error).
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, name = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    os.close(fd)
    tmp = Path(name)
    try:
        yield tmp
        os.chmod(tmp, 0o666 & ~process_umask())  # mkstemp's 0600 is for the temporary only
        fd = os.open(tmp, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)


def atomic_write_bytes(path: Path, data: bytes) -> None:
    """Write ``data`` to ``path`` atomically (:func:`atomic_file`)."""
    with atomic_file(path) as tmp:
        tmp.write_bytes(data)


def atomic_write_text(path: Path, text: str) -> None:
    """Write UTF-8 ``text`` to ``path`` atomically (:func:`atomic_file`)."""
    atomic_write_bytes(path, text.encode("utf-8"))


def save_png(image: Image.Image, path: Path) -> None:
    """Write a PIL image as PNG atomically."""
    buffer = io.BytesIO()
    image.save(buffer, format="PNG")
    atomic_write_bytes(path, buffer.getvalue())


def remove_stale_temps(root: Path) -> int:
    """Delete temporary files a killed writer left under ``root``; returns how many."""
    stale = [p for p in root.rglob(TEMP_GLOB) if p.is_file()]
    for path in stale:
        path.unlink(missing_ok=True)
    return len(stale)


def sha256_file(path: Path) -> tuple[str, int]:
    """(sha256 hex digest, size in bytes) of a file, read in chunks."""
    digest, size = hashlib.sha256(), 0
    with open(path, "rb") as handle:
        while chunk := handle.read(_HASH_CHUNK):
            digest.update(chunk)
            size += len(chunk)
    return digest.hexdigest(), size


def read_toml(path: Path, what: str, *, error: type[SgdataError] = ConfigError) -> dict[str, Any]:
    """The top-level table of the TOML file ``path``; ``what`` names the file in messages
    (``"class file"``: "class file not found", "cannot read the class file").

    Raises:
        ``error``: the file is missing, unreadable, not UTF-8 or not valid TOML.
    """
    try:
        text = Path(path).read_text(encoding="utf-8")
    except FileNotFoundError:
        raise error(f"{path}: {what} not found") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise error(f"{path}: cannot read the {what} ({one_line(exc)})") from None
    return parse_toml(text, str(path), error=error)


def parse_toml(text: str, where: str, *, error: type[SgdataError] = ConfigError) -> dict[str, Any]:
    """The table of TOML ``text`` read from ``where`` (a file or a preset's name).

    Raises:
        ``error``: ``text`` is not valid TOML (the message names ``where``, line and column).
    """
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise error(f"{where}: not valid TOML ({one_line(exc)})") from None
