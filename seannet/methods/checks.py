"""The checks every method's output passes: one line naming the method and the check."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import torch
from torch import Tensor

from seannet.errors import MethodError

__all__ = ["checked_similarity", "checked_vectors", "guarded"]

_TOLERANCE = 1e-4  # how far past [-1, 1] a similarity may round


def guarded(name: str, what: str, call: Callable[..., Any], *args: Any) -> Any:
    """``call(*args)``, an exception inside the method becoming one line naming it."""
    try:
        return call(*args)
    except MethodError:
        raise
    except Exception as exc:  # noqa: BLE001 - whatever a user's method raises
        text = " ".join(str(exc).split())[:200]
        raise MethodError(
            f"method {name!r}: {what} raised {type(exc).__name__}: {text} (check: no exception)"
        ) from None


def checked_vectors(name: str, out: Any, n: int, width: int | None) -> Tensor:
    if not isinstance(out, Tensor):
        raise MethodError(
            f"method {name!r}: embed returned {type(out).__name__}; expected a Tensor [N, D] "
            "(check: type)"
        )
    if out.dim() != 2 or out.shape[0] != n or (width is not None and out.shape[1] != width):
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
    if not isinstance(s, Tensor) or tuple(s.shape) != (len(a),):
        shape = list(s.shape) if isinstance(s, Tensor) else type(s).__name__
        raise MethodError(
            f"method {name!r}: similarity returned {shape} for {len(a)} pairs; "
            f"expected a Tensor [{len(a)}] (check: similarity shape)"
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
