"""A method as a localizer: what maps, ``seannet map`` / ``localize`` / ``navigate`` call to
embed views and score them, with every output checked (the same checks as the benchmark).

A method reaches them three ways (:func:`open_method`):

- by **name** (``tiny-image``, ``path/file.py:Make``, an entry point): a method with no
  ``fit``; its threshold epsilon is given (``--epsilon``);
- by a **method directory**: ``method.json`` (its name, the epsilon chosen on val and the
  dataset it was fit on) and, for a trained method, ``method.pt``: ``{"format": 2, "state":
  method.state_dict()}``, tensors and plain data only (``torch.load(weights_only=True)``
  opens it). Opening one builds the method with its factory (the name in ``method.json``)
  and hands it ``load_state_dict(state)``, so nothing of the method's class is pickled and a
  fresh interpreter opens it. ``seannet benchmark`` writes one into every card directory, so
  a card directory names any benchmarked method, the trained ones included
  (:func:`save_method`);
- a trained run directory (``best.pt``) is a bundled method too: :mod:`seannet.navigation`
  opens it as before.

A localizer's vectors are what the method's similarity reads (unit rows for cosine; the
boxes too for a method that scores them), so a map holds what the method needs.
"""

from __future__ import annotations

import hashlib
import io
import json
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import torch
import torch.nn.functional as F

from seannet.data.collate import ViewTensors, collate_views
from seannet.data.opening import DataSource, dataset_identity, open_dataset
from seannet.data.view_inputs import ImageTransform
from seannet.errors import MethodError
from seannet.methods.checks import (
    checked_image_input,
    checked_similarity,
    checked_vectors,
    embed_views,
    guarded,
)
from seannet.methods.registry import load_method
from seannet.training.runs import MODEL_KEYS
from sgdata.fileio import atomic_write_bytes, atomic_write_text

__all__ = [
    "METHOD_FILE",
    "STATE_FILE",
    "STATE_FORMAT",
    "MethodLocalizer",
    "open_method",
    "save_method",
]

BATCH = 16  # views per embed() call
METHOD_FILE = "method.json"  # name, epsilon and its source, dataset identity, trained
STATE_FILE = "method.pt"  # a fitted method's state: {"format": STATE_FORMAT, "state": ...}
# 2: the method's state_dict(), tensors and plain data (1, the pickled method, never released)
STATE_FORMAT = 2
_PLAIN = (str, int, float, bool, type(None))  # what a state holds besides tensors


