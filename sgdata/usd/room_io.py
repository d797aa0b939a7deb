"""Writing and reading rooms as USD stages (``room.usda``) and checking them with USD's validators.

Layout of a room stage (the on-disk contract; layouts in :mod:`sgdata.usd.layout_layers`
override it)::

    /Room                      Xform, kind assembly; sgdata:roomId, roomType, seed, roomSize
                               (width, depth, height), door:wall, door:center, door:width, door:top
    /Room/Structure            Xform; Meshes Floor, Ceiling, Walls (door gap cut out)
    /Room/Objects              Xform, kind group
    /Room/Objects/<Class>_<instance:04d>
                               Xform, kind component; xformOp:translate (double3) then
                               xformOp:rotateZ (double, degrees); sgdata:class, dynamics,
                               instance, size (float3), variant, color (color3f); rel
                               sgdata:support and sgdata:attachedTo (only when set)
    /Room/Objects/<prim>/Geom  Mesh in the object's local frame, triangles, uniform displayColor
                               indexed: one value per part (distinct colour), one index per face

Written with an appearance, a room also records each object's look and, with textures, holds
materials, texture coordinates and per-part bindings (:mod:`sgdata.usd.looks`,
:mod:`sgdata.usd.materials`).

A door's ``center`` is measured along its wall from the wall's low-coordinate end: from x = 0
on the south and north walls, from y = 0 on the east and west walls. ``sgdata:size`` and
``sgdata:color`` are float32 (as the contract says), so they read back as the shortest decimal
of their float32 value: sizes and colours with at most 6 significant digits round-trip exactly.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Protocol, runtime_checkable

import numpy as np
from pxr import Gf, Kind, Sdf, Usd, UsdGeom, Vt

from sgdata.errors import SceneError, UsdError
from sgdata.usd.geometry import stage_geometry
from sgdata.usd.meshes import MeshData, SceneGeometry
from sgdata.usd.prims import OBJECTS, ROOT, STRUCTURE, object_path
from sgdata.usd.stage import open_stage, write_usd_file
from sgdata.world.scene import WALLS, Dynamics, Opening, Placement, Room, SceneObject

if TYPE_CHECKING:
    from sgdata.usd.layout_meshes import LayoutMeshes
    from sgdata.usd.looks import RoomDresser
    from sgdata.world.appearance import AppearanceConfig
    from sgdata.world.catalog import Catalog
    from sgdata.world.shapes import PartTexture

__all__ = [
    "Geometry",
    "ObjectTextures",
    "TexturedGeometry",
    "catalog_geometry",
    "door_quad",
    "write_room",
    "read_room",
]

WALL_THICKNESS = 0.1  # metres, outside the room rectangle
SLAB_THICKNESS = 0.1  # floor below z = 0, ceiling above z = height

# (vertices (V, 3), faces (F, 3), face colours (F, 3)) of one object, in its local frame.
Geometry = Callable[[SceneObject], tuple[np.ndarray, np.ndarray, np.ndarray]]

_WALL_COLOR = (0.86, 0.84, 0.80)
_CEILING_COLOR = (0.93, 0.93, 0.91)
_FLOOR_COLORS = {  # tiles in wet rooms, wood elsewhere
    "kitchen": (0.62, 0.62, 0.60),
    "bathroom": (0.80, 0.84, 0.86),
    "living_room": (0.55, 0.38, 0.24),
    "bedroom": (0.60, 0.44, 0.30),
}
_DEFAULT_FLOOR = (0.5, 0.5, 0.5)

_STR, _TOKEN, _INT, _INT64 = (
    Sdf.ValueTypeNames.String,
    Sdf.ValueTypeNames.Token,
    Sdf.ValueTypeNames.Int,
    Sdf.ValueTypeNames.Int64,
)
_DOUBLE, _DOUBLE3 = Sdf.ValueTypeNames.Double, Sdf.ValueTypeNames.Double3
_FLOAT3, _COLOR3F = Sdf.ValueTypeNames.Float3, Sdf.ValueTypeNames.Color3f


# (face -> index into textures or -1 (F,), corner st (F, 3, 2), textures) of one object's
# faces: a mesh file's own image textures (sgdata.world.shapes.merged_textures)
ObjectTextures = tuple[np.ndarray, np.ndarray, "tuple[PartTexture, ...]"]


@runtime_checkable
class TexturedGeometry(Protocol):
    """A :data:`Geometry` that also gives the image textures of an object's faces (the mesh
    files' own); a textured room binds them instead of the procedural textures."""

    def __call__(self, obj: SceneObject) -> tuple[np.ndarray, np.ndarray, np.ndarray]: ...

    def textures(self, obj: SceneObject) -> ObjectTextures | None: ...


