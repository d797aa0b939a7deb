"""Reading a composed stage's meshes for rendering, from pxr alone (no catalog needed).

Any stage whose object prims carry ``sgdata:class`` or ``sgdata:instance`` renders, whatever
tool wrote it: such a prim is an object, every mesh beneath it is part of that object (expressed in
the object's local frame), and every other mesh is structure (in world space). Faces with more
than three corners are fanned into triangles; ``primvars:displayColor`` gives the face colours
(constant, uniform, vertex and faceVarying interpolation; grey when absent). Bound materials
override it where they say more (:mod:`sgdata.usd.bound_materials`): a textured face carries
its texture file and coordinates, and the texture's colour factor as its face colour. The
stage's light (``sgdata:light:*`` on its room prim, :mod:`sgdata.usd.prims`) comes back as
:class:`~sgdata.usd.meshes.Lighting`.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
from pxr import Tf, Usd, UsdGeom

from sgdata.errors import UsdError
from sgdata.usd.bound_materials import MaterialReader
from sgdata.usd.gprims import tessellate_gprim
from sgdata.usd.layout_meshes import LayoutMeshes, LayoutScope
from sgdata.usd.meshes import Lighting, MeshData, ObjectGeometry, SceneGeometry, merge_meshes
from sgdata.usd.object_prims import drawn_prims, instance_ids, is_object
from sgdata.usd.prims import LIGHT_INTENSITY, LIGHT_TEMPERATURE
from sgdata.usd.stage import open_stage, usd_reason
from sgdata.usd.stage_frame import room_prim, stage_frame
from sgdata.world.appearance import light_color
from sgdata.world.scene import transform_points

__all__ = ["DEFAULT_COLOR", "prim_triangles", "read_geometry", "stage_geometry"]

DEFAULT_COLOR = (0.6, 0.6, 0.6)  # face colour of meshes without a displayColor


def read_geometry(path: Path, meshes: LayoutMeshes | None = None) -> SceneGeometry:
    """The triangle meshes of the composed stage at ``path`` (a room, a layout, any USD file).

    Invisible prims and guide/proxy purposes are skipped; instance proxies are followed. Meshes
    and the gprims ``Cube``, ``Cylinder``, ``Cone``, ``Capsule`` and ``Sphere`` (tessellated)
    are read, under any nesting of Xforms. Coordinates come back in the room frame (Z up,
    metres, see :func:`sgdata.usd.stage_frame.stage_frame`) whatever the stage's up axis,
    units and origin.

    With ``meshes`` (:class:`~sgdata.usd.layout_meshes.LayoutMeshes`, one per room) the prims a
    layout layer leaves alone are taken from the room's earlier layouts instead of re-read.

    Raises:
        UsdError: the file is missing, unreadable or does not compose, an object prim has
            a non-integer or duplicate ``sgdata:instance``, a mesh is malformed (NaN or inf
            points, an index past its points), a gprim's size is not positive, or a transform
            is not finite or (for an object) singular.
    """
    path = Path(path)
    return stage_geometry(open_stage(path), path, meshes)


def stage_geometry(
    stage: Usd.Stage, path: Path, meshes: LayoutMeshes | None = None
) -> SceneGeometry:
    """:func:`read_geometry` of an open stage (``path`` names it in messages)."""
    with np.errstate(over="ignore", invalid="ignore"):  # overflow is refused just below
        geometry = _read_stage(stage, path, None if meshes is None else meshes.scope(stage))
        parts = [(m.name, m.vertices) for m in geometry.structure]
        parts += [(o.mesh.name, o.world_vertices()) for o in geometry.objects]
    for name, vertices in parts:
        if not np.isfinite(vertices).all():
            raise UsdError(
                f"{path}: {name} has coordinates that overflow to inf or NaN in metres (a huge "
                "metersPerUnit, scale or point); expected a room-sized prim"
            )
    return geometry


def _read_stage(stage: Usd.Stage, path: Path, scope: LayoutScope | None) -> SceneGeometry:
    frame = stage_frame(stage)
    cache = UsdGeom.XformCache(Usd.TimeCode.Default())
    owners: dict[str, Usd.Prim] = {}  # object prim path -> prim, in traversal order
    parts: dict[str, list[MeshData]] = {}
    structure = []
    materials = MaterialReader()
    for prim in drawn_prims(stage):
        if is_object(prim):
            owners[str(prim.GetPath())] = prim
            parts.setdefault(str(prim.GetPath()), [])
        kept, found = (False, None) if scope is None else scope.get(prim)
        if not kept:
            try:
                _check_value_types(prim)
                found = _prim_triangles(prim, materials)
            except UsdError as exc:
                raise UsdError(f"{path}: {exc}") from None
            if scope is not None:
                scope.keep(prim, found)
        if found is None:
            continue
        try:
            world = _world(cache, prim, frame)
        except UsdError as exc:
            raise UsdError(f"{path}: {exc}") from None
        owner = _owner(prim, owners)
        if not np.isfinite(world).all():
            raise UsdError(
                f"{path}: {prim.GetPath()} has a transform with NaN or infinite values "
                "(its own xformOps or an ancestor's); expected finite numbers"
            )
        if owner is None:
            vertices = transform_points(world, found.vertices)
            structure.append(replace(found, vertices=vertices, name=str(prim.GetPath())))
        else:
            to_owner = _inverse(path, owner, _world(cache, owner, frame)) @ world
            if not np.allclose(to_owner, np.eye(4), rtol=0.0, atol=1e-12):
                found = replace(found, vertices=transform_points(to_owner, found.vertices))
            # else: a mesh in its object's own frame keeps its exact vertices, so a moved
            # object's mesh equals the unmoved one (the renderer then only re-poses it)
            parts[str(owner.GetPath())].append(found)
    ids = instance_ids(path, list(owners.values()))
    objects = []
    for key, prim in owners.items():
        cls = prim.GetAttribute("sgdata:class").Get() if prim.HasAttribute("sgdata:class") else None
        objects.append(
            ObjectGeometry(
                instance=ids[key],
                class_name=str(cls) if cls else prim.GetName(),
                mesh=merge_meshes(parts[key], key),
                matrix=_world(cache, prim, frame),
            )
        )
    return SceneGeometry(
        structure=tuple(structure), objects=tuple(objects), lighting=_lighting(stage)
    )


def _lighting(stage: Usd.Stage) -> Lighting:
    """The light the stage's room prim asks for (defaults: scale 1, white)."""
    root = room_prim(stage)
    if not root or not root.IsValid():
        return Lighting()
    intensity = (
        root.GetAttribute(LIGHT_INTENSITY).Get() if root.HasAttribute(LIGHT_INTENSITY) else None
    )
    kelvin = (
        root.GetAttribute(LIGHT_TEMPERATURE).Get() if root.HasAttribute(LIGHT_TEMPERATURE) else None
    )
    return Lighting(
        intensity=1.0 if intensity is None else float(intensity),
        temperature=None if kelvin is None else float(kelvin),
        color=(1.0, 1.0, 1.0) if kelvin is None else light_color(float(kelvin)),
    )


