"""Reading bound materials back for rendering: per-face colours, texture files and coordinates.

For each mesh the material bound to every face is resolved the way USD resolves it
(``UsdShade.MaterialBindingAPI.ComputeBoundMaterial`` on the mesh and on its ``materialBind``
subsets). A ``UsdPreviewSurface`` whose ``diffuseColor`` comes from a ``UsdUVTexture`` makes
the face textured: the texture's resolved file, its ``scale`` (the face colour the texture
is multiplied by) and its ``st`` chain (a ``UsdPrimvarReader_float2``, optionally through a
``UsdTransform2d``) evaluated on the mesh's primvar. A constant ``diffuseColor`` gives the
face colour; faces without a material, or with a surface of another kind, keep their
``displayColor``. Works for stages authored by any tool, not only :mod:`sgdata.usd.materials`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from pxr import Sdf, UsdGeom, UsdShade

from sgdata.errors import UsdError

__all__ = ["FaceMaterials", "MaterialReader"]


@dataclass(frozen=True)
class FaceMaterials:
    """What the bound materials say about the triangles of one mesh."""

    colors: np.ndarray  # (T, 3) float32 face colours (displayColor where no material says)
    face_texture: np.ndarray  # (T,) int32 index into files, -1 untextured
    uvs: np.ndarray  # (T, 3, 2) float32 texture coordinates after the st transform
    files: tuple[str, ...]  # resolved texture files


@dataclass(frozen=True)
class _Surface:
    """One material as the renderer needs it."""

    color: tuple[float, float, float] | None  # None: keep the face's displayColor
    file: str | None = None  # resolved texture file; None: untextured
    primvar: str = "st"
    scale: tuple[float, float] = (1.0, 1.0)
    rotation: float = 0.0  # degrees, counter-clockwise
    translation: tuple[float, float] = (0.0, 0.0)


_PLAIN = _Surface(color=None)


class MaterialReader:
    """Resolves the materials of one stage's meshes, each material once."""

    def __init__(self) -> None:
        self._surfaces: dict[Sdf.Path, _Surface] = {}

    def faces(
        self,
        mesh: UsdGeom.Mesh,
        colors: np.ndarray,
        face_of: np.ndarray,
        corners: np.ndarray,
        indices: np.ndarray,
    ) -> FaceMaterials | None:
        """The bound materials of ``mesh``'s triangles, or None when no face has one.

        Args:
            mesh: the mesh.
            colors: (T, 3) the triangles' displayColor colours.
            face_of: (T,) the source face of each triangle.
            corners: (T, 3) each triangle's corners as indices into the face-vertex list.
            indices: the mesh's faceVertexIndices.

        Raises:
            UsdError: a bound texture's file does not resolve to an existing file.
        """
        n_faces = int(face_of.max()) + 1 if len(face_of) else 0
        surface_of_face: list[_Surface | None] = [None] * n_faces
        prim = mesh.GetPrim()
        whole = self._bound(prim)
        if whole is not None:
            surface_of_face = [whole] * n_faces
        for subset in UsdShade.MaterialBindingAPI(prim).GetMaterialBindSubsets():
            surface = self._bound(subset.GetPrim())
            for face in subset.GetIndicesAttr().Get() or []:
                if 0 <= face < n_faces and surface is not None:
                    surface_of_face[face] = surface
        if all(s is None or s is _PLAIN for s in surface_of_face):
            return None
        return self._evaluate(mesh, colors, face_of, corners, indices, surface_of_face)

    def _evaluate(
        self,
        mesh: UsdGeom.Mesh,
        colors: np.ndarray,
        face_of: np.ndarray,
        corners: np.ndarray,
        indices: np.ndarray,
        surface_of_face: list[_Surface | None],
    ) -> FaceMaterials:
        out_colors = np.array(colors, dtype=np.float32, copy=True)
        which = np.full(len(face_of), -1, dtype=np.int32)
        uvs = np.zeros((len(face_of), 3, 2), dtype=np.float32)
        files: dict[str, int] = {}
        distinct = {id(s): s for s in surface_of_face if s is not None}
        codes = {key: k for k, key in enumerate(distinct)}
        face_code = np.array(
            [-1 if s is None else codes[id(s)] for s in surface_of_face], dtype=np.int64
        )
        tri_code = face_code[face_of] if len(face_of) else face_code[:0]
        for key, surface in distinct.items():
            pick = tri_code == codes[key]
            if not pick.any():
                continue
            if surface.color is not None:
                out_colors[pick] = surface.color
            if surface.file is None:
                continue
            st = _primvar_corners(mesh, surface.primvar, face_of, corners, indices)
            if st is None:
                continue  # no coordinates: drawn untextured in the texture's colour
            which[pick] = files.setdefault(surface.file, len(files))
            uvs[pick] = _transform(st[pick], surface)
        return FaceMaterials(out_colors, which, uvs, tuple(files))

    def _bound(self, prim: object) -> _Surface | None:
        material, _ = UsdShade.MaterialBindingAPI(prim).ComputeBoundMaterial()
        if not material:
            return None
        path = material.GetPath()
        if path not in self._surfaces:
            self._surfaces[path] = _surface(material)
        return self._surfaces[path]