class _CatalogGeometry:
    """Each object's catalog recipe (or mesh files), merged into one mesh; mesh files' image
    textures on request."""

    def __init__(self, catalog: Catalog) -> None:
        self.catalog = catalog

    def __call__(self, obj: SceneObject) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        from sgdata.world.mesh_assets import class_shape
        from sgdata.world.shapes import merged_mesh

        spec = self.catalog[obj.class_name]
        return merged_mesh(class_shape(spec, obj.size, obj.variant, obj.color))

    def textures(self, obj: SceneObject) -> ObjectTextures | None:
        spec = self.catalog[obj.class_name]
        if spec.mesh is None:  # recipes have no image textures
            return None
        from sgdata.world.mesh_assets import mesh_build
        from sgdata.world.shapes import merged_textures

        face, st, textures = merged_textures(mesh_build(spec, obj.size, obj.variant, obj.color))
        return (face, st, textures) if textures else None


def catalog_geometry(catalog: Catalog | None = None) -> TexturedGeometry:
    """The default geometry source: each object's catalog recipe (or mesh file), merged into
    one mesh, with the mesh files' image textures (:class:`TexturedGeometry`).

    Args:
        catalog: the catalog naming each class's recipe; the shipped one when ``None``.
    """
    from sgdata.world.catalog import load_catalog  # late: the catalog and recipes pull in trimesh

    return _CatalogGeometry(catalog if catalog is not None else load_catalog())


# ---------------------------------------------------------------------------------- writing


def write_room(
    room: Room,
    path: Path,
    *,
    geometry: Geometry,
    appearance: AppearanceConfig | None = None,
    textures: Path | None = None,
) -> None:
    """Write ``room`` as a USD stage at ``path``, atomically and byte-reproducibly.

    Args:
        room: the room to write; its objects become prims in ``room.objects`` order.
        path: the ``.usda`` file to write (its folder is created if missing).
        geometry: local-frame mesh of an object (see :func:`catalog_geometry`).
        appearance: record the room's base looks (:func:`sgdata.world.appearance.room_looks`)
            and, with ``appearance.textures``, dress every surface in textured materials;
            ``None`` writes flat colours only.
        textures: the folder of the texture images (written there if missing); default
            :func:`sgdata.scene_files.textures_dir` of ``path``'s folder.

    Raises:
        SceneError: an object's support or owner is not in the room, or its mesh is malformed.
        UsdError: the file cannot be written.
    """
    stage = Usd.Stage.CreateInMemory()
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.z)
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)
    root = UsdGeom.Xform.Define(stage, ROOT).GetPrim()
    stage.SetDefaultPrim(root)
    Usd.ModelAPI(root).SetKind(Kind.Tokens.assembly)
    _set(root, "sgdata:roomId", _STR, room.room_id)
    _set(root, "sgdata:roomType", _TOKEN, room.room_type)
    _set(root, "sgdata:seed", _INT64, _int64(room.seed, f"room {room.room_id} seed"))
    _set(root, "sgdata:roomSize", _DOUBLE3, Gf.Vec3d(room.width, room.depth, room.height))
    _set(root, "sgdata:door:wall", _TOKEN, room.door.wall)
    _set(root, "sgdata:door:center", _DOUBLE, room.door.center)
    _set(root, "sgdata:door:width", _DOUBLE, room.door.width)
    _set(root, "sgdata:door:top", _DOUBLE, room.door.top)
    if room.door.bottom != 0.0:  # a door has none; kept so other openings round-trip too
        _set(root, "sgdata:door:bottom", _DOUBLE, room.door.bottom)

    dresser = None
    if appearance is not None:
        from sgdata.usd.looks import RoomDresser  # late: materials pull in Pillow and textures

        dresser = RoomDresser(stage, room, Path(path), appearance, textures)
    UsdGeom.Xform.Define(stage, STRUCTURE)
    for name, (vertices, faces, colors) in _structure_meshes(room).items():
        mesh, _ = _define_mesh(stage, STRUCTURE.AppendChild(name), vertices, faces, colors)
        if dresser is not None:
            dresser.structure(name, mesh, vertices, faces, tuple(colors[0]))

    group = UsdGeom.Xform.Define(stage, OBJECTS).GetPrim()
    Usd.ModelAPI(group).SetKind(Kind.Tokens.group)
    by_instance = room.by_instance()
    for obj in room.objects:
        _define_object(stage, obj, by_instance, geometry, dresser)
    if dresser is not None:
        dresser.finish()
    write_usd_file(path, stage.GetRootLayer().ExportToString())


