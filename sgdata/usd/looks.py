"""Looks in USD: the attributes that record them, and a layout's appearance as overrides.

A room written with an appearance carries on each object prim ``sgdata:look:texture``
(token, its body's texture kind), ``sgdata:look:variant`` (int) and ``sgdata:look:tint``
(color3f), and on each ``Geom`` an indexed, uniform ``primvars:displayColor``: one value per
part (the distinct colours of the recipe), one index per face. A layout that draws its own
appearance (:func:`override_look`, :func:`override_light`) then overrides, per low- and
high-dynamic object, the look attributes, the part colours (the displayColor *values*, not
the per-face indices) and, in a textured room, the ``material:binding`` of every body part to a
tinted material it defines under ``/Room/Looks``; on ``/Room`` it sets
``sgdata:light:intensity`` (float, scale of the renderer's default lights) and
``sgdata:light:colorTemperature`` (float, Kelvin). Static objects and the structure are never
overridden. :mod:`sgdata.usd.geometry` reads all of it back for the renderer.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from pxr import Gf, Sdf, Usd, UsdGeom, UsdShade

from sgdata.scene_files import textures_dir
from sgdata.usd.materials import (
    IMAGE_PREFIX,
    LOOKS,
    PART_PREFIX,
    bind_material,
    define_base_materials,
    define_image_material,
    define_tinted_material,
    image_material_path,
    set_parts,
    set_st,
    tinted_material_path,
    write_image_file,
    write_texture_files,
)
from sgdata.usd.prims import (
    LIGHT_INTENSITY,
    LIGHT_TEMPERATURE,
    LOOK_TEXTURE,
    LOOK_TINT,
    LOOK_VARIANT,
    OBJECTS,
    ROOT,
)
from sgdata.usd.stage import open_stage
from sgdata.usd.stage_frame import room_prim
from sgdata.world.appearance import AppearanceConfig, LayoutAppearance, Look, room_looks, tinted
from sgdata.world.materials import part_texture
from sgdata.world.scene import Room, SceneObject
from sgdata.world.shapes.base import PartTexture
from sgdata.world.shapes.uvs import box_uvs

__all__ = [
    "ObjectParts",
    "RoomDresser",
    "RoomParts",
    "define_layout_materials",
    "override_light",
    "override_look",
    "read_room_parts",
]

_DISPLAY_COLOR = "primvars:displayColor"


@dataclass(frozen=True)
class ObjectParts:
    """An object's parts as its room stage holds them."""

    prim: Sdf.Path
    colors: tuple[tuple[float, float, float], ...]  # base colour of each part (displayColor values)
    kinds: tuple[str, ...]  # texture kind of each part
    body: tuple[bool, ...]  # whether the part takes the object's look


@dataclass(frozen=True)
class RoomParts:
    """What a layout needs from ``room.usda`` to give objects new looks."""

    textured: bool  # the room has materials (a /Room/Looks scope)
    objects: dict[int, ObjectParts]  # by instance, objects whose Geom has an indexed colour
    materials: frozenset[Sdf.Path]  # materials room.usda defines
    room: Sdf.Path = ROOT  # the prim that carries the light (a room authored elsewhere: its own)


def read_room_parts(path: Path) -> RoomParts:
    """The parts of every object of a room written with an appearance (none for a room
    written without one, or authored elsewhere: such a layout only changes the light).

    Raises:
        UsdError: the file is missing, unreadable or does not compose.
    """
    stage = open_stage(path)
    looks = stage.GetPrimAtPath(LOOKS)
    materials = frozenset(c.GetPath() for c in looks.GetChildren()) if looks else frozenset()
    group = stage.GetPrimAtPath(OBJECTS)
    objects = {}
    for prim in group.GetChildren() if group else []:
        instance = prim.GetAttribute("sgdata:instance").Get()
        mesh = UsdGeom.Mesh(prim.GetChild("Geom"))
        primvar = UsdGeom.PrimvarsAPI(mesh).GetPrimvar("displayColor") if mesh else None
        body = prim.GetAttribute(LOOK_TEXTURE).Get() if prim.HasAttribute(LOOK_TEXTURE) else None
        if instance is None or not body or not primvar or not primvar.IsIndexed():
            continue  # written without an appearance (or elsewhere): its look is its own
        body = str(body)
        colors = tuple(tuple(float(c) for c in v) for v in primvar.Get())
        sorted_parts = [part_texture(c, body) for c in colors]
        for k in _image_parts(mesh, len(colors)):  # a mesh file's own texture: left alone
            sorted_parts[k] = ("image", False)
        objects[int(instance)] = ObjectParts(
            prim.GetPath(),
            colors,  # type: ignore[arg-type]
            tuple(k for k, _ in sorted_parts),
            tuple(b for _, b in sorted_parts),
        )
    root = room_prim(stage)
    return RoomParts(bool(looks), objects, materials, root.GetPath() if root else ROOT)


