"""The label store: one JSON file per photo under ``<out>/labels/``, written atomically.

Every save replaces ``labels/<photo>.json`` through a temporary file and a rename, so a killed
server leaves the previous or the new labels, never half a file. Each file carries a
``revision`` that every save increments; a save based on an older revision (another tab saved
in between) is refused with :class:`ConflictError` instead of silently overwriting.
"""

from __future__ import annotations

import json
import threading
from pathlib import Path

from pydantic import ValidationError

from sgdata.errors import DatasetError, SgdataError
from sgdata.fileio import atomic_write_text, prepare_output_dir, remove_stale_temps
from sgdata.label.models import PhotoLabels

__all__ = ["CLASS_MAP_COPY", "LABELS_DIR", "ConflictError", "LabelStore"]

LABELS_DIR = "labels"  # under the output directory; not a dataset output (export leaves it)
CLASS_MAP_COPY = "classes.toml"  # in LABELS_DIR: the last --classes given, used when none is


class ConflictError(SgdataError):
    """A save was based on an older revision than the one on disk."""

    def __init__(self, photo: str, revision: int) -> None:
        super().__init__(
            f"{photo}: changed elsewhere (revision {revision} on disk); reload to see those labels"
        )
        self.revision = revision


class LabelStore:
    """Per-photo labels under ``root / labels``; safe for the threads of one server."""

    def __init__(self, root: Path) -> None:
        self.root = prepare_output_dir(Path(root))
        self.dir = self.root / LABELS_DIR
        self.dir.mkdir(exist_ok=True)
        remove_stale_temps(self.dir)  # what a killed save may have left
        self._lock = threading.Lock()

    def path(self, photo: str) -> Path:
        """The label file of a photo name (a name the photo index knows: no path parts)."""
        if not photo or "/" in photo or "\\" in photo or photo.startswith("."):
            raise DatasetError(f"photo name {photo!r}: expected a plain file name")
        return self.dir / f"{photo}.json"

    def load(self, photo: str) -> PhotoLabels:
        """The saved labels of ``photo`` (empty labels at revision 0 when none were saved).

        Raises:
            DatasetError: the file exists but is not valid labels.
        """
        path = self.path(photo)
        try:
            text = path.read_text(encoding="utf-8")
        except FileNotFoundError:
            return PhotoLabels()
        try:
            return PhotoLabels.model_validate_json(text)
        except ValidationError as exc:
            raise DatasetError(f"{path}: not valid labels ({exc.error_count()} problems)") from None

    def save(self, photo: str, labels: PhotoLabels) -> PhotoLabels:
        """Store ``labels`` as the next revision of ``photo``; returns what was stored.

        Raises:
            ConflictError: ``labels.revision`` is not the revision on disk.
        """
        with self._lock:
            current = self.load(photo).revision
            if labels.revision != current:
                raise ConflictError(photo, current)
            stored = labels.model_copy(update={"revision": current + 1})
            text = json.dumps(stored.model_dump(mode="json"), indent=1, ensure_ascii=False)
            atomic_write_text(self.path(photo), text + "\n")
            return stored

    def class_map(self, given: Path | None) -> Path | None:
        """The class map to use: ``given`` (remembered for later runs), else the remembered one.

        The labels name mapped classes, so labeling and exporting must use the same map; a copy
        kept beside the labels means ``--classes`` is given once.
        """
        from sgdata.label.classes import load_class_names

        kept = self.dir / CLASS_MAP_COPY
        if given is None:
            return kept if kept.is_file() else None
        load_class_names(given)  # a bad map is an error here, and is not remembered
        atomic_write_text(kept, Path(given).read_text(encoding="utf-8"))
        return given

    def labeled(self) -> dict[str, PhotoLabels]:
        """Every saved photo's labels, by photo name."""
        out = {}
        for path in sorted(self.dir.glob("*.json")):
            name = path.name[: -len(".json")]
            out[name] = self.load(name)
        return out