def prim_triangles(prim: Usd.Prim, materials: MaterialReader) -> MeshData | None:
    """The triangles of a mesh or a tessellated gprim in its own frame, with their colours and
    bound textures; ``None`` for other prims.

    Raises:
        UsdError: a malformed mesh or gprim, or a bound texture that does not resolve.
    """
    return _prim_triangles(prim, materials)


def _prim_triangles(prim: Usd.Prim, materials: MaterialReader) -> MeshData | None:
    """The triangles of a mesh or a tessellated gprim in its own frame; ``None`` for others."""
    if prim.IsA(UsdGeom.Mesh):
        return _triangles(UsdGeom.Mesh(prim), materials)
    if prim.IsA(UsdGeom.Gprim):
        found = tessellate_gprim(prim)
        if found is None:
            return None
        vertices, faces = found
        colors = _face_colors(UsdGeom.Gprim(prim), np.full(len(faces), 3))
        return MeshData(vertices, faces, colors)
    return None


def _owner(prim: Usd.Prim, owners: dict[str, Usd.Prim]) -> Usd.Prim | None:
    """The nearest object prim at or above ``prim`` (ancestors come first in traversal)."""
    for path in reversed(prim.GetPath().GetPrefixes()):
        if str(path) in owners:
            return owners[str(path)]
    return None


def _world(cache: UsdGeom.XformCache, prim: Usd.Prim, frame: np.ndarray | None) -> np.ndarray:
    try:
        # USD matrices act on row vectors (p' = p M): transpose for the column convention
        m = np.array(cache.GetLocalToWorldTransform(prim), dtype=np.float64).T
    except Tf.ErrorException as exc:  # e.g. an xformOp authored with the wrong value type
        reason = usd_reason(exc)
        raise UsdError(f"{prim.GetPath()}: USD cannot compute its transform ({reason})") from None
    return m if frame is None else frame @ m


def _inverse(path: Path, owner: Usd.Prim, matrix: np.ndarray) -> np.ndarray:
    """The inverse of an object's world matrix; a singular one (a zero scale) cannot place it."""
    if abs(np.linalg.det(matrix[:3, :3])) < 1e-18:
        raise UsdError(
            f"{path}: {owner.GetPath()} has a singular transform (a zero scale in its xformOps "
            "or an ancestor's); expected an invertible one"
        )
    return np.linalg.inv(matrix)


