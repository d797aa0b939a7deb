"""Surface: a user's localization method, its outputs broken as methods break them, through the
checks the benchmark and the localizer run on every output (:mod:`seannet.methods.checks`).

A method's ``embed`` returns NaN or inf, the wrong number of rows, one dimension or three, a
width that changes between batches, integers, booleans, complex numbers, a sparse tensor, a
numpy array, a list or None; it raises (a message of many lines, one whose ``str`` raises, a
``MethodError`` of its own), or reads the pose (``views.pose``, ``getattr``, ``hasattr``).
Its ``similarity`` returns values just or far outside [-1, 1], the wrong shape, NaN, complex or
sparse values, or raises. Each ends in one :class:`~seannet.errors.MethodError` line naming the
method and the check, or passes when the outputs are valid (an oracle written here, apart from
the checks, says which); never a traceback. The checks are called directly, as the benchmark
calls them, so an example costs a few small tensors, not a benchmark.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

from hypothesis import strategies as st

from seannet.errors import MethodError, SeannetError  # no torch: the fuzz suite loads it late

from .harness import Surface

if TYPE_CHECKING:
    import torch

    from seannet.data.batch import SceneBatch
    from seannet.methods.views import Views

OUTPUTS = (
    *["valid"] * 16, "nan", "inf", "-inf", "rows+1", "rows-1", "1d", "3d", "0d",
    "transposed", "int", "bool", "complex", "sparse", "numpy", "list", "none", "grad",
    "strided", "width0", "width+1",
)  # fmt: skip
SIMILARITIES = (
    *[None] * 6, *["valid"] * 6, "scaled", "nan", "inf", "rows+1", "2d", "0d", "int", "bool",
    "complex", "sparse", "numpy", "list", "none", "raises",
)  # fmt: skip
DTYPES = ("float32", "float64", "float16", "bfloat16")  # torch's names
SCALES = (*[1.0] * 8, 1e-30, 1e-45, 1e5, 1e30, 1e39, 1e300)
FACTORS = (1.0, 1.00001, 1.001, 2.0, -3.0, 0.0)
RAISES = (*[None] * 24, "KeyError", "ValueError", "AssertionError", "lines", "bad str",
          "long", "MethodError", "SeannetError", "RecursionError")  # fmt: skip
PEEKS = (*[None] * 14, "attribute", "getattr", "hasattr", "unknown field", "set field")
NAMES = ("fuzz-method", "path/with space/m.py:Make", "pkg.mod:make", "ünï-côdé")

methods = st.fixed_dictionaries(
    {
        "name": st.sampled_from(NAMES),
        "views": st.integers(1, 5),
        "width": st.integers(1, 6),
        "output": st.sampled_from(OUTPUTS),
        "second": st.sampled_from((*["valid"] * 12, "width+1", "nan", "rows+1")),
        "dtype": st.sampled_from(DTYPES),
        "scale": st.sampled_from(SCALES),
        "similarity": st.sampled_from(SIMILARITIES),
        "factor": st.sampled_from(FACTORS),
        "raises": st.sampled_from(RAISES),
        "raises_in": st.sampled_from(("embed", "similarity")),
        "peek": st.sampled_from(PEEKS),
        "field": st.integers(0, 63),  # which of the views' hidden fields (HIDDEN_FIELDS)
    }
)


class _BadStr(Exception):
    def __str__(self) -> str:
        raise RuntimeError("str() of this exception fails too")


def _raise(kind: str) -> None:
    if kind == "KeyError":
        raise KeyError("no such feature")
    if kind == "ValueError":
        raise ValueError("operands could not be broadcast together")
    if kind == "AssertionError":
        raise AssertionError("the method's own assert")
    if kind == "lines":
        raise RuntimeError("CUDA out of memory.\nTried to allocate 2.00 GiB\n\nSee the docs")
    if kind == "bad str":
        raise _BadStr()
    if kind == "long":
        raise ValueError("x" * 100_000)
    if kind == "MethodError":  # a method raising the project's error without the details
        raise MethodError("something\nwent wrong")
    if kind == "SeannetError":
        raise SeannetError("a seannet call inside the method failed")
    if kind == "RecursionError":
        raise RecursionError("maximum recursion depth exceeded")


def _batch(n: int, m: int = 4) -> SceneBatch:
    import torch

    from seannet.data.batch import SceneBatch

    return SceneBatch(
        images=torch.arange(n * 3 * 8 * 8, dtype=torch.int64).reshape(n, 3, 8, 8).to(torch.uint8),
        boxes=torch.tensor([[0.0, 0.0, 4.0, 4.0]]),
        box_view=torch.tensor([n - 1]),
        class_ids=torch.tensor([0]),
        slots=torch.tensor([2]),
        adjacency=torch.zeros(n, 3, m, m),
        mean=(0.5, 0.5, 0.5),
        std=(0.5, 0.5, 0.5),
    )


def _output(kind: str, n: int, width: int, dtype: str, scale: float) -> Any:
    """What ``embed`` returns for ``n`` views: ``kind`` of an (n, width) matrix."""
    import torch

    rows = {"rows+1": n + 1, "rows-1": n - 1}.get(kind, n)
    cols = {"width0": 0, "width+1": width + 1}.get(kind, width)
    x = (torch.linspace(-1.0, 1.0, rows * cols, dtype=torch.float64) * scale).reshape(rows, cols)
    x = x.to(getattr(torch, dtype))
    if kind in ("nan", "inf", "-inf") and x.numel():
        x[-1, -1] = {"nan": torch.nan, "inf": torch.inf, "-inf": -torch.inf}[kind]
    changed = {
        "1d": lambda: x.flatten(),
        "3d": lambda: x[..., None],
        "0d": lambda: x.sum(),
        "transposed": lambda: x.t(),
        "int": lambda: (x.double() * 10).clamp(-1e9, 1e9).long(),
        "bool": lambda: x > 0,
        "complex": lambda: x.to(torch.complex64),
        "sparse": lambda: x.to_sparse(),
        "numpy": lambda: x.float().numpy(),
        "list": lambda: x.tolist(),
        "none": lambda: None,
        "grad": lambda: x.float().requires_grad_(),
        "strided": lambda: torch.stack([x, x], dim=2)[..., 0],
    }
    return changed[kind]() if kind in changed else x


def _similarity(kind: str, a: torch.Tensor, b: torch.Tensor, factor: float) -> Any:
    import torch
    import torch.nn.functional as F

    s = F.cosine_similarity(a.double(), b.double(), dim=1)
    changed = {
        "scaled": lambda: s * factor,
        "nan": lambda: torch.where(torch.arange(len(s)) == 0, torch.nan, s),
        "inf": lambda: s + torch.inf,
        "rows+1": lambda: torch.cat([s, s[:1]]),
        "2d": lambda: s[:, None],
        "0d": lambda: s.sum(),
        "int": lambda: s.round().long(),
        "bool": lambda: s > 0,
        "complex": lambda: s.to(torch.complex128),
        "sparse": lambda: s.to_sparse(),
        "numpy": lambda: s.numpy(),
        "list": lambda: s.tolist(),
        "none": lambda: None,
    }
    return changed[kind]() if kind in changed else s


def _peek(views: Views, how: str | None, field: int) -> None:
    from seannet.methods.views import HIDDEN_FIELDS

    fields = sorted(HIDDEN_FIELDS)
    name = fields[field % len(fields)]
    if how == "attribute":
        getattr(views, name)
    elif how == "getattr":
        getattr(views, name, None)
    elif how == "hasattr":
        hasattr(views, name)
    elif how == "unknown field":
        views.colour_histogram  # type: ignore[attr-defined]  # noqa: B018
    elif how == "set field":
        views.images = None  # type: ignore[misc]


class _Method:
    """A user's method that breaks the way ``example`` says."""

    def __init__(self, example: dict[str, Any]) -> None:
        self.example, self.calls = example, 0
        if example["similarity"] is not None:
            self.similarity = self._similarity

    def embed(self, views: Views) -> Any:
        e = self.example
        self.calls += 1
        _peek(views, e["peek"], e["field"])
        if e["raises"] and e["raises_in"] == "embed":
            _raise(e["raises"])
        kind = e["output"] if self.calls == 1 else e["second"]
        return _output(kind, len(views), e["width"], e["dtype"], e["scale"])

    def _similarity(self, a: torch.Tensor, b: torch.Tensor) -> Any:
        e = self.example
        if e["similarity"] == "raises" or (e["raises"] and e["raises_in"] == "similarity"):
            _raise(e["raises"] or "ValueError")
        return _similarity(e["similarity"], a, b, e["factor"])


