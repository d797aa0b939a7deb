"""Materials of textured rooms: texture files, UsdShade networks, part subsets and bindings.

The on-disk contract of a textured ``room.usda`` (see also :mod:`sgdata.usd.room_io`)::

    /Room/Looks                               Scope
    /Room/Looks/<kind>_<variant>              Material, one per texture image; inputs:tint
                                              (float4, (1, 1, 1, 1)), outputs:surface
        Surface    UsdPreviewSurface          diffuseColor <- Texture.outputs:rgb, roughness
        Texture    UsdUVTexture               file @../textures/<kind>_<variant>_<size>px.png@,
                                              sourceColorSpace sRGB, wrapS/T repeat,
                                              st <- Transform, scale <- the material's tint
        Transform  UsdTransform2d             in <- Reader, scale (1 / tile, 1 / tile)
        Reader     UsdPrimvarReader_float2    varname "st"
    /Room/Looks/<kind>_<variant>_<colour>     Material specializing its base material with
                                              inputs:tint = (r, g, b, 1): a surface's colour
    <mesh>                                    primvars:st (texCoord2f[], faceVarying, metres of
                                              the mesh's frame), MaterialBindingAPI
    /Room/Structure/<Floor|Walls|Ceiling>     material:binding -> its tinted material
    /Room/Objects/<prim>/Geom/part_<k>        GeomSubset (face, familyName materialBind): the
                                              faces of the k-th displayColor value, bound to
                                              their tinted material

A face's colour is its texture times its tint, in linear RGB, exactly what
``primvars:displayColor`` holds for it (renderers without materials see the flat colours).

A mesh file's own image textures (a glTF ``baseColorTexture``, an MTL ``map_Kd``) are copied
into the same textures folder as ``mesh_<sha256[:16]>.png`` and bound to their faces' parts::

    /Room/Looks/image_<sha256[:16]>_<colour>  Material; Surface (UsdPreviewSurface,
                                              diffuseColor <- Texture.outputs:rgb), Texture
                                              (UsdUVTexture, the file, sRGB, repeat, scale =
                                              the file's base colour, st <- Reader), Reader
                                              (UsdPrimvarReader_float2 "st", the file's UVs)

Those faces' ``primvars:st`` are the file's UVs and their displayColor the texture's colour
at each face's centre times the base colour (the flat fallback).
Texture images are shared by every room of a folder: :func:`write_texture_files` writes the
ones missing and leaves identical ones alone.
"""

from __future__ import annotations

import hashlib
import io
import os
from functools import cache
from pathlib import Path

import numpy as np
from PIL import Image
from pxr import Gf, Sdf, Usd, UsdGeom, UsdShade, Vt

from sgdata.errors import UsdError
from sgdata.fileio import atomic_write_bytes
from sgdata.usd.prims import LOOKS
from sgdata.world.textures import TEXTURE_KINDS, texture_file_name, texture_image

__all__ = [
    "IMAGE_PREFIX",
    "PART_FAMILY",
    "PART_PREFIX",
    "base_material_path",
    "bind_material",
    "define_base_materials",
    "define_image_material",
    "image_material_path",
    "define_tinted_material",
    "set_parts",
    "set_st",
    "texture_png",
    "tinted_material_path",
    "write_image_file",
    "write_texture_files",
]

PART_FAMILY = "materialBind"  # UsdShade's family name for per-face material bindings
PART_PREFIX = "part_"  # subset k of a mesh holds the faces of its k-th displayColor value
_TINT = "tint"
IMAGE_PREFIX = "image_"  # materials of a mesh file's own image textures


@cache
def texture_png(kind: str, variant: int, size: int) -> bytes:
    """The PNG bytes of a texture image, made once per process (fixed encoder settings)."""
    buffer = io.BytesIO()
    Image.fromarray(np.ascontiguousarray(texture_image(kind, variant, size)), mode="RGB").save(
        buffer, format="PNG", optimize=False, compress_level=6
    )
    return buffer.getvalue()