def _define_object(
    stage: Usd.Stage,
    obj: SceneObject,
    by_instance: dict[int, SceneObject],
    geometry: Geometry,
    dresser: RoomDresser | None,
) -> None:
    where = f"object {obj.prim_name}"
    xform = UsdGeom.Xform.Define(stage, object_path(obj))
    prim = xform.GetPrim()
    Usd.ModelAPI(prim).SetKind(Kind.Tokens.component)
    p = obj.placement
    xform.AddTranslateOp(UsdGeom.XformOp.PrecisionDouble).Set(Gf.Vec3d(p.x, p.y, p.z))
    xform.AddRotateZOp(UsdGeom.XformOp.PrecisionDouble).Set(math.degrees(p.yaw))
    _set(prim, "sgdata:class", _STR, obj.class_name)
    _set(prim, "sgdata:dynamics", _TOKEN, str(obj.dynamics))
    _set(prim, "sgdata:instance", _INT, obj.instance)
    _set(prim, "sgdata:size", _FLOAT3, Gf.Vec3f(*obj.size))
    _set(prim, "sgdata:variant", _INT, obj.variant)
    _set(prim, "sgdata:color", _COLOR3F, Gf.Vec3f(*obj.color))
    for rel_name, target in (
        ("sgdata:support", obj.support),
        ("sgdata:attachedTo", obj.attached_to),
    ):
        if target is None:
            continue
        if target not in by_instance:
            raise SceneError(f"{where}: {rel_name} names instance {target}, not in the room")
        rel = prim.CreateRelationship(rel_name, custom=True)
        rel.SetTargets([object_path(by_instance[target])])
    vertices, faces, colors = _checked_mesh(where, *geometry(obj))
    images = None
    if dresser is not None and dresser.textured and isinstance(geometry, TexturedGeometry):
        images = geometry.textures(obj)
    mesh, parts = _define_mesh(
        stage,
        object_path(obj).AppendChild("Geom"),
        vertices,
        faces,
        colors,
        None if images is None else images[0],
    )
    if dresser is not None:
        dresser.object(prim, obj, mesh, vertices, faces, parts, images)


def _define_mesh(
    stage: Usd.Stage,
    path: Sdf.Path,
    vertices: np.ndarray,
    faces: np.ndarray,
    colors: np.ndarray,
    images: np.ndarray | None = None,
) -> tuple[UsdGeom.Mesh, np.ndarray]:
    """A triangle mesh with an indexed uniform displayColor; returns it and the part
    (index of its colour among the distinct colours, in order of first use) of each face.
    With ``images`` (each face's image texture, -1 none) a part is a distinct colour and image
    (two parts may then share a displayColor value)."""
    mesh = UsdGeom.Mesh.Define(stage, path)
    points = Vt.Vec3fArray.FromNumpy(np.ascontiguousarray(vertices, dtype=np.float32))
    mesh.CreatePointsAttr(points)
    mesh.CreateFaceVertexCountsAttr(Vt.IntArray.FromNumpy(np.full(len(faces), 3, np.int32)))
    mesh.CreateFaceVertexIndicesAttr(
        Vt.IntArray.FromNumpy(np.ascontiguousarray(faces, dtype=np.int32).ravel())
    )
    mesh.CreateExtentAttr(UsdGeom.Mesh.ComputeExtent(points))
    mesh.CreateSubdivisionSchemeAttr(UsdGeom.Tokens.none)
    mesh.CreateDoubleSidedAttr(False)
    flat = np.asarray(colors, dtype=np.float32).reshape(-1, 3)
    if images is None:
        values, parts = _parts(flat)
    else:
        keyed, parts = _parts(np.c_[flat, np.asarray(images, np.float32).reshape(-1, 1)])
        values = np.ascontiguousarray(keyed[:, :3], dtype=np.float32)
    primvar = mesh.CreateDisplayColorPrimvar(UsdGeom.Tokens.uniform)
    primvar.Set(Vt.Vec3fArray.FromNumpy(values))
    primvar.SetIndices(Vt.IntArray.FromNumpy(parts))
    return mesh, parts