def _image_parts(mesh: UsdGeom.Mesh, count: int) -> list[int]:
    """The parts of ``mesh`` bound to a mesh file's image texture material."""
    found = []
    for k in range(count):
        subset = mesh.GetPrim().GetChild(f"{PART_PREFIX}{k}")
        rel = subset.GetRelationship(UsdShade.Tokens.materialBinding) if subset else None
        targets = rel.GetTargets() if rel else []
        if targets and targets[0].name.startswith(IMAGE_PREFIX):
            found.append(k)
    return found


def override_light(layer: Sdf.Layer, parts: RoomParts, appearance: LayoutAppearance) -> None:
    """Set the layout's light on the room prim (``/Room``) in ``layer``."""
    spec = Sdf.CreatePrimInLayer(layer, parts.room)
    for name, value in (
        (LIGHT_INTENSITY, appearance.light_intensity),
        (LIGHT_TEMPERATURE, appearance.color_temperature),
    ):
        attr = Sdf.AttributeSpec(spec, name, Sdf.ValueTypeNames.Float, Sdf.VariabilityVarying, True)
        attr.default = float(value)


def override_look(
    layer: Sdf.Layer, parts: RoomParts, instance: int, look: Look, materials: dict
) -> None:
    """Give object ``instance`` its layout look in ``layer``: look attributes, part colours
    and, in a textured room, the binding of each body part to its tinted material (collected
    in ``materials``, path -> (kind, variant, colour), for :func:`define_layout_materials`).
    Objects the room holds no parts for are left alone."""
    obj = parts.objects.get(instance)
    if obj is None:
        return
    spec = Sdf.CreatePrimInLayer(layer, obj.prim)
    variant = Sdf.AttributeSpec(
        spec, LOOK_VARIANT, Sdf.ValueTypeNames.Int, Sdf.VariabilityVarying, True
    )
    variant.default = int(look.variant)
    tint = Sdf.AttributeSpec(
        spec, LOOK_TINT, Sdf.ValueTypeNames.Color3f, Sdf.VariabilityVarying, True
    )
    tint.default = Gf.Vec3f(*look.tint)
    colors = [
        tinted(c, look.tint) if body else c for c, body in zip(obj.colors, obj.body, strict=True)
    ]
    geom = Sdf.CreatePrimInLayer(layer, obj.prim.AppendChild("Geom"))
    values = Sdf.AttributeSpec(geom, _DISPLAY_COLOR, Sdf.ValueTypeNames.Color3fArray)
    values.default = [Gf.Vec3f(*c) for c in np.asarray(colors, np.float32).tolist()]
    if not parts.textured:
        return
    for k, (kind, body, color) in enumerate(zip(obj.kinds, obj.body, colors, strict=True)):
        if not body:
            continue
        path = tinted_material_path(kind, look.variant, color)
        if path not in parts.materials:
            materials.setdefault(path, (kind, look.variant, color))
        part = Sdf.CreatePrimInLayer(
            layer, obj.prim.AppendChild("Geom").AppendChild(f"{PART_PREFIX}{k}")
        )
        rel = Sdf.RelationshipSpec(part, UsdShade.Tokens.materialBinding, False)
        rel.targetPathList.ClearEditsAndMakeExplicit()
        rel.targetPathList.explicitItems = [path]


def define_layout_materials(layer: Sdf.Layer, materials: dict) -> None:
    """Define the tinted materials :func:`override_look` collected, in the order collected."""
    for kind, variant, color in materials.values():
        define_tinted_material(layer, kind, variant, color)