# ---------------------------------------------------------------- the oracle, apart from checks
def _valid_vectors(out: Any, n: int, width: int | None) -> bool:
    """An (n, D) real float tensor, D >= 1 (``width`` when a batch set it), every value finite."""
    import torch

    if not isinstance(out, torch.Tensor) or out.layout != torch.strided:
        return False
    if out.dim() != 2 or out.shape[0] != n or out.shape[1] < 1:
        return False
    if width is not None and out.shape[1] != width:
        return False
    if not out.dtype.is_floating_point:
        return False
    return bool(torch.isfinite(out.detach()).all())


def _valid_similarity(s: Any, pairs: int) -> bool:
    """A (pairs,) real tensor, finite, within [-1, 1] up to rounding."""
    import torch

    if not isinstance(s, torch.Tensor) or s.layout != torch.strided or s.is_complex():
        return False
    if tuple(s.shape) != (pairs,):
        return False
    values = s.detach().double()
    return bool(torch.isfinite(values).all()) and float(values.abs().max()) <= 1.0 + 1e-4


def _expected(example: dict[str, Any]) -> bool:
    """Whether the checks must pass ``example``'s method (its outputs made once more here)."""
    n = example["views"]
    if example["peek"] in ("attribute", "getattr", "hasattr", "unknown field", "set field"):
        return False
    if example["raises"] and (example["raises_in"] == "embed" or example["similarity"]):
        return False
    first = _output(example["output"], n, example["width"], example["dtype"], example["scale"])
    if not _valid_vectors(first, n, None):
        return False
    second = _output(example["second"], n, example["width"], example["dtype"], example["scale"])
    if not _valid_vectors(second, n, first.shape[1]):
        return False
    if example["similarity"] in (None, "raises"):
        return example["similarity"] is None
    a, b = first.detach(), second.detach().flip(0)
    return _valid_similarity(_similarity(example["similarity"], a, b, example["factor"]), n)


