"""Metadata checks: the dataset card's front matter and ``croissant.json`` agree with the
manifest (both are written from it, so each is compared with what the manifest writes again)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from sgdata.dataset.card import front_matter, read_front_matter
from sgdata.dataset.croissant import croissant_dict
from sgdata.dataset.manifest import META_SINCE, Manifest
from sgdata.dataset.paths import CARD, CROISSANT, MANIFEST
from sgdata.dataset.schema import parse_version
from sgdata.errors import DatasetError
from sgdata.validate.problems import Collector

__all__ = ["check_metadata"]

CARD_CHECK = "metadata.card"
CROISSANT_CHECK = "metadata.croissant"


def _first_difference(found: str, wanted: str) -> tuple[int, str, str]:
    """(1-based line, found line, wanted line) of the first line that differs."""
    a, b = found.split("\n"), wanted.split("\n")
    for k in range(max(len(a), len(b))):
        x = a[k] if k < len(a) else "<end of front matter>"
        y = b[k] if k < len(b) else "<end of front matter>"
        if x != y:
            return k + 1, x.strip(), y.strip()
    return 0, "", ""


def _check_card(root: Path, manifest: Manifest, out: Collector) -> None:
    out.count(CARD_CHECK)
    path = root / CARD
    if not path.is_file():
        out.add(CARD_CHECK, CARD, "missing; write it again: sgdata migrate ROOT")
        return
    try:
        found = read_front_matter(path)
    except DatasetError as exc:
        out.add(CARD_CHECK, CARD, str(exc).split(": ", 1)[-1])
        return
    wanted = front_matter(manifest)
    if found != wanted:
        line, have, want = _first_difference(found, wanted)
        out.add(
            CARD_CHECK,
            CARD,
            f"front matter line {line} is {have!r}; {MANIFEST} gives {want!r}",
            field=f"front matter line {line}",
        )


def _differences(found: Any, wanted: Any, where: str) -> list[str]:
    """Key paths where two JSON values differ (lists by position, ``@id``s named)."""
    if isinstance(found, dict) and isinstance(wanted, dict):
        out = []
        for key in sorted(set(found) | set(wanted)):
            out += _differences(found.get(key), wanted.get(key), f"{where}.{key}")
        return out
    if isinstance(found, list) and isinstance(wanted, list) and len(found) == len(wanted):
        out = []
        for k, (a, b) in enumerate(zip(found, wanted, strict=True)):
            name = b.get("@id", k) if isinstance(b, dict) else k
            out += _differences(a, b, f"{where}[{name}]")
        return out
    return [] if found == wanted else [where.lstrip(".")]


def _check_croissant(root: Path, manifest: Manifest, out: Collector) -> None:
    out.count(CROISSANT_CHECK)
    path = root / CROISSANT
    if not path.is_file():
        out.add(CROISSANT_CHECK, CROISSANT, "missing; write it again: sgdata migrate ROOT")
        return
    try:
        found = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        out.add(CROISSANT_CHECK, CROISSANT, f"not readable JSON ({exc})")
        return
    for where in _differences(found, croissant_dict(manifest), ""):
        out.add(CROISSANT_CHECK, CROISSANT, f"differs from what {MANIFEST} gives", field=where)


def check_metadata(root: Path, raw: dict[str, Any], out: Collector) -> None:
    """The card's front matter and ``croissant.json`` against the manifest (format 2.0.0 on;
    an older dataset has neither, and these checks are skipped)."""
    if parse_version(raw["format_version"]) < parse_version(META_SINCE):
        out.skipped.extend([CARD_CHECK, CROISSANT_CHECK])
        return
    try:
        manifest = Manifest.from_dict(raw)
    except DatasetError:
        return  # reported by the manifest checks
    _check_card(root, manifest, out)
    _check_croissant(root, manifest, out)
