"""Reading mesh files: every mesh's triangles, colours, texture images and UVs, in the file's frame.

glTF / GLB, OBJ (+ MTL), PLY and STL are read with trimesh. Other formats come from a reader
registered for their suffix (:func:`register_mesh_reader`): USD / USDZ are read with pxr by
:mod:`sgdata.usd.mesh_files`, which the pipeline registers (the scene model imports no USD).
A reader returns a :class:`RawMesh`; measuring, checking and placing it is
:mod:`sgdata.world.mesh_assets`' job.

Colours: a face's colour (what a renderer without textures draws) is its material's base colour
times its texture sampled at the face's UV centroid, or the file's vertex / face colours. A
textured face also keeps its UVs, its base colour and its image (PNG bytes, encoded with fixed
settings and named by their sha256), so the USD can carry the texture itself.
"""

from __future__ import annotations

import hashlib
import io
import json
import re
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from sgdata.errors import CatalogError

__all__ = [
    "MeshImage",
    "RawMesh",
    "image_png",
    "mesh_reader",
    "read_mesh_file",
    "register_mesh_reader",
    "sample",
    "texture_files",
]

NEUTRAL = (0.7, 0.7, 0.7)  # a face with no colour in its file


@dataclass(frozen=True, eq=False)
class MeshImage:
    """A texture image a mesh file holds or names, as PNG bytes."""

    name: str  # file name for the scene's textures folder: mesh_<sha256[:16]>.png
    png: bytes


@dataclass(frozen=True, eq=False)
class RawMesh:
    """Every mesh of one file concatenated, in the file's frame and units."""

    vertices: np.ndarray  # (V, 3) float64
    faces: np.ndarray  # (F, 3) int64
    colors: np.ndarray  # (F, 3) float32 flat colour of each face, linear RGB in [0, 1]
    base: np.ndarray  # (F, 3) float32 the colour a face's texture is multiplied by
    uvs: np.ndarray  # (F, 3, 2) float32 texture coordinates of each corner (0 untextured)
    face_image: np.ndarray  # (F,) int32 index into images, -1 untextured
    images: tuple[MeshImage, ...] = ()
    up: str | None = None  # the up axis the file declares ("y" | "z"), None: not declared
    meters_per_unit: float | None = None  # the unit the file declares, None: not declared
    texture_paths: tuple[str, ...] = ()  # image files read beside it (hashed for provenance)


Reader = Callable[[Path], RawMesh]
_READERS: dict[str, Reader] = {}


def register_mesh_reader(suffixes: Iterable[str], reader: Reader) -> None:
    """Read files with these suffixes (".usd", ...) with ``reader`` (again: replaced)."""
    for suffix in suffixes:
        _READERS[suffix.lower()] = reader


def mesh_reader(suffix: str) -> Reader | None:
    """The registered reader of a suffix, if any."""
    return _READERS.get(suffix.lower())


def read_mesh_file(file: Path) -> RawMesh:
    """The meshes of ``file``, read by its suffix's registered reader or trimesh.

    Raises:
        CatalogError: the file cannot be read or holds no triangles (one line naming it).
    """
    reader = mesh_reader(file.suffix)
    if reader is not None:
        return reader(file)
    return _read_trimesh(file)


def texture_files(file: Path) -> list[Path]:
    """The image files an OBJ's MTL or a .gltf names; a missing one is refused here (trimesh
    would drop it silently and draw the mesh untextured)."""
    names: list[tuple[Path, str]] = []
    suffix = file.suffix.lower()
    try:
        if suffix == ".obj":
            for line in file.read_text(encoding="utf-8", errors="replace").splitlines():
                if line.startswith("mtllib "):
                    mtl = file.parent / line[7:].strip()
                    if not mtl.is_file():
                        raise CatalogError(
                            f"{file}: its material file {mtl.name!r} is missing (looked in "
                            f"{mtl.parent}); put it beside the OBJ or remove the mtllib line"
                        )
                    for entry in mtl.read_text(encoding="utf-8", errors="replace").splitlines():
                        match = re.match(r"\s*(map_Kd|map_Ka|map_d|map_Bump|bump)\s+(.+)", entry)
                        if match:
                            names.append((mtl, match.group(2).split()[-1]))
        elif suffix == ".gltf":
            doc = json.loads(file.read_text(encoding="utf-8"))
            for image in doc.get("images", []):
                uri = image.get("uri", "")
                if uri and not uri.startswith("data:"):
                    names.append((file, uri))
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        raise CatalogError(f"{file}: cannot read the mesh file ({exc})") from None
    found = []
    for owner, name in names:
        texture = owner.parent / name
        if not texture.is_file():
            raise CatalogError(
                f"{file}: texture {name!r} (named in {owner.name}) is missing; put it in "
                f"{texture.parent} or remove it from {owner.name}"
            )
        if texture.resolve() not in found:
            found.append(texture.resolve())
    return sorted(found)