def feed(example: dict[str, Any], work: Path, session: None) -> None:
    from seannet.methods.checks import checked_similarity, checked_vectors, guarded
    from seannet.methods.views import Views

    name, n = example["name"], example["views"]
    method = _Method(example)
    expected = _expected(example)
    try:
        width = None
        batches = []
        for _ in range(2):  # two batches: the second must keep the first's width
            views = Views(_batch(n), method=name)
            out = guarded(name, "embed", method.embed, views)
            batches.append(checked_vectors(name, out, n, width))
            width = batches[-1].shape[1]
        similarity = getattr(method, "similarity", None)
        if similarity is not None:
            checked_similarity(name, similarity, batches[0], batches[1].flip(0))
    except MethodError as exc:
        text = str(exc)
        assert f"method {name!r}" in text and "(check: " in text, (
            f"refusal without the method or the check: {text[:200]}"
        )
        assert not expected, f"valid method refused: {text[:200]}"
        raise
    assert expected, "broken method passed the checks: " + repr(example)[:200]
    for out in batches:
        assert out.device.type == "cpu" and not out.requires_grad, (
            "checked vectors still on a device or in the graph: " + name
        )


SURFACE = Surface(
    name="localization methods (checks)",
    inputs=methods,
    feed=feed,
    refusals=(MethodError,),
)