class RoomDresser:
    """Dresses a room stage being written (:func:`sgdata.usd.room_io.write_room`): records each
    object's base look and, with textures, adds texture coordinates, part subsets, bindings
    and the materials they use; :meth:`finish` defines ``/Room/Looks`` last."""

    def __init__(
        self,
        stage: Usd.Stage,
        room: Room,
        path: Path,
        appearance: AppearanceConfig,
        textures: Path | None,
    ) -> None:
        self.stage, self.path, self.appearance = stage, path, appearance
        self.textures = textures if textures is not None else textures_dir(path.parent)
        self.looks = room_looks(room)
        self._materials: dict[Sdf.Path, tuple[str, int, tuple[float, float, float]]] = {}
        self._images: dict[Sdf.Path, tuple[str, bytes, tuple[float, float, float]]] = {}

    @property
    def textured(self) -> bool:
        """Whether the room is dressed in textured materials."""
        return bool(self.appearance.textures)

    def structure(
        self,
        name: str,
        mesh: UsdGeom.Mesh,
        vertices: np.ndarray,
        faces: np.ndarray,
        color: tuple[float, ...],
    ) -> None:
        """Texture a structure mesh (world-space coordinates: one texture runs across walls)."""
        if not self.appearance.textures:
            return
        look = self.looks.structure[name]
        set_st(mesh, _rounded_uvs(vertices, faces))
        bind_material(mesh.GetPrim(), self._material(look.texture, look.variant, color))

    def object(
        self,
        prim: Usd.Prim,
        obj: SceneObject,
        mesh: UsdGeom.Mesh,
        vertices: np.ndarray,
        faces: np.ndarray,
        parts: np.ndarray,
        images: tuple | None = None,
    ) -> None:
        """Record an object's look; with textures, bind each of its parts (displayColor values):
        a part with a mesh file's image texture (``images``: each face's index into the
        textures, corner st, the textures; see :class:`sgdata.usd.room_io.TexturedGeometry`)
        to that image on the file's UVs, the others to their procedural texture."""
        look = self.looks.objects[obj.instance]
        prim.CreateAttribute(LOOK_TEXTURE, Sdf.ValueTypeNames.Token, custom=True).Set(look.texture)
        prim.CreateAttribute(LOOK_VARIANT, Sdf.ValueTypeNames.Int, custom=True).Set(look.variant)
        prim.CreateAttribute(LOOK_TINT, Sdf.ValueTypeNames.Color3f, custom=True).Set(
            Gf.Vec3f(*look.tint)
        )
        if not self.appearance.textures:
            return
        colors = UsdGeom.PrimvarsAPI(mesh).GetPrimvar("displayColor").Get()
        st = _rounded_uvs(vertices, faces)
        image_of_part = np.full(len(colors), -1)
        if images is not None:
            face_image, uvs, textures = images
            textured = np.asarray(face_image) >= 0
            st[textured] = np.asarray(uvs, np.float32)[textured]
            image_of_part[np.asarray(parts)[textured]] = np.asarray(face_image)[textured]
        materials = []
        for k, value in enumerate(colors):
            color = (float(value[0]), float(value[1]), float(value[2]))
            if image_of_part[k] >= 0:
                materials.append(self._image(textures[int(image_of_part[k])]))
                continue
            kind, body = part_texture(color, look.texture)
            materials.append(self._material(kind, look.variant if body else 0, color))
        set_st(mesh, st)
        set_parts(mesh, parts, materials)

    def finish(self) -> None:
        """Write the texture files and define the base and tinted materials under /Room/Looks."""
        if not self.appearance.textures:
            return
        size = self.appearance.texture_size
        write_texture_files(self.textures, size)
        define_base_materials(self.stage, self.path, self.textures, size)
        define_layout_materials(self.stage.GetRootLayer(), self._materials)
        relative = Path(os.path.relpath(self.textures, self.path.parent)).as_posix()
        for path, (name, data, scale) in self._images.items():
            write_image_file(self.textures, name, data)
            define_image_material(self.stage, path, f"{relative}/{name}", scale)

    def _image(self, texture: PartTexture) -> Sdf.Path:
        scale = tuple(float(c) for c in texture.scale)
        path = image_material_path(texture.name, scale)  # type: ignore[arg-type]
        self._images.setdefault(path, (texture.name, texture.png, scale))  # type: ignore[arg-type]
        return path

    def _material(self, kind: str, variant: int, color: tuple[float, ...]) -> Sdf.Path:
        rgb = (float(color[0]), float(color[1]), float(color[2]))
        path = tinted_material_path(kind, variant, rgb)
        self._materials.setdefault(path, (kind, variant, rgb))
        return path


def _rounded_uvs(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Box-projected st in metres, to the millimetre (below a texel of every texture; shorter
    text and more shared values)."""
    return np.round(box_uvs(vertices, faces), 3)