def image_png(pixels: np.ndarray) -> MeshImage:
    """An RGB image (H, W, 3) uint8 as PNG bytes (fixed encoder settings) and its name."""
    from PIL import Image  # late: only textured files need it

    buffer = io.BytesIO()
    Image.fromarray(np.ascontiguousarray(pixels, np.uint8), mode="RGB").save(
        buffer, format="PNG", optimize=False, compress_level=6
    )
    data = buffer.getvalue()
    return MeshImage(f"mesh_{hashlib.sha256(data).hexdigest()[:16]}.png", data)


def sample(pixels: np.ndarray, uvs: np.ndarray) -> np.ndarray:
    """(F, 3) colours of an image (H, W, 3) float in [0, 1] at each face's UV centroid
    (bottom-left origin, repeat wrapping)."""
    h, w = pixels.shape[:2]
    centre = np.nan_to_num(np.asarray(uvs, np.float64).mean(axis=1)) % 1.0
    col = np.minimum((centre[:, 0] * w).astype(np.int64), w - 1)
    row = np.minimum(((1.0 - centre[:, 1]) * h).astype(np.int64), h - 1)
    return pixels[row, col]


def _read_trimesh(file: Path) -> RawMesh:
    import trimesh  # late: heavy, and only the reading side needs it

    if file.stat().st_size == 0:  # trimesh would answer with an index error of its own
        raise CatalogError(f"{file}: the file is empty (0 bytes); re-export it")
    try:
        loaded = trimesh.load(str(file), process=False)
    except Exception as exc:  # noqa: BLE001 -- any reader failure is the file's fault
        first = (str(exc).strip().splitlines() or [type(exc).__name__])[0][:160]
        raise CatalogError(f"{file}: cannot read the mesh ({first})") from None
    meshes = loaded.dump() if isinstance(loaded, trimesh.Scene) else [loaded]
    meshes = [m for m in meshes if isinstance(m, trimesh.Trimesh) and len(m.faces)]
    if not meshes:
        raise CatalogError(f"{file}: the file holds no triangles (an empty mesh); re-export it")
    images: dict[str, MeshImage] = {}
    parts = []
    offset = 0
    for mesh in meshes:
        v = np.asarray(mesh.vertices, np.float64)
        faces = np.asarray(mesh.faces, np.int64)
        parts.append((v, faces + offset, *_face_materials(mesh, faces, images)))
        offset += len(v)
    order = {name: k for k, name in enumerate(images)}
    face_image = np.concatenate(
        [np.full(len(p[1]), order[p[5]] if p[5] else -1, np.int32) for p in parts]
    )
    return RawMesh(
        vertices=np.concatenate([p[0] for p in parts]),
        faces=np.concatenate([p[1] for p in parts]),
        colors=np.concatenate([p[2] for p in parts]).astype(np.float32),
        base=np.concatenate([p[3] for p in parts]).astype(np.float32),
        uvs=np.concatenate([p[4] for p in parts]).astype(np.float32),
        face_image=face_image,
        images=tuple(images.values()),
    )


def _face_materials(
    mesh: object, faces: np.ndarray, images: dict[str, MeshImage]
) -> tuple[np.ndarray, np.ndarray, np.ndarray, str]:
    """(colours, base colours, corner UVs, image name or "") of a trimesh's faces; a new
    image is added to ``images``."""
    count = len(faces)
    zero_uv = np.zeros((count, 3, 2), np.float32)
    visual = mesh.visual  # type: ignore[attr-defined]
    kind = getattr(visual, "kind", None)
    if kind in ("face", "vertex"):
        colors = np.asarray(visual.face_colors, np.float32)[:, :3] / 255.0
        return colors, colors, zero_uv, ""
    if kind != "texture":
        flat = np.tile(np.asarray(NEUTRAL, np.float32), (count, 1))
        return flat, flat, zero_uv, ""
    material = visual.material
    factor = getattr(material, "baseColorFactor", None)
    image = getattr(material, "baseColorTexture", None)
    if factor is None and image is None:  # a SimpleMaterial (OBJ + MTL): the map, else Kd
        image = getattr(material, "image", None)
        factor = getattr(material, "diffuse", None) if image is None else None
    base = (
        np.asarray(factor, np.float32).reshape(-1)[:3] / 255.0
        if factor is not None
        else np.ones(3, np.float32)
    )
    colors = np.tile(base, (count, 1))
    uv = getattr(visual, "uv", None)
    if image is None or uv is None or len(uv) != len(mesh.vertices):  # type: ignore[attr-defined]
        return colors, colors, zero_uv, ""
    rgb = np.asarray(image.convert("RGB"), np.uint8)
    corner_uv = np.asarray(uv, np.float64)[faces]
    colors = colors * sample(rgb.astype(np.float32) / 255.0, corner_uv)
    corner_uv = np.nan_to_num(corner_uv).astype(np.float32)
    png = image_png(rgb)
    images.setdefault(png.name, png)
    return colors, np.tile(base, (count, 1)), corner_uv, png.name
