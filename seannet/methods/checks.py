"""The checks every method's output passes: one line naming the method and the check."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import torch
from torch import Tensor

from seannet.data.batch import SceneBatch
from seannet.errors import MethodError
from seannet.methods.views import Views
from seannet.weights import IMAGE_SIZE

__all__ = ["checked_image_input", "checked_similarity", "checked_vectors", "embed_views", "guarded"]

_TOLERANCE = 1e-4  # how far past [-1, 1] a similarity may round
MAX_IMAGE_SIZE = 1024  # pixels a side: past this a CPU benchmark would not end


def guarded(name: str, what: str, call: Callable[..., Any], *args: Any) -> Any:
    """``call(*args)``, an exception inside the method becoming one line naming it (a
    :class:`MethodError` of the checks, e.g. a read of the pose, passes as it is)."""
    try:
        return call(*args)
    except Exception as exc:  # noqa: BLE001 - whatever a user's method raises
        if isinstance(exc, MethodError) and _names(exc, name):
            raise
        text = " ".join(_text(exc).split())[:200]
        raise MethodError(
            f"method {name!r}: {what} raised {type(exc).__name__}: {text} (check: no exception)"
        ) from None


def embed_views(name: str, method: Any, batch: SceneBatch) -> Any:
    """``method.embed`` of one batch as :class:`Views`, guarded; a method that read a hidden
    field (the pose) is refused even when it caught the error and carried on."""
    views = Views(batch, method=name)
    out = guarded(name, "embed", method.embed, views)
    if views.hidden_reads:
        raise MethodError(
            f"method {name!r} read views.{views.hidden_reads[0]} and carried on: a method "
            "never sees the pose (check: no pose)"
        )
    return out


def checked_image_input(name: str, method: Any) -> tuple[int, str]:
    """The method's ``image_size`` (default 224) and ``network`` (default ``"resnet"``, the
    normalisation family), checked: an integer side in [8, MAX_IMAGE_SIZE] and a string."""
    size, network = getattr(method, "image_size", IMAGE_SIZE), getattr(method, "network", "resnet")
    if isinstance(size, bool) or not isinstance(size, int) or not 8 <= size <= MAX_IMAGE_SIZE:
        raise MethodError(
            f"method {name!r}: image_size {size!r}; expected an integer side in pixels in "
            f"[8, {MAX_IMAGE_SIZE}] (check: image input)"
        )
    if not isinstance(network, str):
        raise MethodError(
            f"method {name!r}: network {network!r}; expected a name such as 'resnet' "
            "(check: image input)"
        )
    return size, network


def _names(exc: MethodError, name: str) -> bool:
    """Whether ``exc`` is one line of the checks about method ``name``."""
    text = _text(exc)
    return f"method {name!r}" in text and "(check: " in text and "\n" not in text


def _text(exc: BaseException) -> str:
    """``str(exc)``, or a note when the exception cannot say what it is."""
    try:
        return str(exc)
    except Exception:  # noqa: BLE001 - a user's exception whose __str__ fails
        return "(its message cannot be read)"


def _plain(out: Tensor) -> bool:
    """A dense tensor of real numbers (not sparse, not complex): what the checks can read."""
    return out.layout == torch.strided and not out.is_complex()


def checked_vectors(name: str, out: Any, n: int, width: int | None) -> Tensor:
    """``embed``'s output for ``n`` views, checked: a dense float tensor [n, D], D >= 1 (the
    ``width`` of the batches before when given), finite; detached, on the CPU."""
    if not isinstance(out, Tensor) or out.layout != torch.strided:
        kind = type(out).__name__ if not isinstance(out, Tensor) else f"a {out.layout} tensor"
        raise MethodError(
            f"method {name!r}: embed returned {kind}; expected a dense Tensor [N, D] (check: type)"
        )
    if (
        out.dim() != 2
        or out.shape[0] != n
        or out.shape[1] < 1
        or (width is not None and out.shape[1] != width)
    ):
        want = f"[{n}, {width if width is not None else 'D'}]"
        raise MethodError(
            f"method {name!r}: embed returned shape {list(out.shape)} for {n} views; expected "
            f"{want} (check: shape)"
        )
    if not out.is_floating_point():
        raise MethodError(
            f"method {name!r}: embed returned dtype {out.dtype}; expected a float tensor "
            "(check: dtype)"
        )
    if not bool(torch.isfinite(out).all()):
        raise MethodError(f"method {name!r}: embed returned NaN or inf (check: finite)")
    return out.detach().cpu()


def checked_similarity(name: str, similarity: Callable[..., Any], a: Tensor, b: Tensor) -> Tensor:
    """``similarity(a, b)`` of row pairs, checked: a float tensor [P], finite, in [-1, 1]."""
    s = guarded(name, "similarity", similarity, a, b)
    if not isinstance(s, Tensor) or not _plain(s) or tuple(s.shape) != (len(a),):
        shape = list(s.shape) if isinstance(s, Tensor) else type(s).__name__
        kind = f" {s.layout} {s.dtype}" if isinstance(s, Tensor) and not _plain(s) else ""
        raise MethodError(
            f"method {name!r}: similarity returned{kind} {shape} for {len(a)} pairs; "
            f"expected a dense real Tensor [{len(a)}] (check: similarity shape)"
        )
    s = s.detach().double().cpu()
    if not bool(torch.isfinite(s).all()):
        raise MethodError(f"method {name!r}: similarity returned NaN or inf (check: finite)")
    if float(s.abs().max()) > 1.0 + _TOLERANCE:
        raise MethodError(
            f"method {name!r}: similarity {float(s.abs().max()):.4g} outside [-1, 1], where "
            "epsilon and lambda assume a cosine (check: similarity range)"
        )
    return s
