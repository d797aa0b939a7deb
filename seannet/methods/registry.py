"""The method interface (:class:`Method`) and the one registry of methods: a decorator, an
import path ``package.module:factory`` (or ``path/file.py:factory``) and the entry-point group
``seannet.methods``; a model spec of :mod:`seannet.model.specs` names a bundled network."""

from __future__ import annotations

import hashlib
import importlib
import importlib.util
import sys
from collections.abc import Callable
from importlib.metadata import entry_points
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol, runtime_checkable

from torch import Tensor

from seannet.errors import MethodError, ModelError

if TYPE_CHECKING:
    from seannet.model.specs import ResolvedSpec

__all__ = [
    "ENTRY_POINT_GROUP",
    "Method",
    "load_method",
    "method_names",
    "method_source",
    "method_title",
    "register_method",
]

ENTRY_POINT_GROUP = "seannet.methods"
# The reference methods, by import path: the registry names them, the module that defines
# them never imports the registry (no circle, dynamic imports included)
REFERENCE = {
    "tiny-image": "seannet.methods.reference:TinyImage",
    "lite0-gem": "seannet.methods.reference:Lite0GeM",
    "lite0-gem-head": "seannet.methods.reference:Lite0GeMHead",
    "lite0-netvlad": "seannet.methods.reference:Lite0NetVLAD",
    "boxes-overlap": "seannet.methods.reference:BoxOverlap",
    "boxes-kernel": "seannet.methods.reference:BoxKernelMethod",
}
_REGISTERED: dict[str, Callable[[], Any]] = {}


@runtime_checkable
class Method(Protocol):
    """A localization method: views in, one vector per view out.

    Required:
        ``embed(views) -> Tensor[N, D]``: float vectors, finite, one row per view of the
        :class:`~seannet.methods.views.Views` batch (images, visible objects' boxes, classes,
        slots, relations; never the pose).

    Optional attributes and methods (the harness reads them with ``getattr``):
        ``similarity(a, b) -> Tensor[P]``: the similarity of the row pairs (a[k], b[k]), in
            [-1, 1] (default: cosine);
        ``fit(train, val, budget)``: train on :class:`~seannet.methods.views.SplitData`
            ``train``, make every choice on ``val``; called once per seed;
        ``uses_boxes`` (bool): the box-noise sweep applies;
        ``image_size`` (int, default 224) and ``network`` (a registry network whose input
            normalisation ``views.normalised`` uses; default ImageNet statistics);
        ``state_dict() -> dict`` and ``load_state_dict(state)`` (needed with ``fit``): the
            fitted state as tensors and plain data, and putting it back into a fresh object
            of the factory; a benchmark card directory keeps it (``method.pt``) and
            :func:`~seannet.methods.localizer.open_method` rebuilds the method from it.
    """

    def embed(self, views: Any) -> Tensor: ...


def register_method(name: str) -> Callable[[Callable[[], Any]], Callable[[], Any]]:
    """Decorator: register a factory (a class or a function of no arguments) under ``name``.

    Raises:
        MethodError: ``name`` is taken by another factory, or is a bundled model name.
    """
    from seannet.model.specs import MODEL_NAMES

    def decorate(factory: Callable[[], Any]) -> Callable[[], Any]:
        taken = name in MODEL_NAMES or name in REFERENCE
        if taken or (name in _REGISTERED and _REGISTERED[name] is not factory):
            raise MethodError(f"method {name!r}: the name is taken; register it under another")
        _REGISTERED[name] = factory
        return factory

    return decorate


def _entry_points() -> dict[str, Any]:
    return {ep.name: ep for ep in entry_points(group=ENTRY_POINT_GROUP)}


def method_names() -> list[str]:
    """Every method a name reaches: the registered ones, the entry points, the model names."""
    from seannet.model.specs import MODEL_NAMES

    named = [*REFERENCE, *_REGISTERED]
    return [*named, *(n for n in _entry_points() if n not in named), *MODEL_NAMES]


def _from_path(target: str) -> Callable[[], Any]:
    """The factory an import path names: ``package.module:factory`` or ``file.py:factory``."""
    where, _, attr = target.rpartition(":")
    if where.endswith(".py"):
        path = Path(where)
        if not path.is_file():
            raise MethodError(f"method {target!r}: no such file {path}")
        name = f"seannet_user_method_{path.stem}"
        spec = importlib.util.spec_from_file_location(name, path)
        assert spec is not None and spec.loader is not None
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        spec.loader.exec_module(module)
    else:
        module = importlib.import_module(where)
    factory = getattr(module, attr, None)
    if factory is None:
        raise MethodError(f"method {target!r}: {where} has no {attr!r}")
    return factory


def load_method(name: str) -> tuple[Callable[[], Any], ResolvedSpec | None]:
    """The factory of method ``name`` and, for a bundled network, its spec resolved (the one
    parse of it: the factory builds the network from it); None for any other method.

    ``name`` is, in this order: an import path (``pkg.mod:make`` or ``file.py:make``), a name
    registered with :func:`register_method` (the reference methods included), an entry point
    of the group ``seannet.methods``, or a model spec (``resnet18+boxes``, ``seannet@lite0``).

    Raises:
        MethodError: nothing of that name; the message lists what there is.
    """
    try:
        if ":" in name:
            return _from_path(name), None
        if name in REFERENCE:
            return _from_path(REFERENCE[name]), None
        if name in _REGISTERED:
            return _REGISTERED[name], None
        found = _entry_points()
        if name in found:
            return found[name].load(), None
    except MethodError:
        raise
    except Exception as exc:  # noqa: BLE001 - a user's module that fails to import
        raise MethodError(f"method {name!r}: loading failed: {type(exc).__name__}: {exc}") from None
    from seannet.model.specs import parse_spec

    try:
        spec = parse_spec(name)
    except ModelError:
        raise MethodError(
            f"method {name!r}: not registered, no entry point, no import path (pkg.mod:make) and "
            f"no model spec; registered: {', '.join([*REFERENCE, *_REGISTERED])}"
        ) from None
    from seannet.methods.bundled import NetworkMethod

    return (lambda: NetworkMethod(spec)), spec


def method_title(name: str, method: Any) -> str:
    """How a card and the leaderboard call method ``name``: one loaded by import path by its
    ``name`` attribute, else its class (not the path the user typed, which names a machine's
    folders); any other method by ``name``."""
    if ":" not in name:
        return name
    given = getattr(method, "name", None)
    return given if isinstance(given, str) and given else type(method).__name__


def method_source(name: str) -> dict[str, str] | None:
    """The file a method loaded by import path came from and its sha256 (which code made a
    card), or None for a registered, entry-point or bundled method (the commit names those)."""
    where, colon, _ = name.rpartition(":")
    if not colon:
        return None
    if where.endswith(".py"):
        path = Path(where)
    else:
        spec = importlib.util.find_spec(where)
        if spec is None or spec.origin is None:
            return None
        path = Path(spec.origin)
    return {"file": path.name, "sha256": hashlib.sha256(path.read_bytes()).hexdigest()}