def _surface(material: UsdShade.Material) -> _Surface:
    shader = _source_shader(material.GetSurfaceOutput()) if material.GetSurfaceOutput() else None
    if shader is None or shader.GetShaderId() != "UsdPreviewSurface":
        return _PLAIN
    diffuse = shader.GetInput("diffuseColor")
    if not diffuse:
        return _PLAIN
    texture = _source_shader(diffuse)
    if texture is None:
        value = _value(diffuse)
        return _Surface(color=_rgb(value)) if value is not None else _PLAIN
    if texture.GetShaderId() != "UsdUVTexture":
        return _PLAIN
    asset = _value(texture.GetInput("file"))
    scale = _value(texture.GetInput("scale"))
    color = _rgb(scale) if scale is not None else (1.0, 1.0, 1.0)
    if not isinstance(asset, Sdf.AssetPath) or not asset.path:
        return _Surface(color=color)
    if not asset.resolvedPath:
        raise UsdError(
            f"{material.GetPath()}: texture {asset.path!r} not found (resolved relative to the "
            "layer that names it); restore the file or regenerate the room"
        )
    surface = _Surface(color=color, file=asset.resolvedPath)
    st = _source_shader(texture.GetInput("st"))
    transform = None
    if st is not None and st.GetShaderId() == "UsdTransform2d":
        transform = st
        st = _source_shader(st.GetInput("in"))
    primvar = "st"
    if st is not None and st.GetShaderId().startswith("UsdPrimvarReader"):
        name = _value(st.GetInput("varname"))
        primvar = str(name) if name else "st"
    scale2, rotation, shift = (1.0, 1.0), 0.0, (0.0, 0.0)
    if transform is not None:
        s = _value(transform.GetInput("scale"))
        r = _value(transform.GetInput("rotation"))
        t = _value(transform.GetInput("translation"))
        scale2 = (float(s[0]), float(s[1])) if s is not None else scale2
        rotation = float(r) if r is not None else 0.0
        shift = (float(t[0]), float(t[1])) if t is not None else shift
    return _Surface(surface.color, surface.file, primvar, scale2, rotation, shift)


def _source_shader(port: object) -> UsdShade.Shader | None:
    """The shader feeding an input or output through its (first) connection, if any."""
    if not port or not port.HasConnectedSource():
        return None
    sources, _ = port.GetConnectedSources()
    if not sources:
        return None
    prim = sources[0].source.GetPrim()
    return UsdShade.Shader(prim) if prim.IsA(UsdShade.Shader) else None


def _value(port: object) -> object:
    """An input's value, following connections to material interface inputs."""
    if not port:
        return None
    for attr in port.GetValueProducingAttributes():
        value = attr.Get()
        if value is not None:
            return value
    return None


def _rgb(value: object) -> tuple[float, float, float]:
    v = list(value)  # type: ignore[call-overload]
    return (float(v[0]), float(v[1]), float(v[2]))


def _primvar_corners(
    mesh: UsdGeom.Mesh,
    name: str,
    face_of: np.ndarray,
    corners: np.ndarray,
    indices: np.ndarray,
) -> np.ndarray | None:
    """(T, 3, 2) values of a float2 primvar at each triangle corner, or None if unusable."""
    primvar = UsdGeom.PrimvarsAPI(mesh).GetPrimvar(name)
    if not primvar or not primvar.HasValue():
        return None
    values = primvar.ComputeFlattened()
    if values is None or len(values) == 0:
        return None
    data = np.array(values, dtype=np.float64).reshape(len(values), -1)[:, :2]
    interpolation = primvar.GetInterpolation()
    if interpolation == UsdGeom.Tokens.faceVarying and len(data) == len(indices):
        return data[corners]
    if interpolation in (UsdGeom.Tokens.vertex, UsdGeom.Tokens.varying):
        if len(indices) and int(indices.max()) < len(data):
            return data[indices[corners]]
        return None
    if interpolation == UsdGeom.Tokens.uniform and len(face_of) and int(face_of.max()) < len(data):
        return np.repeat(data[face_of][:, None, :], 3, axis=1)
    if interpolation == UsdGeom.Tokens.constant:
        return np.broadcast_to(data[0], (len(face_of), 3, 2)).copy()
    return None


def _transform(st: np.ndarray, surface: _Surface) -> np.ndarray:
    """UsdTransform2d: in * scale, rotated counter-clockwise, plus translation."""
    out = st * np.asarray(surface.scale)
    if surface.rotation:
        a = math.radians(surface.rotation)
        c, s = math.cos(a), math.sin(a)
        out = np.stack([c * out[..., 0] - s * out[..., 1], s * out[..., 0] + c * out[..., 1]], -1)
    return (out + np.asarray(surface.translation)).astype(np.float32)