def write_texture_files(directory: Path, size: int) -> list[Path]:
    """Write every texture image (all kinds and variants) of ``size`` into ``directory``.

    A file already there with the same bytes is left alone, so rooms written one after the
    other (or by parallel workers) share one set of files.

    Raises:
        UsdError: the folder or a file cannot be written.
    """
    paths = []
    for kind, spec in TEXTURE_KINDS.items():
        for variant in range(spec.variants):
            path = Path(directory) / texture_file_name(kind, variant, size)
            data = texture_png(kind, variant, size)
            try:
                if not (
                    path.is_file()
                    and path.stat().st_size == len(data)
                    and path.read_bytes() == data
                ):
                    atomic_write_bytes(path, data)
            except OSError as exc:
                raise UsdError(f"{path}: cannot write texture ({exc.strerror or exc})") from None
            paths.append(path)
    return paths


def write_image_file(directory: Path, name: str, data: bytes) -> Path:
    """Write a mesh file's texture image (PNG bytes) as ``directory/name``, unless the same
    bytes are there already.

    Raises:
        UsdError: the file cannot be written.
    """
    path = Path(directory) / name
    try:
        if not (path.is_file() and path.stat().st_size == len(data) and path.read_bytes() == data):
            atomic_write_bytes(path, data)
    except OSError as exc:
        raise UsdError(f"{path}: cannot write texture ({exc.strerror or exc})") from None
    return path


def image_material_path(name: str, scale: tuple[float, float, float]) -> Sdf.Path:
    """``/Room/Looks/image_<image>_<8 hex digits>``: image file ``name`` times ``scale``."""
    digest = hashlib.blake2b(np.asarray(scale, np.float32).tobytes(), digest_size=4).hexdigest()
    stem = Path(name).stem.removeprefix("mesh_")
    return LOOKS.AppendChild(f"{IMAGE_PREFIX}{stem}_{digest}")


def define_image_material(
    stage: Usd.Stage, path: Sdf.Path, file: str, scale: tuple[float, float, float]
) -> None:
    """Define the material of a mesh file's image texture at ``path``: ``file`` (relative to
    the room's folder) read on the mesh's ``st`` as is, times ``scale``."""
    material = UsdShade.Material.Define(stage, path)
    reader = _shader(stage, path, "Reader", "UsdPrimvarReader_float2")
    reader.CreateInput("varname", Sdf.ValueTypeNames.String).Set("st")
    st = reader.CreateOutput("result", Sdf.ValueTypeNames.Float2)
    texture = _shader(stage, path, "Texture", "UsdUVTexture")
    texture.CreateInput("file", Sdf.ValueTypeNames.Asset).Set(Sdf.AssetPath(file))
    texture.CreateInput("sourceColorSpace", Sdf.ValueTypeNames.Token).Set("sRGB")
    texture.CreateInput("wrapS", Sdf.ValueTypeNames.Token).Set("repeat")
    texture.CreateInput("wrapT", Sdf.ValueTypeNames.Token).Set("repeat")
    texture.CreateInput("st", Sdf.ValueTypeNames.Float2).ConnectToSource(st)
    r, g, b = (float(np.float32(c)) for c in scale)
    texture.CreateInput("scale", Sdf.ValueTypeNames.Float4).Set(Gf.Vec4f(r, g, b, 1.0))
    rgb = texture.CreateOutput("rgb", Sdf.ValueTypeNames.Float3)
    surface = _shader(stage, path, "Surface", "UsdPreviewSurface")
    surface.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).ConnectToSource(rgb)
    surface.CreateInput("roughness", Sdf.ValueTypeNames.Float).Set(0.5)
    surface.CreateInput("metallic", Sdf.ValueTypeNames.Float).Set(0.0)
    out = surface.CreateOutput("surface", Sdf.ValueTypeNames.Token)
    material.CreateSurfaceOutput().ConnectToSource(out)


