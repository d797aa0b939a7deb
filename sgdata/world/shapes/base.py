"""Recipe registry and the types recipes return, plus primitive helpers shared by recipes."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import trimesh

__all__ = [
    "DARK",
    "GLASS",
    "METAL",
    "RECIPES",
    "WHITE",
    "Attachment",
    "Color",
    "Part",
    "PartTexture",
    "Recipe",
    "ShapeBuild",
    "Size",
    "Surface",
    "box",
    "build_shape",
    "cone",
    "cylinder",
    "elliptic_cylinder",
    "frustum",
    "hollow_box",
    "merged_mesh",
    "merged_textures",
    "open_cylinder",
    "recipe",
    "rotated_box",
    "shade",
    "slab",
    "sphere",
    "tube",
]

Size = tuple[float, float, float]
Color = tuple[float, float, float]

# Secondary colours recipes share for parts whose colour the palette does not choose.
METAL: Color = (0.72, 0.73, 0.75)
DARK: Color = (0.06, 0.06, 0.07)
WHITE: Color = (0.92, 0.92, 0.9)
GLASS: Color = (0.55, 0.72, 0.85)


@dataclass(frozen=True, eq=False)
class PartTexture:
    """An image texture on a part's faces (a mesh file's own; recipes have none)."""

    name: str  # file name in a scene's textures folder (by the PNG's sha256)
    png: bytes  # the image, PNG-encoded
    uvs: np.ndarray  # (F, 3, 2) float32 corner coordinates of the part's faces (bottom-left)
    scale: Color  # the colour the image is multiplied by (the material's base colour)


@dataclass(frozen=True)
class Part:
    """One closed primitive mesh of a shape, in the local frame, with its colour (and, from a
    mesh file, its image texture: ``color`` is then what a renderer without textures draws)."""

    mesh: trimesh.Trimesh
    color: Color
    texture: PartTexture | None = None


@dataclass(frozen=True)
class Surface:
    """An axis-aligned rectangle in the local frame that other objects can rest on."""

    x0: float
    y0: float
    x1: float
    y1: float
    z: float  # height of the resting plane above the local origin
    clearance: float = math.inf  # free height above the plane (a shelf below another)
    inside: bool = False  # an inner surface (basin, bowl, shelf compartment): for `containers`


@dataclass(frozen=True)
class Attachment:
    """A part that becomes an object of its own, fixed to its owner (a shelf board, a basin)."""

    class_name: str
    size: Size
    x: float  # position of the part's local origin in the owner's local frame
    y: float
    z: float
    yaw: float = 0.0


@dataclass
class ShapeBuild:
    """What a recipe makes."""

    parts: list[Part]
    surfaces: list[Surface] = field(default_factory=list)
    attachments: list[Attachment] = field(default_factory=list)


Recipe = Callable[[Size, int, Color], ShapeBuild]
RECIPES: dict[str, Recipe] = {}


def recipe(name: str) -> Callable[[Recipe], Recipe]:
    """Register a recipe under ``name`` (the catalog's ``shape`` field)."""

    def register(fn: Recipe) -> Recipe:
        if name in RECIPES:
            raise ValueError(f"recipe {name!r} registered twice")
        RECIPES[name] = fn
        return fn

    return register


def build_shape(shape: str, size: Size, variant: int, color: Color) -> ShapeBuild:
    """Run the recipe ``shape``; ``variant`` is taken modulo nothing: recipes wrap it themselves."""
    return RECIPES[shape](size, variant, color)


# trimesh's unit box (its vertices and faces, in its order). ``trimesh.creation.box`` also
# hands the mesh its face normals, which the constructor checks against the faces: that check
# was a third of writing a room's USD, and no part's normals are ever read.
_UNIT_BOX = trimesh.creation.box()


def box(extents: Size, center: tuple[float, float, float], color: Color) -> Part:
    """An axis-aligned box part with the given full extents, centred at ``center`` (the
    vertices ``trimesh.creation.box(extents=extents)`` moved to ``center`` gives, exactly)."""
    vertices = _UNIT_BOX.vertices * np.asarray(extents, dtype=np.float64)
    mesh = trimesh.Trimesh(vertices=vertices, faces=_UNIT_BOX.faces.copy(), process=False)
    mesh.apply_translation(center)
    return Part(mesh, color)


def cylinder(
    radius: float,
    height: float,
    center: tuple[float, float, float],
    color: Color,
    *,
    axis: str = "z",
    sections: int = 16,
) -> Part:
    """A closed cylinder part along ``axis`` (x, y or z), centred at ``center``."""
    mesh = trimesh.creation.cylinder(radius=radius, height=height, sections=sections)
    if axis == "x":
        mesh.apply_transform(trimesh.transformations.rotation_matrix(math.pi / 2, [0, 1, 0]))
    elif axis == "y":
        mesh.apply_transform(trimesh.transformations.rotation_matrix(math.pi / 2, [1, 0, 0]))
    mesh.apply_translation(center)
    return Part(mesh, color)


def slab(lo: tuple[float, float, float], hi: tuple[float, float, float], color: Color) -> Part:
    """An axis-aligned box part spanning the corners ``lo`` to ``hi``."""
    extents = (hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2])
    center = ((lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2)
    return box(extents, center, color)


def rotated_box(
    extents: Size,
    center: tuple[float, float, float],
    color: Color,
    *,
    rx: float = 0.0,
    ry: float = 0.0,
    rz: float = 0.0,
) -> Part:
    """A box part turned by ``rx``, ``ry``, ``rz`` radians (applied in that order) about its
    centre, then moved to ``center``."""
    mesh = trimesh.creation.box(extents=extents)
    for angle, axis in ((rx, [1, 0, 0]), (ry, [0, 1, 0]), (rz, [0, 0, 1])):
        if angle:
            mesh.apply_transform(trimesh.transformations.rotation_matrix(angle, axis))
    mesh.apply_translation(center)
    return Part(mesh, color)


def sphere(
    radius: float,
    center: tuple[float, float, float],
    color: Color,
    *,
    scale: tuple[float, float, float] = (1.0, 1.0, 1.0),
    subdivisions: int = 2,
) -> Part:
    """A closed icosphere part, stretched by ``scale`` into an ellipsoid, centred at ``center``."""
    mesh = trimesh.creation.icosphere(subdivisions=subdivisions, radius=radius)
    mesh.apply_transform(np.diag([*scale, 1.0]))
    mesh.apply_translation(center)
    return Part(mesh, color)


def cone(
    radius: float,
    height: float,
    base: tuple[float, float, float],
    color: Color,
    *,
    sections: int = 16,
) -> Part:
    """A closed upright cone part with its base disc centred at ``base``."""
    mesh = trimesh.creation.cone(radius=radius, height=height, sections=sections)
    mesh.apply_translation(base)
    return Part(mesh, color)


def frustum(
    r_bottom: float,
    r_top: float,
    height: float,
    base: tuple[float, float, float],
    color: Color,
    *,
    sections: int = 16,
) -> Part:
    """A closed upright truncated cone (a lamp shade, a flower pot) with its base at ``base``."""
    mesh = trimesh.creation.cylinder(radius=r_bottom, height=height, sections=sections)
    v = np.array(mesh.vertices)
    top = v[:, 2] > 0
    v[top, :2] *= r_top / r_bottom
    v[:, 2] += height / 2
    mesh = trimesh.Trimesh(v + np.asarray(base), mesh.faces, process=False)
    return Part(mesh, color)


def tube(
    r_in: float,
    r_out: float,
    height: float,
    base: tuple[float, float, float],
    color: Color,
    *,
    sections: int = 16,
) -> Part:
    """A closed upright ring (thick-walled pipe) with its bottom centred at ``base``."""
    mesh = trimesh.creation.annulus(r_min=r_in, r_max=r_out, height=height, sections=sections)
    mesh.apply_translation((base[0], base[1], base[2] + height / 2))
    return Part(mesh, color)


def open_cylinder(
    radius: float,
    height: float,
    base: tuple[float, float, float],
    wall: float,
    color: Color,
    *,
    sections: int = 16,
    inner: Color | None = None,
) -> list[Part]:
    """An open-top round container (bowl, pot, bin): a bottom disc and a ring wall."""
    x, y, z = base
    return [
        cylinder(radius - wall / 2, wall, (x, y, z + wall / 2), inner or color, sections=sections),
        tube(radius - wall, radius, height, base, color, sections=sections),
    ]


def hollow_box(
    size: Size,
    base: tuple[float, float, float],
    wall: float,
    color: Color,
    *,
    inner: Color | None = None,
) -> list[Part]:
    """An open-top box (basin, hamper, crate) from five slabs; ``base`` is its bottom centre."""
    w, d, h = size
    x, y, z = base
    x0, x1, y0, y1 = x - w / 2, x + w / 2, y - d / 2, y + d / 2
    return [
        slab((x0 + wall, y0 + wall, z), (x1 - wall, y1 - wall, z + wall), inner or color),
        slab((x0, y0, z), (x1, y0 + wall, z + h), color),
        slab((x0, y1 - wall, z), (x1, y1, z + h), color),
        slab((x0, y0 + wall, z), (x0 + wall, y1 - wall, z + h), color),
        slab((x1 - wall, y0 + wall, z), (x1, y1 - wall, z + h), color),
    ]


def elliptic_cylinder(
    rx: float,
    ry: float,
    height: float,
    center: tuple[float, float, float],
    color: Color,
    *,
    axis: str = "z",
    sections: int = 16,
) -> Part:
    """A closed cylinder with an elliptic cross-section: ``rx``/``ry`` are the semi-axes across
    the cylinder (for ``axis="y"``: along x and z), centred at ``center``."""
    part = cylinder(1.0, height, (0.0, 0.0, 0.0), color, axis=axis, sections=sections)
    scale = {"z": (rx, ry, 1.0), "y": (rx, 1.0, ry), "x": (1.0, rx, ry)}[axis]
    part.mesh.apply_transform(np.diag([*scale, 1.0]))
    part.mesh.apply_translation(center)
    return part


def shade(color: Color, factor: float) -> Color:
    """A darker (factor < 1) or lighter (factor > 1) tone of ``color``, clipped to [0, 1]."""
    return tuple(float(min(1.0, max(0.0, c * factor))) for c in color)  # type: ignore[return-value]


def merged_mesh(build: ShapeBuild) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """All parts as one triangle mesh: vertices (V, 3) float64, faces (F, 3) int32 and
    per-face colours (F, 3) float32."""
    vertices, faces, colors = [], [], []
    offset = 0
    for part in build.parts:
        v = np.asarray(part.mesh.vertices, dtype=np.float64)
        f = np.asarray(part.mesh.faces, dtype=np.int64) + offset
        vertices.append(v)
        faces.append(f)
        colors.append(np.tile(np.asarray(part.color, dtype=np.float32), (len(f), 1)))
        offset += len(v)
    return (
        np.concatenate(vertices),
        np.concatenate(faces).astype(np.int32),
        np.concatenate(colors),
    )


def merged_textures(build: ShapeBuild) -> tuple[np.ndarray, np.ndarray, tuple[PartTexture, ...]]:
    """The image textures of :func:`merged_mesh`'s faces: each face's index into the textured
    parts' textures (-1 untextured, (F,) int32), the corner coordinates ((F, 3, 2) float32,
    zero where untextured) and the textures in part order."""
    which, uvs, textures = [], [], []
    for part in build.parts:
        n = len(part.mesh.faces)
        if part.texture is None:
            which.append(np.full(n, -1, np.int32))
            uvs.append(np.zeros((n, 3, 2), np.float32))
            continue
        which.append(np.full(n, len(textures), np.int32))
        uvs.append(np.asarray(part.texture.uvs, np.float32).reshape(n, 3, 2))
        textures.append(part.texture)
    if not which:
        return np.zeros(0, np.int32), np.zeros((0, 3, 2), np.float32), ()
    return np.concatenate(which), np.concatenate(uvs), tuple(textures)
