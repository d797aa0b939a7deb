"""The meshes of a room kept across its layouts: a layout re-reads only what its layer changes.

A layout stage is a layout layer (the stage's root layer) over the room's layers. Most prims'
triangles, colours and materials come from the room's layers alone, identical in every
layout; only the prims the layout layer overrides differ (moved objects change their
transforms, which are read per layout anyway; re-dressed ones their colours and bindings).
:class:`LayoutMeshes` keeps what :func:`sgdata.usd.geometry.stage_geometry` read for each prim
the layout layer leaves alone, so the next layout of the same room reads only the prims its
layer touches.

A prim is *left alone* by the root layer when no spec of the root layer composes into it or
into any prim below it (a part's binding), through any arc (a reference, an inherit), nor
into an ancestor other than a spec that only moves it (its properties all ``xformOp*`` or
``sgdata:*``, no metadata beyond its specifier). When the layer overrides a prim of the room
that is not geometry (a material, a shader, a class, an untyped prim), nothing is reused for
that layout: what such a prim feeds (a binding's material) is not in the prims' own specs.
"""

from __future__ import annotations

from pxr import Sdf, Usd

from sgdata.usd.meshes import MeshData

__all__ = ["LayoutMeshes"]

_MOVE_PREFIXES = ("xformOp", "sgdata:")  # properties that leave a prim's triangles as they are
_GEOMETRY_TYPES = ("Xform", "Scope", "Mesh", "GeomSubset", "Cube", "Cylinder", "Cone",
                   "Capsule", "Sphere")  # fmt: skip


class LayoutMeshes:
    """Per-prim reads (``None``: a prim with no triangles) of the room's layers, for the
    layouts of one room. A stage over other layers than the last one starts it afresh."""

    def __init__(self) -> None:
        # the room's layers, held: USD drops a layer no stage holds, and the next layout's
        # stage would parse the room again
        self._layers: list[Sdf.Layer] = []
        self._base: tuple[str, ...] = ()
        self.reads: dict[str, MeshData | None] = {}  # prim path -> what was read of it
        self.read = 0  # prims read from their stage
        self.reused = 0  # prims taken from an earlier layout instead

    def scope(self, stage: Usd.Stage) -> LayoutScope | None:
        """What ``stage``'s root layer leaves alone, or ``None`` when nothing may be reused
        (a stage of one layer, or a root layer that overrides a room prim that is not
        geometry)."""
        layers = stage.GetLayerStack(includeSessionLayers=False)
        base = tuple(layer.identifier for layer in layers[1:])
        if not base:
            return None
        if base != self._base:
            self._base, self.reads = base, {}
        self._layers = list(layers[1:])
        if _overrides_beyond_geometry(layers[0], layers[1:], stage):
            return None
        return LayoutScope(self, layers[0], stage)


class LayoutScope:
    """The reuse rule of one layout stage (see the module), from one pass over its prims."""

    def __init__(self, meshes: LayoutMeshes, root: Sdf.Layer, stage: Usd.Stage) -> None:
        self._meshes = meshes
        self._changed: set[Sdf.Path] = set()  # a root spec composes into it or below it
        self._feeding: set[Sdf.Path] = set()  # ... and more than a move, for what is below
        for prim in Usd.PrimRange.Stage(stage, Usd.TraverseInstanceProxies()):
            spec = next((s for s in prim.GetPrimStack() if s.layer == root), None)
            if spec is None:
                continue
            self._changed.update(prim.GetPath().GetPrefixes())
            if not _moves_only(spec):
                self._feeding.add(prim.GetPath())

    def left_alone(self, prim: Usd.Prim) -> bool:
        """Whether the root layer composes into nothing this prim's read depends on."""
        path = prim.GetPath()
        if path in self._changed:
            return False
        return not any(prefix in self._feeding for prefix in path.GetPrefixes())

    def get(self, prim: Usd.Prim) -> tuple[bool, MeshData | None]:
        """``(True, read)`` for a prim read before and left alone here, else ``(False, None)``."""
        key = str(prim.GetPath())
        if key in self._meshes.reads and self.left_alone(prim):
            self._meshes.reused += 1
            return True, self._meshes.reads[key]
        return False, None

    def keep(self, prim: Usd.Prim, read: MeshData | None) -> None:
        """Keep a prim's read for the next layouts when the root layer leaves it alone."""
        self._meshes.read += 1
        if self.left_alone(prim):
            self._meshes.reads[str(prim.GetPath())] = read


def _moves_only(spec: Sdf.PrimSpec) -> bool:
    """Whether a spec only moves its prim (transform or sgdata properties, no metadata)."""
    return set(spec.ListInfoKeys()) <= {"specifier"} and all(
        name.startswith(_MOVE_PREFIXES) for name in spec.properties.keys()
    )


def _overrides_beyond_geometry(root: Sdf.Layer, base: list[Sdf.Layer], stage: Usd.Stage) -> bool:
    """Whether the root layer changes a room prim that is not geometry (a material, a shader,
    a class or an untyped prim), which may feed meshes outside their own specs."""
    paths: list[Sdf.Path] = []
    root.Traverse(Sdf.Path.absoluteRootPath, lambda path: paths.append(path))
    for path in paths:
        if not path.IsPrimPath() or _moves_only(root.GetPrimAtPath(path)):
            continue
        prim = stage.GetPrimAtPath(path)
        in_room = any(layer.GetPrimAtPath(path) for layer in base)
        if in_room and prim and (prim.IsAbstract() or prim.GetTypeName() not in _GEOMETRY_TYPES):
            return True
    return False