class MethodLocalizer:
    """Views in, checked vectors out; ``score`` is the method's similarity (default cosine).

    Built from a method name (:func:`~seannet.methods.registry.load_method`; a trained method
    must be fit first: pass the fitted object as ``method``). ``epsilon`` is the threshold a
    benchmark card chose on val (``card["summary"]["epsilon"]``), NaN when unknown.

    The navigation side reads ``name``, ``source`` (what names it: the method's name or its
    directory), ``digest`` (maps record it), ``identity`` (the dataset), ``epsilon``,
    ``epsilon_source``, ``transform``, :meth:`embed` and :meth:`similarities`.
    """

    def __init__(
        self,
        name: str,
        method: Any | None = None,
        *,
        epsilon: float = math.nan,
        epsilon_source: str = "none",
        identity: dict[str, Any] | None = None,
        source: str | None = None,
        digest: str | None = None,
    ) -> None:
        self.name = name
        self.method = method if method is not None else guarded(name, "its factory",
                                                                load_method(name)[0])  # fmt: skip
        self.epsilon = epsilon
        self.epsilon_source = epsilon_source
        self.identity = identity or {}
        self.source = source or name
        self.digest = digest or _name_digest(name)
        self._similarity = getattr(self.method, "similarity", None)

    @property
    def transform(self) -> ImageTransform:
        """The image transform the method reads views with (its size and normalisation)."""
        return ImageTransform.for_model(*checked_image_input(self.name, self.method))

    def embed(self, views: Sequence[ViewTensors]) -> np.ndarray:
        """(N, D) float32 vectors of views (made with :attr:`transform`), checked."""
        parts = []
        for start in range(0, len(views), BATCH):
            batch, _ = collate_views(list(views[start : start + BATCH]))
            with torch.no_grad():
                out = embed_views(self.name, self.method, batch)
            width = parts[0].shape[1] if parts else None
            parts.append(checked_vectors(self.name, out, batch.num_views, width))
        if not parts:
            return np.zeros((0, 0), dtype=np.float32)
        vectors = torch.cat(parts)
        if self._similarity is None:
            vectors = F.normalize(vectors.float(), dim=1)  # cosine: unit rows, dot products
        return vectors.float().numpy()  # float32 (bfloat16 has no numpy type)

    def score(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """(P,) similarity of the row pairs (a[k], b[k]) of :meth:`embed`'s vectors."""
        # a map's rows are read-only (torch warns on those): copied only where needed
        ta, tb = (torch.from_numpy(np.require(x, requirements=["C", "W"])) for x in (a, b))
        if self._similarity is None:
            return (ta * tb).sum(1).double().numpy()
        with torch.no_grad():
            return checked_similarity(self.name, self._similarity, ta, tb).numpy()

    def similarities(self, vector: np.ndarray, rows: np.ndarray) -> np.ndarray:
        """(N,) similarity of one vector of :meth:`embed` to each of ``rows`` (a map's)."""
        if self._similarity is None:
            return rows @ vector
        return self.score(np.broadcast_to(vector, rows.shape), rows)


def _name_digest(name: str) -> str:
    """What an unfitted method's maps are keyed by: its name and, for a file, its bytes."""
    digest = hashlib.sha256(name.encode())
    where, colon, _ = name.rpartition(":")
    if colon and where.endswith(".py") and Path(where).is_file():
        digest.update(Path(where).read_bytes())
    return digest.hexdigest()


def save_method(
    directory: Path,
    name: str,
    method: Any,
    *,
    epsilon: float,
    epsilon_source: str,
    data: DataSource,
) -> Path:
    """Write ``method.json`` (and, for a method with ``fit``, ``method.pt``: its
    ``state_dict()``) into ``directory``, so that :func:`open_method` gives the same localizer
    back, in this interpreter or a fresh one.

    Raises:
        MethodError: a trained method without ``state_dict`` / ``load_state_dict``, or whose
            state holds something other than tensors and plain data (nothing is written).
    """
    trained = callable(getattr(method, "fit", None))
    if trained:
        atomic_write_bytes(directory / STATE_FILE, _state_bytes(name, method))
    record = {
        "method": 1,
        "name": name,
        "trained": trained,
        "epsilon": epsilon,
        "epsilon_source": epsilon_source,
        "dataset": dataset_identity(data),
    }
    atomic_write_text(directory / METHOD_FILE, json.dumps(record, indent=1))
    return directory / METHOD_FILE


def _state_bytes(name: str, method: Any) -> bytes:
    """``method.pt``'s bytes: the format and the method's ``state_dict()``, checked plain."""
    missing = [
        m for m in ("state_dict", "load_state_dict") if not callable(getattr(method, m, None))
    ]
    if missing:
        raise MethodError(
            f"method {name!r} is trained (it has fit) but has no {' / '.join(missing)}: add "
            "state_dict() -> a dict of tensors and plain data, and load_state_dict(state) that "
            "puts it back into the method its factory builds (docs/benchmark.md) (check: state)"
        )
    state = guarded(name, "state_dict", method.state_dict)
    if not isinstance(state, dict):
        raise MethodError(
            f"method {name!r}: state_dict returned {type(state).__name__}; expected a dict "
            "(check: state)"
        )
    bad = _not_plain(state, "state")
    if bad is not None:
        where, value = bad
        raise MethodError(
            f"method {name!r}: {where} is a {type(value).__name__}; a state holds tensors, "
            "str, int, float, bool, None, and lists, tuples and dicts (str or int keys) of them "
            "(check: state)"
        )
    buffer = io.BytesIO()
    torch.save({"format": STATE_FORMAT, "state": state}, buffer)
    return buffer.getvalue()


def _not_plain(value: Any, where: str) -> tuple[str, Any] | None:
    """The first place in ``value`` that is not a tensor or plain data, and what is there."""
    if isinstance(value, (torch.Tensor, *_PLAIN)):
        return None
    if isinstance(value, dict):
        for key, item in value.items():
            if not isinstance(key, str | int):
                return f"{where} key {key!r}", key
            found = _not_plain(item, f"{where}[{key!r}]")
            if found is not None:
                return found
        return None
    if isinstance(value, list | tuple):
        for k, item in enumerate(value):
            found = _not_plain(item, f"{where}[{k}]")
            if found is not None:
                return found
        return None
    return where, value


def _read_record(path: Path) -> dict[str, Any]:
    try:
        record = json.loads(path.read_text())
    except (OSError, ValueError) as exc:
        raise MethodError(f"{path}: not a method record ({exc})") from None
    if not isinstance(record, dict) or not isinstance(record.get("name"), str):
        raise MethodError(f"{path}: no method name in it; write it again with seannet benchmark")
    return record


def open_method(
    target: str | Path,
    data: DataSource,
    *,
    epsilon: float | None = None,
    source: str = "--epsilon",
    require_epsilon: bool = True,
) -> MethodLocalizer:
    """The localizer ``target`` names on ``data``: a method directory (``method.json``) or a
    method name of :func:`~seannet.methods.registry.load_method`.

    Args:
        epsilon: the threshold to use; None: the directory's (a name has none).
        source: where a given ``epsilon`` comes from (reported beside it).
        require_epsilon: without one, raise (True) or leave epsilon NaN (building maps).

    Raises:
        MethodError: no such method; a trained method named without its directory; a
            directory fit on another dataset's vocabulary; no epsilon when one is required.
    """
    directory = Path(target)
    ds = open_dataset(data)
    identity = dataset_identity(ds)
    if (directory / METHOD_FILE).is_file():
        record = _read_record(directory / METHOD_FILE)
        name = record["name"]
        factory, _ = load_method(name)  # the method's module; its factory rebuilds it
        state = directory / STATE_FILE
        if record.get("trained"):
            if not state.is_file():
                raise MethodError(f"{directory}: {STATE_FILE} is missing; benchmark it again")
            fitted = record.get("dataset", {})
            if any(fitted.get(k) != identity.get(k) for k in MODEL_KEYS):
                raise MethodError(
                    f"{directory}: method {name!r} was fit on another dataset's vocabulary "
                    f"than {ds.root}'s"
                )
            blob = state.read_bytes()
            method = _restore(name, factory, blob, state)
            digest = hashlib.sha256(blob).hexdigest()
        else:
            method, digest = guarded(name, "its factory", factory), _name_digest(name)
        if epsilon is None:
            found = record.get("epsilon")
            if isinstance(found, int | float) and math.isfinite(found):
                epsilon, source = float(found), f"{directory / METHOD_FILE}"
        where = str(directory.resolve())
    else:
        name = str(target)
        factory, _ = load_method(name)
        method = guarded(name, "its factory", factory)
        if callable(getattr(method, "fit", None)):
            raise MethodError(
                f"method {name!r} is trained (it has fit): run `seannet benchmark --methods "
                f"{name}` and give its card directory instead"
            )
        digest, where = _name_digest(name), name
    if epsilon is None:
        if require_epsilon:
            raise MethodError(
                f"method {name!r}: no epsilon; pass --epsilon or give its card directory"
            )
        epsilon, source = math.nan, "none"
    if require_epsilon and not math.isfinite(epsilon):
        raise MethodError(f"epsilon {epsilon}: expected a finite number")
    return MethodLocalizer(
        name, method, epsilon=float(epsilon), epsilon_source=source, identity=identity,
        source=where, digest=digest,
    )  # fmt: skip


def _restore(name: str, factory: Any, blob: bytes, path: Path) -> Any:
    """The fitted method ``method.pt``'s bytes hold: the factory's method, its state loaded.

    Raises:
        MethodError: not a method state; the method has no ``load_state_dict``, or it raised.
    """
    try:
        saved = torch.load(io.BytesIO(blob), map_location="cpu", weights_only=True)
    except Exception as exc:  # noqa: BLE001 - torch raises many types for a damaged file
        raise MethodError(
            f"{path}: unreadable method state ({type(exc).__name__}); benchmark it again"
        ) from None
    if not isinstance(saved, dict) or saved.get("format") != STATE_FORMAT or "state" not in saved:
        raise MethodError(
            f"{path}: not a method state of format {STATE_FORMAT}; benchmark it again"
        )
    method = guarded(name, "its factory", factory)
    load = getattr(method, "load_state_dict", None)
    if not callable(load):
        raise MethodError(
            f"method {name!r} has no load_state_dict(state) to take {path} back; add it "
            "(docs/benchmark.md) (check: state)"
        )
    guarded(name, "load_state_dict", load, saved["state"])
    return method