def base_material_path(kind: str, variant: int) -> Sdf.Path:
    """``/Room/Looks/<kind>_<variant>``: the material of one texture image, untinted."""
    return LOOKS.AppendChild(f"{kind}_{variant}")


def tinted_material_path(kind: str, variant: int, color: tuple[float, float, float]) -> Sdf.Path:
    """``/Room/Looks/<kind>_<variant>_<8 hex digits>``, named by the float32 bytes of ``color``
    (equal colours share a material, in a room and in its layouts)."""
    digest = hashlib.blake2b(np.asarray(color, np.float32).tobytes(), digest_size=4).hexdigest()
    return LOOKS.AppendChild(f"{kind}_{variant}_{digest}")


def define_base_materials(stage: Usd.Stage, room_path: Path, textures: Path, size: int) -> None:
    """Define ``/Room/Looks`` and one base material per texture image of ``size`` in
    ``textures`` (referred to relative to ``room_path``'s folder)."""
    UsdGeom.Scope.Define(stage, LOOKS)
    relative = Path(os.path.relpath(textures, Path(room_path).parent)).as_posix()
    for kind, spec in TEXTURE_KINDS.items():
        for variant in range(spec.variants):
            path = base_material_path(kind, variant)
            material = UsdShade.Material.Define(stage, path)
            tint = material.CreateInput(_TINT, Sdf.ValueTypeNames.Float4)
            tint.Set(Gf.Vec4f(1.0, 1.0, 1.0, 1.0))
            reader = _shader(stage, path, "Reader", "UsdPrimvarReader_float2")
            reader.CreateInput("varname", Sdf.ValueTypeNames.String).Set("st")
            st = reader.CreateOutput("result", Sdf.ValueTypeNames.Float2)
            transform = _shader(stage, path, "Transform", "UsdTransform2d")
            transform.CreateInput("in", Sdf.ValueTypeNames.Float2).ConnectToSource(st)
            scale = 1.0 / spec.tile
            transform.CreateInput("scale", Sdf.ValueTypeNames.Float2).Set(Gf.Vec2f(scale, scale))
            uv = transform.CreateOutput("result", Sdf.ValueTypeNames.Float2)
            texture = _shader(stage, path, "Texture", "UsdUVTexture")
            file = f"{relative}/{texture_file_name(kind, variant, size)}"
            texture.CreateInput("file", Sdf.ValueTypeNames.Asset).Set(Sdf.AssetPath(file))
            texture.CreateInput("sourceColorSpace", Sdf.ValueTypeNames.Token).Set("sRGB")
            texture.CreateInput("wrapS", Sdf.ValueTypeNames.Token).Set("repeat")
            texture.CreateInput("wrapT", Sdf.ValueTypeNames.Token).Set("repeat")
            texture.CreateInput("st", Sdf.ValueTypeNames.Float2).ConnectToSource(uv)
            texture.CreateInput("scale", Sdf.ValueTypeNames.Float4).ConnectToSource(tint)
            rgb = texture.CreateOutput("rgb", Sdf.ValueTypeNames.Float3)
            surface = _shader(stage, path, "Surface", "UsdPreviewSurface")
            surface.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).ConnectToSource(rgb)
            surface.CreateInput("roughness", Sdf.ValueTypeNames.Float).Set(spec.roughness)
            surface.CreateInput("metallic", Sdf.ValueTypeNames.Float).Set(0.0)
            out = surface.CreateOutput("surface", Sdf.ValueTypeNames.Token)
            material.CreateSurfaceOutput().ConnectToSource(out)


def _shader(stage: Usd.Stage, material: Sdf.Path, name: str, shader_id: str) -> UsdShade.Shader:
    shader = UsdShade.Shader.Define(stage, material.AppendChild(name))
    shader.CreateIdAttr(shader_id)
    return shader


