"""The meshes of a room kept across its layouts: a layout re-reads only what its layer changes.

A layout stage is a layout layer (the stage's root layer) over the room's layers. Most prims'
triangles, colours and materials come from the room's layers alone, identical in every
layout; only the prims the layout layer overrides differ (moved objects change their
transforms, which are read per layout anyway; re-dressed ones their colours and bindings).
:class:`LayoutMeshes` keeps what :func:`sgdata.usd.geometry.stage_geometry` read for each prim
the layout layer leaves alone, so the next layout of the same room reads only the prims its
layer touches.

A prim is *left alone* by the root layer when the layer holds no spec for it, for any of its
descendants (a part's binding), nor for an ancestor other than a transform-only one (a spec
whose properties are all ``xformOp*`` or ``sgdata:*`` and that authors no metadata beyond its
specifier: a move). When the layer overrides a prim of the room that no mesh hangs from or
under (a material, a shader, a class an object inherits), nothing is reused for that layout.
"""

from __future__ import annotations

from pxr import Sdf, Usd

from sgdata.usd.meshes import MeshData

__all__ = ["LayoutMeshes"]

_MOVE_PREFIXES = ("xformOp", "sgdata:")  # properties that leave a prim's triangles as they are
_GEOMETRY_TYPES = ("Xform", "Scope", "Mesh", "GeomSubset", "Cube", "Cylinder", "Cone",
                   "Capsule", "Sphere", "")  # fmt: skip


class LayoutMeshes:
    """Per-prim reads (``None``: a prim with no triangles) of the room's layers, for the
    layouts of one room. A stage over other layers than the last one starts it afresh."""

    def __init__(self) -> None:
        # the room's layers, held: USD drops a layer no stage holds, and the next layout's
        # stage would parse the room again
        self._layers: list[Sdf.Layer] = []
        self._base: tuple[str, ...] = ()
        self._reads: dict[str, MeshData | None] = {}
        self.read = 0  # prims read from their stage
        self.reused = 0  # prims taken from an earlier layout instead

    def scope(self, stage: Usd.Stage) -> LayoutScope | None:
        """What ``stage``'s root layer leaves alone, or ``None`` when nothing may be reused
        (a stage of one layer, or a root layer that overrides a room prim outside the meshes'
        chains)."""
        layers = stage.GetLayerStack(includeSessionLayers=False)
        base = tuple(layer.identifier for layer in layers[1:])
        if not base:
            return None
        if base != self._base:
            self._base, self._reads = base, {}
        self._layers = list(layers[1:])
        touched = _touched(layers[0], layers[1:], stage)
        return None if touched is None else LayoutScope(self, *touched)


class LayoutScope:
    """The reuse rule of one layout stage (see the module)."""

    def __init__(self, meshes: LayoutMeshes, touched: set[Sdf.Path], specs: set[Sdf.Path]) -> None:
        self._meshes, self._touched, self._specs = meshes, touched, specs
        # a prim is changed when it, or one of its descendants, is touched
        self._changed = {prefix for path in touched for prefix in path.GetPrefixes()}

    def left_alone(self, path: Sdf.Path) -> bool:
        """Whether the root layer has no spec for this prim and changes nothing it reads."""
        if path in self._specs or path in self._changed:
            return False
        return not any(prefix in self._touched for prefix in path.GetPrefixes())

    def get(self, path: Sdf.Path) -> tuple[bool, MeshData | None]:
        """``(True, read)`` for a prim read before and left alone here, else ``(False, None)``."""
        key = str(path)
        if key in self._meshes._reads and self.left_alone(path):
            self._meshes.reused += 1
            return True, self._meshes._reads[key]
        return False, None

    def keep(self, path: Sdf.Path, read: MeshData | None) -> None:
        """Keep a prim's read for the next layouts when the root layer leaves it alone."""
        self._meshes.read += 1
        if self.left_alone(path):
            self._meshes._reads[str(path)] = read


def _touched(
    root: Sdf.Layer, base: list[Sdf.Layer], stage: Usd.Stage
) -> tuple[set[Sdf.Path], set[Sdf.Path]] | None:
    """The root layer's prim specs that may change triangles (``touched``) and all its prim
    specs (``specs``); ``None`` when it overrides a room prim that is not geometry."""
    touched: set[Sdf.Path] = set()
    specs: set[Sdf.Path] = set()

    def visit(path: Sdf.Path) -> None:
        if not path.IsPrimPath():
            return
        spec = root.GetPrimAtPath(path)
        specs.add(path)
        moves_only = set(spec.ListInfoKeys()) <= {"specifier"} and all(
            name.startswith(_MOVE_PREFIXES) for name in spec.properties.keys()
        )
        if moves_only:
            return
        touched.add(path)

    root.Traverse(Sdf.Path.absoluteRootPath, visit)
    for path in touched:
        in_room = any(layer.GetPrimAtPath(path) for layer in base)
        prim = stage.GetPrimAtPath(path)
        if in_room and prim and prim.GetTypeName() not in _GEOMETRY_TYPES:
            return None
    return touched, specs