def _parts(colors: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The distinct colours in order of first use, and each face's index into them."""
    if not len(colors):
        return np.zeros((0, 3), np.float32), np.zeros(0, np.int32)
    unique, first, inverse = np.unique(colors, axis=0, return_index=True, return_inverse=True)
    order = np.argsort(first, kind="stable")
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    values = np.ascontiguousarray(unique[order], dtype=np.float32)
    return values, rank[inverse.reshape(-1)].astype(np.int32)


def _checked_mesh(
    where: str, vertices: np.ndarray, faces: np.ndarray, colors: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    v, f, c = np.asarray(vertices), np.asarray(faces), np.asarray(colors)
    if v.ndim != 2 or v.shape[1] != 3 or f.ndim != 2 or f.shape[1] != 3 or c.shape != f.shape:
        raise SceneError(
            f"{where}: geometry must be vertices (V, 3), faces (F, 3), colours (F, 3); "
            f"got {v.shape}, {f.shape}, {c.shape}"
        )
    if len(f) and (f.min() < 0 or f.max() >= len(v)):
        raise SceneError(f"{where}: face indices outside [0, {len(v)})")
    return v, f, c


def _set(prim: Usd.Prim, name: str, type_name: Sdf.ValueTypeName, value: object) -> None:
    prim.CreateAttribute(name, type_name, custom=True).Set(value)


def _int64(value: int, what: str) -> int:
    if not -(2**63) <= value < 2**63:
        raise SceneError(f"{what} {value} does not fit USD's int64; use a seed below 2**63")
    return int(value)


def _box(lo: tuple[float, float, float], hi: tuple[float, float, float]) -> np.ndarray:
    """The 12 outward-wound triangles of the box [lo, hi], as an (12, 3, 3) corner array."""
    corners = np.array(
        [
            [(lo, hi)[i & 1][0], (lo, hi)[(i >> 1) & 1][1], (lo, hi)[(i >> 2) & 1][2]]
            for i in range(8)
        ]
    )
    tris = [[0, 2, 3], [0, 3, 1], [4, 5, 7], [4, 7, 6], [0, 1, 5], [0, 5, 4]]
    tris += [[2, 6, 7], [2, 7, 3], [0, 4, 6], [0, 6, 2], [1, 3, 7], [1, 7, 5]]
    return corners[np.array(tris)]


def _wall_boxes(room: Room) -> list[np.ndarray]:
    """The wall boxes, each wall split around the openings that lie in it."""
    w, d, h, t = room.width, room.depth, room.height, WALL_THICKNESS
    # wall -> (along-axis span, fixed-axis span, along axis is x)
    spans = {
        "south": ((-t, w + t), (-t, 0.0), True),
        "north": ((-t, w + t), (d, d + t), True),
        "west": ((0.0, d), (-t, 0.0), False),
        "east": ((0.0, d), (w, w + t), False),
    }
    boxes = []
    for wall in WALLS:
        (a0, a1), (b0, b1), along_x = spans[wall]
        pieces = [(a0, a1, 0.0, h)]
        door = room.door
        if door.wall == wall:
            g0, g1 = door.center - door.width / 2, door.center + door.width / 2
            pieces = [(a0, g0, 0.0, h), (g1, a1, 0.0, h), (g0, g1, door.top, h)]
            pieces.append((g0, g1, 0.0, door.bottom))
        for p0, p1, z0, z1 in pieces:
            if p1 - p0 <= 1e-9 or z1 - z0 <= 1e-9:
                continue
            lo, hi = ((p0, b0, z0), (p1, b1, z1)) if along_x else ((b0, p0, z0), (b1, p1, z1))
            boxes.append(_box(lo, hi))
    return boxes


def _structure_meshes(room: Room) -> dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Floor, Ceiling and Walls as world-space triangle meshes with face colours."""
    w, d, h, s = room.width, room.depth, room.height, SLAB_THICKNESS
    parts = {
        "Floor": ([_box((0.0, 0.0, -s), (w, d, 0.0))], _FLOOR_COLORS.get(room.room_type)),
        "Ceiling": ([_box((0.0, 0.0, h), (w, d, h + s))], _CEILING_COLOR),
        "Walls": (_wall_boxes(room), _WALL_COLOR),
    }
    meshes = {}
    for name, (boxes, color) in parts.items():
        tris = np.concatenate(boxes)
        faces = np.arange(3 * len(tris), dtype=np.int32).reshape(-1, 3)
        colors = np.tile(np.asarray(color or _DEFAULT_FLOOR, np.float32), (len(tris), 1))
        meshes[name] = (tris.reshape(-1, 3), faces, colors)
    return meshes


DOOR_BEHIND = 0.5  # metres behind the door wall's inner plane: past any wall (0.1 m here)
DOOR_MARGIN = 2.0  # metres the door rectangle reaches past the opening on each side


def door_quad(room: Room) -> MeshData:
    """The room's door opening as the id pass draws it (:attr:`SceneGeometry.door`): a
    rectangle in the room frame, :data:`DOOR_BEHIND` behind the door's wall and
    :data:`DOOR_MARGIN` larger than the opening on every side. Through a gap it is what a ray
    meets past the gap's own faces (those are wall); behind a solid wall (a measured room's
    virtual entry) the wall hides it. Never drawn in colour."""
    door, w, d, m = room.door, room.width, room.depth, DOOR_MARGIN
    a0, a1 = door.center - door.width / 2 - m, door.center + door.width / 2 + m
    z0, z1 = door.bottom - m, door.top + m
    if door.wall in ("south", "north"):
        y = -DOOR_BEHIND if door.wall == "south" else d + DOOR_BEHIND
        corners = [(a0, y, z0), (a1, y, z0), (a1, y, z1), (a0, y, z1)]
    else:
        x = -DOOR_BEHIND if door.wall == "west" else w + DOOR_BEHIND
        corners = [(x, a0, z0), (x, a1, z0), (x, a1, z1), (x, a0, z1)]
    faces = np.array([[0, 1, 2], [0, 2, 3]], np.int32)
    return MeshData(np.array(corners, np.float64), faces, np.zeros((2, 3), np.float32), "door")


# ---------------------------------------------------------------------------------- reading


def read_room(path: Path) -> Room:
    """Read a room back from ``room.usda``, or the composed room of a ``layout_<k>.usda``.

    A stage not written by :func:`write_room` (no ``sgdata:roomSize``, or tagged by
    ``sgdata tag``) is measured from its geometry (:mod:`sgdata.usd.user_rooms`).

    Raises:
        UsdError: the file is missing, unreadable, does not compose, or lacks a ``sgdata:*``
            attribute this module writes (the message names the prim and the attribute).
    """
    path = Path(path)
    return _stage_room(open_stage(path), path)


def read_scene(path: Path, meshes: LayoutMeshes | None = None) -> tuple[Room, SceneGeometry]:
    """The room of :func:`read_room` and the meshes of :func:`sgdata.usd.geometry.
    read_geometry` from one opening of the stage at ``path`` (``meshes``: the room's meshes
    kept across its layouts, see :mod:`sgdata.usd.layout_meshes`).

    Raises:
        UsdError: as either function.
    """
    path = Path(path)
    stage = open_stage(path)
    return _stage_room(stage, path), stage_geometry(stage, path, meshes)


def _stage_room(stage: Usd.Stage, path: Path) -> Room:
    from sgdata.usd.user_rooms import is_measured, measure_stage  # late: it reads geometry

    if is_measured(stage):  # a room authored elsewhere, tagged or not
        return measure_stage(stage, path).room
    root = stage.GetPrimAtPath(ROOT)
    size = _get(path, root, "sgdata:roomSize")
    door = Opening(
        wall=str(_get(path, root, "sgdata:door:wall")),
        center=float(_get(path, root, "sgdata:door:center")),
        width=float(_get(path, root, "sgdata:door:width")),
        bottom=float(_get(path, root, "sgdata:door:bottom", 0.0)),
        top=float(_get(path, root, "sgdata:door:top")),
    )
    if door.wall not in WALLS:
        raise UsdError(f"{path}: {ROOT} sgdata:door:wall is {door.wall!r}; expected one of {WALLS}")
    group = stage.GetPrimAtPath(OBJECTS)
    prims = list(group.GetChildren()) if group.IsValid() else []
    instances = {p.GetPath(): int(_get(path, p, "sgdata:instance")) for p in prims}
    objects = [_read_object(path, prim, instances) for prim in prims]
    return Room(
        room_id=str(_get(path, root, "sgdata:roomId")),
        room_type=str(_get(path, root, "sgdata:roomType")),
        width=float(size[0]),
        depth=float(size[1]),
        height=float(size[2]),
        seed=int(_get(path, root, "sgdata:seed")),
        door=door,
        objects=tuple(objects),
    )


def _read_object(path: Path, prim: Usd.Prim, instances: dict[Sdf.Path, int]) -> SceneObject:
    dynamics = str(_get(path, prim, "sgdata:dynamics"))
    try:
        dyn = Dynamics(dynamics)
    except ValueError:
        raise UsdError(
            f"{path}: {prim.GetPath()} sgdata:dynamics is {dynamics!r}; "
            f"expected static, low or high"
        ) from None
    return SceneObject(
        instance=instances[prim.GetPath()],
        class_name=str(_get(path, prim, "sgdata:class")),
        dynamics=dyn,
        size=_float3(_get(path, prim, "sgdata:size")),
        placement=_read_placement(path, prim),
        variant=int(_get(path, prim, "sgdata:variant", 0)),
        color=_float3(_get(path, prim, "sgdata:color", Gf.Vec3f(0.7, 0.7, 0.7))),
        support=_target(path, prim, "sgdata:support", instances),
        attached_to=_target(path, prim, "sgdata:attachedTo", instances),
    )


def _read_placement(path: Path, prim: Usd.Prim) -> Placement:
    translate = prim.GetAttribute("xformOp:translate").Get()
    rotate = prim.GetAttribute("xformOp:rotateZ").Get()
    if translate is not None and rotate is not None:
        return Placement(*(float(v) for v in translate), yaw=math.radians(rotate))
    # authored by another tool: take position and heading from the composed transform
    m = np.array(UsdGeom.Xformable(prim).ComputeLocalToWorldTransform(Usd.TimeCode.Default()))
    if not np.isfinite(m).all():
        raise UsdError(f"{path}: {prim.GetPath()} has no usable transform")
    return Placement(*(float(v) for v in m[3, :3]), yaw=math.atan2(m[0, 1], m[0, 0]))


def _target(path: Path, prim: Usd.Prim, name: str, instances: dict[Sdf.Path, int]) -> int | None:
    rel = prim.GetRelationship(name)
    targets = rel.GetTargets() if rel else []
    if not targets:
        return None
    if len(targets) > 1 or targets[0] not in instances:
        raise UsdError(
            f"{path}: {prim.GetPath()} {name} targets {[str(t) for t in targets]}; "
            f"expected one object prim under {OBJECTS}"
        )
    return instances[targets[0]]


_MISSING = object()


def _get(path: Path, prim: Usd.Prim, name: str, default: object = _MISSING) -> object:
    attr = prim.GetAttribute(name)
    value = attr.Get() if attr else None
    if value is None:
        if default is _MISSING:
            raise UsdError(f"{path}: {prim.GetPath()} lacks attribute {name}")
        return default
    return value


def _float3(value: object) -> tuple[float, float, float]:
    # float32 in the file: its shortest decimal gives back the value that was written
    a, b, c = (float(str(np.float32(v))) for v in value)  # type: ignore[attr-defined]
    return (a, b, c)


# ------------------------------------------------------------------------------- validation