def _triangles(mesh: UsdGeom.Mesh, materials: MaterialReader) -> MeshData:
    """Fan-triangulate a mesh; colours per triangle from its displayColor primvar, then from
    its bound materials (with their textures).

    Raises:
        UsdError: points that are not finite, face counts that disagree with the indices, or an
            index outside the points (names the prim, without the file).
    """
    where = mesh.GetPath()
    points = mesh.GetPointsAttr().Get()
    counts = mesh.GetFaceVertexCountsAttr().Get()
    indices = mesh.GetFaceVertexIndicesAttr().Get()
    vertices = np.array(points, dtype=np.float64).reshape(-1, 3) if points else np.zeros((0, 3))
    counts = np.array(counts, dtype=np.int64) if counts else np.zeros(0, np.int64)
    indices = np.array(indices, dtype=np.int64) if indices else np.zeros(0, np.int64)
    if not np.isfinite(vertices).all():
        k = int(np.flatnonzero(~np.isfinite(vertices).all(axis=1))[0])
        raise UsdError(
            f"{where} points[{k}] is {tuple(vertices[k].tolist())}; expected finite numbers "
            "(no NaN or inf): fix or remove that point"
        )
    if (counts < 0).any() or counts.sum() != len(indices):
        raise UsdError(
            f"{where} faceVertexCounts sum to {int(counts.sum())} but faceVertexIndices holds "
            f"{len(indices)} indices; expected one index per face corner (and no negative count)"
        )
    outside = (indices < 0) | (indices >= len(vertices))
    if outside.any():
        k = int(np.flatnonzero(outside)[0])
        raise UsdError(
            f"{where} faceVertexIndices[{k}] is {int(indices[k])}, past the mesh's "
            f"{len(vertices)} points; expected indices in [0, {len(vertices)}): fix the index"
        )
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]]).astype(np.int64)
    tri_counts = np.maximum(counts - 2, 0)
    face_of = np.repeat(np.arange(len(counts)), tri_counts)  # source face of each triangle
    k = np.arange(len(face_of)) - np.repeat(np.cumsum(tri_counts) - tri_counts, tri_counts)
    corners = np.stack([starts[face_of], starts[face_of] + k + 1, starts[face_of] + k + 2], 1)
    if mesh.GetOrientationAttr().Get() == UsdGeom.Tokens.leftHanded:
        corners = corners[:, [0, 2, 1]]
    faces = indices[corners].astype(np.int32)
    colors = _face_colors(mesh, counts)[face_of]
    if len(corners):
        corner_colors = _corner_colors(mesh, indices, len(vertices))
        if corner_colors is not None:  # per-vertex / face-varying: average over the triangle
            colors = corner_colors[corners].mean(axis=1).astype(np.float32)
    bound = materials.faces(mesh, colors, face_of, corners, indices)
    if bound is None:
        return MeshData(vertices, faces, colors)
    textured = bool((bound.face_texture >= 0).any())
    return MeshData(
        vertices,
        faces,
        bound.colors,
        uvs=bound.uvs if textured else None,
        face_texture=bound.face_texture if textured else None,
        textures=bound.files if textured else (),
    )


# Python types of scalar values (pxr gives no pythonClass for them)
_SCALARS = {"double": float, "float": float, "half": float, "int": int, "int64": int,
            "uint": int, "token": str, "string": str, "bool": bool}  # fmt: skip


def _check_value_types(prim: Usd.Prim) -> None:
    """Refuse an attribute authored with another value type than its schema's (a wrong
    typeName in a hand-written file: ``string points = "1"``) rather than misread it."""
    for attr in prim.GetAuthoredAttributes():
        value = attr.Get()
        name = attr.GetTypeName()
        expected = name.type.pythonClass or _SCALARS.get(str(name))
        if value is None or expected is None or isinstance(value, expected):
            continue
        if expected is float and isinstance(value, int):
            continue
        shown = repr(value) if len(repr(value)) < 40 else repr(value)[:37] + "..."
        raise UsdError(
            f"{attr.GetPath()} holds {shown}, authored with another value type; expected {name}"
        )


def _display_color(mesh: UsdGeom.Gprim) -> tuple[np.ndarray, str] | None:
    primvar = UsdGeom.PrimvarsAPI(mesh.GetPrim()).GetPrimvar("displayColor")
    if not primvar or not primvar.HasValue():
        return None
    values = primvar.ComputeFlattened()
    if values is None or len(values) == 0:
        return None
    return np.array(values, dtype=np.float32).reshape(-1, 3), primvar.GetInterpolation()


def _face_colors(mesh: UsdGeom.Gprim, counts: np.ndarray) -> np.ndarray:
    found = _display_color(mesh)
    n = len(counts)
    if found is not None:
        values, interpolation = found
        if interpolation == UsdGeom.Tokens.uniform and len(values) == n:
            return values
        if interpolation == UsdGeom.Tokens.constant:
            return np.tile(values[0], (n, 1))
    return np.tile(np.asarray(DEFAULT_COLOR, np.float32), (n, 1))


def _corner_colors(mesh: UsdGeom.Mesh, indices: np.ndarray, n_points: int) -> np.ndarray | None:
    """Colour of every face-vertex corner for vertex / faceVarying colours, else ``None``."""
    found = _display_color(mesh)
    if found is None:
        return None
    values, interpolation = found
    if interpolation in (UsdGeom.Tokens.vertex, UsdGeom.Tokens.varying) and len(values) == n_points:
        return values[indices]
    if interpolation == UsdGeom.Tokens.faceVarying and len(values) == len(indices):
        return values
    return None
