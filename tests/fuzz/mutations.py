"""Mutations people make to structured input, as hypothesis strategies shared by the surfaces."""

from __future__ import annotations

import copy
import json
import math
from typing import Any

from hypothesis import strategies as st

__all__ = ["NASTY_NUMBERS", "NASTY_TEXT", "json_values", "mutated", "paths_of", "to_toml"]

# numbers a hand-edited file holds by mistake: signs, zeros, overflow, NaN and inf, fractions
NASTY_NUMBERS = (
    -1, 0, 1, -0.5, 0.5, 1e-12, -1e308, 1e308, 2**63, -(2**63) - 1, 2**31, 1e20,
    math.nan, math.inf, -math.inf,
)  # fmt: skip
# names people type: unicode, URL-encoded, paths, blanks, control characters, very long
NASTY_TEXT = (
    "", " ", "Mug ", "mug", "MUG", "Müg", "杯子", "🍺", "coffee%20mug", "a%2Fb", "../../etc/x",
    "C:\\x", "a\x00b", "\u202emirror", "x" * 5000, "null", "NaN", "1e999", "-1", "[1]",
)  # fmt: skip

json_values = st.recursive(
    st.none()
    | st.booleans()
    | st.integers()
    | st.floats()
    | st.sampled_from(NASTY_NUMBERS)
    | st.text(max_size=8)
    | st.sampled_from(NASTY_TEXT),
    lambda inner: (
        st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=6), inner, max_size=3)
    ),
    max_leaves=6,
)


def paths_of(doc: Any, prefix: tuple = ()) -> list[tuple]:
    """Every path (keys and indices) to a value inside ``doc``, the root included."""
    out = [prefix]
    if isinstance(doc, dict):
        for k, v in doc.items():
            out += paths_of(v, (*prefix, k))
    elif isinstance(doc, list):
        for i, v in enumerate(doc):
            out += paths_of(v, (*prefix, i))
    return out


def _get(doc: Any, path: tuple) -> Any:
    for key in path:
        doc = doc[key]
    return doc


@st.composite
def mutated(draw: st.DrawFn, base: Any, *, most: int = 3) -> Any:
    """``base`` (JSON-like) with 0 to ``most`` mutations: a value removed, retyped, made extreme
    or nasty text, a list item duplicated (duplicate ids), an unknown key added."""
    doc = copy.deepcopy(base)
    ops = ["remove", "retype", "number", "text", "duplicate", "unknown"]
    for _ in range(draw(st.integers(0, most))):
        path = draw(st.sampled_from(paths_of(doc)))
        op = draw(st.sampled_from(ops))
        if not path:  # the root itself: only a retype reaches it
            doc = draw(json_values) if op == "retype" else doc
            continue
        parent, key = _get(doc, path[:-1]), path[-1]
        if op == "remove":
            del parent[key]
        elif op == "retype":
            parent[key] = draw(json_values)
        elif op == "number":
            parent[key] = draw(st.sampled_from(NASTY_NUMBERS) | st.integers() | st.floats())
        elif op == "text":
            parent[key] = draw(st.sampled_from(NASTY_TEXT) | st.text(max_size=12))
        elif op == "duplicate" and isinstance(parent, list):
            parent.append(copy.deepcopy(parent[key]))
        elif op == "unknown" and isinstance(parent, dict):
            parent[draw(st.sampled_from(["extra", "Id", "id ", "__proto__"]))] = draw(json_values)
    return doc


def to_toml(doc: dict) -> str:
    """TOML text of a JSON-like table: sub-tables as ``[sections]``, deeper ones inline; ``None``
    (which TOML lacks) becomes an empty inline table."""
    lines = [f"{_key(k)} = {_value(v)}" for k, v in doc.items() if not isinstance(v, dict)]
    for k, v in doc.items():
        if isinstance(v, dict):
            lines.append(f"[{_key(k)}]")
            lines += [f"{_key(kk)} = {_value(vv)}" for kk, vv in v.items()]
    return "\n".join(lines) + "\n"


def _key(key: Any) -> str:
    return json.dumps(str(key))


def _value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return (
            "nan" if math.isnan(v) else ("inf" if v > 0 else "-inf") if math.isinf(v) else repr(v)
        )
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, list):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{_key(k)} = {_value(x)}" for k, x in v.items()) + "}"
    return "{}"  # None