def define_tinted_material(
    layer: Sdf.Layer, kind: str, variant: int, color: tuple[float, float, float]
) -> Sdf.Path:
    """Define (once per layer) the material of texture ``kind``/``variant`` tinted ``color``:
    a Material specializing its base material, setting only ``inputs:tint``."""
    path = tinted_material_path(kind, variant, color)
    if layer.GetPrimAtPath(path):
        return path
    if not layer.GetPrimAtPath(LOOKS):
        Sdf.CreatePrimInLayer(layer, LOOKS)  # an over: the Scope is defined by room.usda
    spec = Sdf.PrimSpec(layer.GetPrimAtPath(LOOKS), path.name, Sdf.SpecifierDef, "Material")
    spec.specializesList.Prepend(base_material_path(kind, variant))
    tint = Sdf.AttributeSpec(spec, f"inputs:{_TINT}", Sdf.ValueTypeNames.Float4)
    r, g, b = (float(np.float32(c)) for c in color)
    tint.default = Gf.Vec4f(r, g, b, 1.0)
    return path


def bind_material(prim: Usd.Prim, material: Sdf.Path) -> None:
    """Bind ``material`` to ``prim`` (a mesh or a subset), applying MaterialBindingAPI.

    The material need not exist yet (materials are defined last, under ``/Room/Looks``)."""
    UsdShade.MaterialBindingAPI.Apply(prim)
    rel = prim.CreateRelationship(UsdShade.Tokens.materialBinding, custom=False)
    rel.SetTargets([material])


def set_st(mesh: UsdGeom.Mesh, uvs: np.ndarray) -> None:
    """Author ``primvars:st`` (texCoord2f, faceVarying, indexed: each distinct coordinate once)
    from (F, 3, 2) corner coordinates of a triangle mesh (face-vertex order)."""
    corners = np.asarray(uvs, np.float32).reshape(-1, 2)
    if len(corners) != 3 * len(mesh.GetFaceVertexCountsAttr().Get() or []):
        raise UsdError(f"{mesh.GetPath()}: {len(corners)} st values for a triangle mesh")
    values, index = np.unique(corners, axis=0, return_inverse=True)
    primvar = UsdGeom.PrimvarsAPI(mesh).CreatePrimvar(
        "st", Sdf.ValueTypeNames.TexCoord2fArray, UsdGeom.Tokens.faceVarying
    )
    primvar.Set(Vt.Vec2fArray.FromNumpy(np.ascontiguousarray(values)))
    primvar.SetIndices(Vt.IntArray.FromNumpy(index.reshape(-1).astype(np.int32)))


def set_parts(
    mesh: UsdGeom.Mesh, part_of_face: np.ndarray, materials: list[Sdf.Path]
) -> list[Usd.Prim]:
    """Subsets ``part_<k>`` of the faces whose part is k, each bound to ``materials[k]``; the
    family is a partition (every face in exactly one part)."""
    part_of_face = np.asarray(part_of_face)
    subsets = []
    for k, material in enumerate(materials):
        faces = np.flatnonzero(part_of_face == k).astype(np.int32)
        subset = UsdGeom.Subset.Define(
            mesh.GetPrim().GetStage(), mesh.GetPath().AppendChild(f"{PART_PREFIX}{k}")
        )
        subset.CreateElementTypeAttr(UsdGeom.Tokens.face)
        subset.CreateFamilyNameAttr(PART_FAMILY)
        subset.CreateIndicesAttr(Vt.IntArray.FromNumpy(faces))
        bind_material(subset.GetPrim(), material)
        subsets.append(subset.GetPrim())
    UsdGeom.Subset.SetFamilyType(mesh, PART_FAMILY, UsdGeom.Tokens.partition)
    UsdShade.MaterialBindingAPI.Apply(mesh.GetPrim())
    return subsets
