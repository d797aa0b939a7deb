"""Object prims of a stage: which prims are objects, and their instance ids (authored or assigned).

A prim is an object when it carries ``sgdata:class`` or ``sgdata:instance``. Objects without an
authored ``sgdata:instance`` get ids assigned in prim path order (sorted path strings), starting
above the largest authored id, so the same stage always gets the same ids.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

from pxr import Usd, UsdGeom

from sgdata.errors import UsdError

__all__ = ["is_object", "drawn", "drawn_prims", "object_prims", "instance_ids"]


def is_object(prim: Usd.Prim) -> bool:
    """True for an object prim (it carries ``sgdata:class`` or ``sgdata:instance``)."""
    return prim.HasAttribute("sgdata:class") or prim.HasAttribute("sgdata:instance")


def drawn(prim: Usd.Prim) -> bool:
    """False for invisible prims and guide / proxy purposes (their subtrees are not drawn)."""
    if not prim.IsA(UsdGeom.Imageable):
        return True
    imageable = UsdGeom.Imageable(prim)
    if imageable.GetVisibilityAttr().Get() == UsdGeom.Tokens.invisible:
        return False
    return imageable.GetPurposeAttr().Get() not in (UsdGeom.Tokens.guide, UsdGeom.Tokens.proxy)


def drawn_prims(stage: Usd.Stage) -> Iterator[Usd.Prim]:
    """Every drawn prim of a composed stage in traversal order (hidden subtrees pruned,
    instance proxies followed)."""
    prims = iter(Usd.PrimRange.Stage(stage, Usd.TraverseInstanceProxies()))
    for prim in prims:
        if not drawn(prim):
            prims.PruneChildren()  # type: ignore[attr-defined]
            continue
        yield prim


def object_prims(stage: Usd.Stage) -> list[Usd.Prim]:
    """The drawn object prims of a composed stage, in traversal order."""
    return [prim for prim in drawn_prims(stage) if is_object(prim)]


def instance_ids(path: Path, prims: list[Usd.Prim]) -> dict[str, int]:
    """Prim path -> instance id: the authored ``sgdata:instance``, else assigned by path order.

    Raises:
        UsdError: an authored id is not an integer, or two prims share one.
    """
    ids: dict[str, int] = {}
    seen: dict[int, str] = {}
    missing = []
    for prim in prims:
        key = str(prim.GetPath())
        attr = prim.GetAttribute("sgdata:instance")
        value = attr.Get() if attr else None
        if value is None:
            missing.append(key)
            continue
        if not isinstance(value, int) or isinstance(value, bool):
            raise UsdError(f"{path}: {key} sgdata:instance is {value!r}; expected an integer")
        if value in seen:
            raise UsdError(f"{path}: {key} and {seen[value]} share sgdata:instance {value}")
        seen[value] = key
        ids[key] = value
    nxt = max(seen, default=0) + 1
    for key in sorted(missing):
        ids[key] = nxt
        nxt += 1
    return ids
