"""Foreign annotations as plain data: photos, boxes and relations read from a file, unmapped."""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath
from typing import Any
from urllib.parse import parse_qs, unquote, urlparse

from sgdata.errors import SgdataError

__all__ = [
    "AnnotationFormatError",
    "ForeignBox",
    "ForeignPhoto",
    "ForeignRelation",
    "FieldReader",
    "read_json",
    "image_name",
]


class AnnotationFormatError(SgdataError):
    """An annotation file is not what its format promises (names the file and the field)."""


@dataclass(frozen=True)
class ForeignBox:
    """One rectangle as the file gives it: pixel box [u1, v1, u2, v2] and the file's label."""

    id: int  # object id in the photo's labels
    label: str  # the file's class name ("" when none)
    box: tuple[int, int, int, int]
    where: str  # where in the file, for messages


@dataclass(frozen=True)
class ForeignRelation:
    """One relation as the file gives it, already oriented (``bi`` is kept as symmetric)."""

    src: int
    dst: int
    label: str  # the file's relation label ("" when none)
    symmetric: bool  # Label Studio ``direction = "bi"``
    where: str


@dataclass
class ForeignPhoto:
    """The annotations of one photo, before class and relation names are mapped."""

    name: str  # the photo's file name (no directories)
    width: int | None  # the size the file says the photo has (None: not given)
    height: int | None
    where: str
    boxes: list[ForeignBox] = field(default_factory=list)
    relations: list[ForeignRelation] = field(default_factory=list)
    room_id: str | None = None  # carried by an sgdata Label Studio export
    room_type: str | None = None
    pose: dict[str, int] | None = None  # {layout, i, j, heading}


def read_json(path: Path) -> Any:
    """The parsed JSON of an annotation file.

    Raises:
        AnnotationFormatError: missing, unreadable or not JSON.
    """
    try:
        text = Path(path).read_text(encoding="utf-8")
    except FileNotFoundError:
        raise AnnotationFormatError(f"{path}: no such annotation file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise AnnotationFormatError(f"{path}: cannot read it ({exc})") from None
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise AnnotationFormatError(
            f"{path}: not JSON (line {exc.lineno}, column {exc.colno}: {exc.msg})"
        ) from None
    except ValueError as exc:  # an integer of more digits than Python converts (4,300)
        raise AnnotationFormatError(
            f"{path}: a number too long to read ({str(exc).split(':')[0]})"
        ) from None
    except RecursionError:
        raise AnnotationFormatError(
            f"{path}: not JSON this reader takes (nested too deeply)"
        ) from None


def _finite_number(value: Any) -> bool:
    """A JSON number a float holds: not a bool, not NaN or infinite, and not an integer
    beyond a float's range (JSON allows any number of digits)."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        return False
    try:
        return math.isfinite(value)
    except OverflowError:  # an int too large to convert to float
        return False


# what a stored id, size or pose index fits in (Parquet's int64): JSON allows any number of digits
_INT64 = (-(2**63), 2**63 - 1)


class FieldReader:
    """Typed access to the fields of one file's JSON, with one-line errors naming the field."""

    def __init__(self, path: Path) -> None:
        self.path = path

    def fail(self, where: str, expected: str) -> AnnotationFormatError:
        """The error for a bad field ``where``."""
        return AnnotationFormatError(f"{self.path}: {where}: expected {expected}")

    def obj(self, value: Any, where: str) -> dict:
        if not isinstance(value, dict):
            raise self.fail(where, "an object")
        return value

    def items(self, value: Any, where: str) -> list:
        if not isinstance(value, list):
            raise self.fail(where, "a list")
        return value

    def get(self, parent: dict, key: str, where: str, kind: str, *, default: Any = ...) -> Any:
        """``parent[key]`` checked to be a ``kind``: str | int | number | list | object."""
        if key not in parent or parent[key] is None:
            if default is not ...:
                return default
            raise self.fail(f"{where}.{key}", f"a {kind} (it is missing)")
        value = parent[key]
        ok = {
            "str": isinstance(value, str),
            "int": isinstance(value, int) and not isinstance(value, bool),
            "number": _finite_number(value),
            "list": isinstance(value, list),
            "object": isinstance(value, dict),
        }[kind]
        if not ok:
            raise self.fail(f"{where}.{key}", f"a {kind}, not {value!r:.40}")
        if kind == "int" and not _INT64[0] <= value <= _INT64[1]:
            raise self.fail(f"{where}.{key}", f"an integer within int64, not {value!r:.40}")
        return value

    def size(
        self, parent: dict, where: str, keys: tuple[str, str]
    ) -> tuple[int | None, int | None]:
        """An optional positive (width, height) pair under ``keys``."""
        out = []
        for key in keys:
            value = self.get(parent, key, where, "int", default=None)
            if value is not None and value <= 0:
                raise self.fail(f"{where}.{key}", f"a positive size, not {value}")
            out.append(value)
        return out[0], out[1]

    def box(
        self,
        u1: float,
        v1: float,
        u2: float,
        v2: float,
        size: tuple[int | None, int | None],
        where: str,
    ) -> tuple[int, int, int, int]:
        """A pixel box from float edges: rounded, clipped to the photo, non-empty."""
        width, height = size
        if not all(math.isfinite(x) for x in (u1, v1, u2, v2)):
            raise self.fail(where, f"finite box edges, not {[u1, v1, u2, v2]}")
        edges = [round(u1), round(v1), round(u2), round(v2)]
        lo = [0, 0, 0, 0]
        hi = [width, height, width, height]
        for k in range(4):
            edges[k] = max(lo[k], edges[k])
            if hi[k] is not None:
                edges[k] = min(hi[k], edges[k])
        if not (edges[0] < edges[2] and edges[1] < edges[3]):
            raise self.fail(where, f"a box of at least one pixel, not {[u1, v1, u2, v2]}")
        return edges[0], edges[1], edges[2], edges[3]


def image_name(reference: str) -> str:
    """The photo file name an annotation's image reference points at.

    Directories are dropped (``train/0001.jpg``, ``../images/a.png``); a URL gives its path's
    last part, or the ``d`` query of Label Studio's ``/data/local-files/?d=...`` links.
    """
    parsed = urlparse(reference)
    path = parsed.path
    if parsed.query:
        local = parse_qs(parsed.query).get("d")
        if local:
            path = local[0]
    path = unquote(path).replace("\\", "/")
    return PurePosixPath(path).name
