"""Mesh files as catalog classes: read, check and measure each file once, and build its shape.

A catalog class with ``mesh = "my_assets/mugs/*.glb"`` has one variant per file (glTF / GLB,
OBJ with its MTL, PLY, STL read with trimesh; USD / USDZ by the reader the pipeline registers).
Each file is checked (a known format, its textures present, vertices, faces with area, no NaN)
and measured like a user's room: its up axis (Y or Z) and unit (m, cm, mm) are the ones that
put its size within the class's size bounds (or those the class declares), its front turned to
-Y, and it is moved to the local frame of every object (footprint centred on the origin,
resting on z = 0). The scale policy ``keep`` (the default) keeps its true size, which must lie
within the bounds; ``fit`` scales it uniformly into them. From the measured mesh come the floor
footprint (the convex hull of its projection) and the support surfaces of its upward faces (a
table top, shelf levels, a bowl's inside). Colours, UVs and texture images come from
:mod:`sgdata.world.mesh_files`: a face's flat colour is its base colour times its texture at
the face's UV centroid; a textured part also carries its image and UVs
(:class:`~sgdata.world.shapes.PartTexture`), which a textured room binds in UsdShade
(:mod:`sgdata.usd.looks`).

Everything read is cached per process (one read per worker), keyed by the file's path, size and
modification time; the bytes of a file, not its name, decide what a dataset holds (its sha256
goes to the manifest: :func:`asset_files`).
"""

from __future__ import annotations

import dataclasses
import hashlib
import math
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from sgdata.errors import CatalogError
from sgdata.world.mesh_detail import budgets, decimate
from sgdata.world.mesh_files import (
    MeshImage,
    RawMesh,
    mesh_reader,
    read_mesh_file,
    texture_files,
)
from sgdata.world.shapes.base import Part, PartTexture, ShapeBuild, Surface

if TYPE_CHECKING:
    from sgdata.world.catalog import Catalog, ClassSpec, MeshSource

__all__ = [
    "MESH_FORMATS",
    "MeshAsset",
    "asset_files",
    "class_assets",
    "class_shape",
    "class_sizes",
    "mesh_build",
    "mesh_footprint",
    "orientation_warning",
    "read_asset",
]

# Readable formats and the up axis each usually has (glTF says Y; OBJ exporters mostly Y).
MESH_FORMATS = {".glb": "y", ".gltf": "y", ".obj": "y", ".ply": "z", ".stl": "z"}
# USD / USDZ: read by the reader sgdata.usd.mesh_files registers (an authored upAxis rules)
MESH_FORMATS.update(dict.fromkeys((".usd", ".usda", ".usdc", ".usdz"), "y"))
# Formats whose specification fixes the up axis: glTF 2.0 is Y up. Theirs is read, never
# guessed. OBJ, PLY and STL say nothing, and USD without an authored upAxis is written Z up by
# some tools despite UsdGeom's Y fallback: theirs is measured (the axis that puts the size
# within the class's bounds).
SPECIFIED_UP = (".glb", ".gltf")
# How a file's up axis was decided, as the assets summary says it
UP_FROM = ("given", "declared", "format", "measured")
_UNITS = {"m": 1.0, "cm": 0.01, "mm": 0.001}
# a measured size this far (as a factor) outside the class's bounds is refused under `keep`
SIZE_TOLERANCE = 1.25
# `fit` refuses a file it would have to scale by more than this (either way): wrong units
FIT_LIMIT = 10.0
DEGENERATE_SHARE = 0.1  # refuse a file with more of its faces without area than this
UP_NORMAL = 0.95  # a face is "upward" (part of a support surface) when its normal's z exceeds it
LEVEL_STEP = 0.005  # metres: upward faces within one step of height form one surface
MIN_SURFACE_SHARE = 0.08  # of the footprint's box area: smaller levels offer no support
SHRINK_STEPS = 8  # a surface's rectangle shrinks by 10 % at most this often to lie on its faces


@dataclass(frozen=True, eq=False)
class MeshAsset:
    """One mesh file, checked and measured, in an object's local frame (metres, Z up, front
    -Y, footprint centred on the origin, bottom on z = 0)."""

    path: str  # absolute path of the file
    sha256: str  # of the file's bytes
    vertices: np.ndarray  # (V, 3) float64
    faces: np.ndarray  # (F, 3) int32
    face_colors: np.ndarray  # (F, 3) float32, linear RGB in [0, 1]
    size: tuple[float, float, float]  # width, depth, height (m) as measured
    up: str  # the file's up axis: "y" or "z"
    up_from: str  # how it was decided, one of UP_FROM
    units: str  # the file's unit: "m", "cm" or "mm"
    footprint: np.ndarray  # (K, 2) convex hull of the floor projection, counter-clockwise
    surfaces: tuple[Surface, ...]  # support surfaces from upward faces
    textures: tuple[str, ...] = ()  # texture files it reads (absolute paths)
    texture_sha256: tuple[str, ...] = ()
    face_base: np.ndarray | None = None  # (F, 3) float32 what a face's texture is multiplied by
    face_uvs: np.ndarray | None = None  # (F, 3, 2) float32 corner texture coordinates
    face_image: np.ndarray | None = None  # (F,) int32 index into images, -1 untextured
    images: tuple[MeshImage, ...] = ()  # the texture images its faces use (PNG bytes)

    @property
    def triangles(self) -> int:
        return len(self.faces)


def class_assets(spec: ClassSpec) -> tuple[MeshAsset, ...]:
    """The measured files of a mesh class, variant order.

    Raises:
        CatalogError: the class has no mesh files, or a file is bad (one line naming it).
    """
    if spec.mesh is None:
        raise CatalogError(f"class {spec.name}: not a mesh class (its shape is a recipe)")
    return tuple(
        read_asset(path, spec.mesh, spec.size_min, spec.size_max, spec.name)
        for path in spec.mesh.files
    )


def class_sizes(spec: ClassSpec) -> tuple[tuple[float, float, float], ...]:
    """Measured size of each variant of a mesh class (what ``keep`` places)."""
    return tuple(asset.size for asset in class_assets(spec))


def read_asset(
    path: str,
    source: MeshSource,
    size_min: tuple[float, float, float],
    size_max: tuple[float, float, float],
    class_name: str,
) -> MeshAsset:
    """Read, check and measure one mesh file (cached while the file is unchanged).

    Raises:
        CatalogError: unknown format, missing texture, unreadable file, empty mesh, NaN or
            infinite vertices, faces without area, or a size no unit or up axis makes
            plausible for the class -- one line naming the file and the fix.
    """
    try:
        stat = Path(path).stat()
    except OSError:
        raise CatalogError(f"{path}: mesh file not found (class {class_name})") from None
    return _read_cached(
        path, stat.st_size, stat.st_mtime_ns, source, size_min, size_max, class_name
    )


@lru_cache(maxsize=256)
def _read_cached(
    path: str,
    _bytes: int,
    _mtime: int,
    source: MeshSource,
    size_min: tuple[float, float, float],
    size_max: tuple[float, float, float],
    class_name: str,
) -> MeshAsset:
    file = Path(path)
    suffix = file.suffix.lower()
    if suffix not in MESH_FORMATS:
        raise CatalogError(
            f"{file}: unknown mesh format {suffix or '(no suffix)'!r}; expected one of "
            f"{', '.join(sorted(MESH_FORMATS))} (convert it, e.g. with Blender)"
        )
    if suffix in (".usd", ".usda", ".usdc", ".usdz") and mesh_reader(suffix) is None:
        raise CatalogError(
            f"{file}: USD mesh files are read by sgdata.usd.mesh_files; call "
            "register_usd_mesh_reader() first (sgdata generate and the CLI do)"
        )
    textures = texture_files(file)
    raw = read_mesh_file(file)
    textures = sorted({*textures, *(Path(p) for p in raw.texture_paths)})
    vertices, keep = _checked(file, raw.vertices, raw.faces)
    faces = raw.faces[keep].astype(np.int32)
    up_from = "given" if source.up != "auto" else "declared" if raw.up is not None else None
    if up_from is None:
        up_from = "format" if suffix in SPECIFIED_UP else "measured"
    source = _declared(raw, source)
    if raw.meters_per_unit is not None:  # the file says its unit: read it in metres
        vertices = vertices * raw.meters_per_unit
    if up_from == "format":
        source = dataclasses.replace(source, up=MESH_FORMATS[suffix])
    up, units, scale = _measure(file, vertices, source, size_min, size_max, class_name)
    local = _to_local(vertices, up, source.front) * _UNITS[units] * scale
    lo, hi = local.min(axis=0), local.max(axis=0)
    local = local - np.array([(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, lo[2]])
    size = tuple(round(float(v), 4) for v in hi - lo)
    return MeshAsset(
        path=str(file),
        sha256=_sha256(file),
        vertices=local,
        faces=faces,
        face_colors=np.clip(raw.colors[keep], 0.0, 1.0),
        size=(size[0], size[1], size[2]),
        up=up,
        up_from=up_from,
        units=units,
        footprint=_hull(local[:, :2]),
        surfaces=_surfaces(local, faces),
        textures=tuple(str(t) for t in textures),
        texture_sha256=tuple(_sha256(t) for t in textures),
        face_base=np.clip(raw.base[keep], 0.0, 1.0),
        face_uvs=raw.uvs[keep],
        face_image=raw.face_image[keep],
        images=raw.images,
    )


def orientation_warning(class_name: str, assets: tuple[MeshAsset, ...]) -> str | None:
    """A warning when the variants of one class were read with different up axes and one of
    them was measured (it may lie on its side), naming each file's axis and how it was
    decided; files whose axis their format or entry fixes are taken at their word."""
    if len({a.up for a in assets}) < 2 or all(a.up_from != "measured" for a in assets):
        return None
    read = ", ".join(f"{Path(a.path).name}: {a.up.upper()} ({a.up_from})" for a in assets)
    return (
        f"class {class_name}'s files disagree on the up axis ({read}); if one lies on its "
        'side, give up = "y" or "z" in the class entry (or re-export it)'
    )


def _declared(raw: RawMesh, source: MeshSource) -> MeshSource:
    """``source`` with the up axis and unit a file declares (USD's upAxis, metersPerUnit)
    where the class entry leaves them to be measured."""
    changes = {}
    if raw.up is not None and source.up == "auto":
        changes["up"] = raw.up
    if raw.meters_per_unit is not None and source.units == "auto":
        changes["units"] = "m"
    return dataclasses.replace(source, **changes) if changes else source


# ------------------------------------------------------------------------------- reading


def _checked(file: Path, vertices: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Refuse a mesh that cannot be placed; the vertices, and which faces to keep (the few
    without area are dropped)."""
    if not np.isfinite(vertices).all():
        bad = int((~np.isfinite(vertices).all(axis=1)).sum())
        raise CatalogError(
            f"{file}: {bad} of {len(vertices)} vertices are NaN or infinite; repair the mesh"
        )
    if faces.min() < 0 or faces.max() >= len(vertices):
        raise CatalogError(f"{file}: faces name vertices the file does not have; re-export it")
    tri = vertices[faces]
    area = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    extent = float(np.ptp(vertices, axis=0).max())
    flat = area <= (extent * 1e-7) ** 2 if extent > 0 else np.ones(len(faces), bool)
    if flat.mean() > DEGENERATE_SHARE or extent == 0:
        raise CatalogError(
            f"{file}: {int(flat.sum())} of {len(faces)} faces have no area (degenerate); "
            "repair the mesh (e.g. merge vertices, remove zero-area faces)"
        )
    return vertices, ~flat


# ----------------------------------------------------------------------------- measuring


def _to_local(vertices: np.ndarray, up: str, front: str) -> np.ndarray:
    """The file's frame turned Z up (a Y-up file's +Z front becomes -Y) and its front to -Y."""
    x, y, z = vertices[:, 0], vertices[:, 1], vertices[:, 2]
    if up == "y":
        x, y, z = x, -z, y
    if front == "+y":
        x, y = -x, -y
    elif front == "+x":
        x, y = y, -x
    elif front == "-x":
        x, y = -y, x
    return np.stack([x, y, z], axis=1)


def _measure(
    file: Path,
    vertices: np.ndarray,
    source: MeshSource,
    size_min: tuple[float, float, float],
    size_max: tuple[float, float, float],
    class_name: str,
) -> tuple[str, str, float]:
    """The up axis and unit that put the file's size within the class's bounds, and the
    uniform scale (1 under ``keep``) that ``fit`` adds."""
    default_up = MESH_FORMATS[file.suffix.lower()]
    ups = [source.up] if source.up != "auto" else [default_up, "z" if default_up == "y" else "y"]
    units = [source.units] if source.units != "auto" else list(_UNITS)
    lo, hi = np.log(size_min), np.log(size_max)
    fit = source.scale == "fit"
    best: tuple[tuple[float, float], str, str, np.ndarray, float] | None = None
    for up in ups:
        extent = np.ptp(_to_local(vertices, up, source.front), axis=0)
        for unit in units:
            size = np.maximum(extent * _UNITS[unit], 1e-9)
            scale = _fit_scale(size, lo, hi) if fit else 1.0
            # fit: the proportions decide the up axis first; the unit, how far it scales
            key = (round(_miss(size * scale, lo, hi), 9), _miss(size, lo, hi))
            if best is None or key < best[0]:
                best = (key, up, unit, size, scale)
    assert best is not None
    (miss, raw_miss), up, unit, size, scale = best
    measured = " x ".join(f"{v:.3g}" for v in size)
    bounds = (
        f"[{', '.join(f'{v:g}' for v in size_min)}] to [{', '.join(f'{v:g}' for v in size_max)}] m"
    )
    if miss > 3 * math.log(SIZE_TOLERANCE) and fit:
        raise CatalogError(
            f"{file}: measures {measured} m ({up.upper()} up); its proportions fit class "
            f"{class_name}'s size {bounds} at no scale; give its 'up' axis in the class entry "
            "or widen size_min/size_max"
        )
    if fit and not 1.0 / FIT_LIMIT <= scale <= FIT_LIMIT:
        raise CatalogError(
            f"{file}: measures {measured} m read in {unit} ({up.upper()} up), {scale:.3g} "
            f"times off class {class_name}'s size {bounds}; give its 'units' in the class entry"
        )
    if miss > 3 * math.log(SIZE_TOLERANCE):
        raw = " x ".join(f"{v:.4g}" for v in np.ptp(vertices, axis=0))
        raise CatalogError(
            f"{file}: measures {raw} (file units); no unit (m, cm, mm) or up axis (Y, Z) puts "
            f"it within class {class_name}'s size {bounds} (closest: {measured} m in {unit}); "
            'fix the file\'s scale, widen size_min/size_max, or set scale = "fit"'
        )
    return up, unit, scale


def _miss(size: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> float:
    """How far (summed log factors) a size lies outside the log bounds ``lo``..``hi``."""
    logs = np.log(size)
    return float(np.sum(np.maximum(0.0, lo - logs) + np.maximum(0.0, logs - hi)))


def _fit_scale(size: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> float:
    """The uniform scale nearest 1 that brings ``size`` within the bounds (the middle of what
    the tightest sides allow when no scale does)."""
    low = float(np.max(np.exp(lo) / size))  # smallest scale reaching every lower bound
    high = float(np.min(np.exp(hi) / size))  # largest keeping every upper bound
    if low <= high:
        return min(max(1.0, low), high)
    return math.sqrt(low * high)


def _hull(points: np.ndarray) -> np.ndarray:
    """Counter-clockwise convex hull of 2D points (Andrew's monotone chain)."""
    pts = np.unique(np.round(points, 6), axis=0)
    if len(pts) < 3:
        return pts

    def half(seq: np.ndarray) -> list[np.ndarray]:
        out: list[np.ndarray] = []
        for p in seq:
            while len(out) >= 2 and _turn(out[-2], out[-1], p) <= 0:
                out.pop()
            out.append(p)
        return out

    lower, upper = half(pts), half(pts[::-1])
    return np.array(lower[:-1] + upper[:-1])


def _turn(o: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    """The z of (a - o) x (b - o): > 0 for a left turn."""
    return float((a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]))


def _surfaces(vertices: np.ndarray, faces: np.ndarray) -> tuple[Surface, ...]:
    """Support surfaces from upward faces, grouped by height: the top (free above), shelf
    levels (their clearance the lowest downward face above them) and insides (free above, but
    walls rising around them: a bowl, a basin), each the centred part of its faces' box that
    their area covers."""
    tri = vertices[faces]
    cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    area = 0.5 * np.linalg.norm(cross, axis=1)
    normal_z = cross[:, 2] / np.maximum(2 * area, 1e-18)
    centre = tri.mean(axis=1)
    top = float(vertices[:, 2].max())
    box_area = float(np.ptp(vertices[:, 0]) * np.ptp(vertices[:, 1]))
    up = normal_z > UP_NORMAL
    down = normal_z < -UP_NORMAL
    levels = np.round(centre[:, 2] / LEVEL_STEP).astype(np.int64)
    surfaces = []
    for level in np.unique(levels[up]):
        mine = up & (levels == level)
        total = float(area[mine].sum())
        if total < MIN_SURFACE_SHARE * box_area or level * LEVEL_STEP < 0.02 * top:
            continue
        pts = tri[mine].reshape(-1, 3)
        x0, y0 = pts[:, 0].min(), pts[:, 1].min()
        x1, y1 = pts[:, 0].max(), pts[:, 1].max()
        cover = min(1.0, total / max((x1 - x0) * (y1 - y0), 1e-12))
        cx, cy, hx, hy = (x0 + x1) / 2, (y0 + y1) / 2, (x1 - x0) * cover / 2, (y1 - y0) * cover / 2
        for _ in range(SHRINK_STEPS):  # shrink until the faces cover it (a disc's inner square)
            if _covered(tri[mine][:, :, :2], cx - hx, cy - hy, cx + hx, cy + hy):
                break
            hx, hy = hx * 0.9, hy * 0.9
        else:
            continue  # a ring (a mug's rim), not a surface to rest on
        z = float(pts[:, 2].max())
        above = down & (centre[:, 2] > z + 1e-4)
        above &= (np.abs(centre[:, 0] - cx) < hx) & (np.abs(centre[:, 1] - cy) < hy)
        clearance = float(centre[above, 2].min() - z) if above.any() else math.inf
        inside = math.isinf(clearance) and z < top - 0.25 * top
        surfaces.append(
            Surface(
                round(float(cx - hx), 4),
                round(float(cy - hy), 4),
                round(float(cx + hx), 4),
                round(float(cy + hy), 4),
                round(z, 4),
                round(clearance, 4) if math.isfinite(clearance) else math.inf,
                inside,
            )
        )
    return tuple(surfaces)


def _covered(tri: np.ndarray, x0: float, y0: float, x1: float, y1: float) -> bool:
    """Do the 2D triangles ``tri`` (T, 3, 2) cover a 5 x 5 grid of points of the rectangle?"""
    gx, gy = np.meshgrid(np.linspace(x0, x1, 5), np.linspace(y0, y1, 5))
    p = np.stack([gx.ravel(), gy.ravel()], axis=1)[:, None, :]  # (P, 1, 2)
    a, b, c = tri[None, :, 0], tri[None, :, 1], tri[None, :, 2]

    def side(u: np.ndarray, v: np.ndarray) -> np.ndarray:
        return (v[..., 0] - u[..., 0]) * (p[..., 1] - u[..., 1]) - (v[..., 1] - u[..., 1]) * (
            p[..., 0] - u[..., 0]
        )

    s1, s2, s3 = side(a, b), side(b, c), side(c, a)
    eps = 1e-9
    inside = ((s1 >= -eps) & (s2 >= -eps) & (s3 >= -eps)) | (
        (s1 <= eps) & (s2 <= eps) & (s3 <= eps)
    )
    return bool(inside.any(axis=1).all())


def _sha256(file: Path) -> str:
    digest = hashlib.sha256()
    with open(file, "rb") as handle:
        for block in iter(lambda: handle.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


# ------------------------------------------------------------------------------ building


@lru_cache(maxsize=1024)
def mesh_build(
    spec: ClassSpec,
    size: tuple[float, float, float],
    variant: int,
    color: tuple[float, float, float] = (0.5, 0.5, 0.5),
) -> ShapeBuild:
    """The parts (one per colour of the file) and support surfaces of variant ``variant`` of
    a mesh class, scaled to ``size``; a recolouring class (one with a palette) paints its
    largest colour ``color``. Parts are simplified to the class's ``max_triangles``
    (:mod:`sgdata.world.mesh_detail`); the surfaces are the full mesh's."""
    import trimesh  # late: the recipes' part type

    asset = class_assets(spec)[variant % len(spec.mesh.files)]  # type: ignore[union-attr]
    factor = np.array(size, np.float64) / np.maximum(np.array(asset.size), 1e-9)
    vertices = asset.vertices * factor
    colors = asset.face_colors
    image = asset.face_image if asset.face_image is not None else np.full(len(colors), -1)
    base = asset.face_base if asset.face_base is not None else colors
    # a part: the faces of one flat colour (and one texture image and base colour, if any)
    key = np.c_[np.round(colors * 63), image, np.where(image[:, None] >= 0, np.round(base * 63), 0)]
    keys, group = np.unique(key.astype(np.int64), axis=0, return_inverse=True)
    group = group.reshape(-1)
    main = -1
    if spec.mesh is not None and spec.mesh.recolor:
        tri = vertices[asset.faces]
        area = np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
        main = int(np.argmax(np.bincount(group, weights=area, minlength=len(keys))))
    limit = spec.mesh.max_triangles if spec.mesh is not None else 0
    budget = budgets([int(n) for n in np.bincount(group, minlength=len(keys))], limit)
    parts = []
    for k in range(len(keys)):
        mine = group == k
        faces = asset.faces[mine]
        used, local = np.unique(faces, return_inverse=True)
        uvs = asset.face_uvs[mine] if keys[k][3] >= 0 and asset.face_uvs is not None else None
        part_vertices, part_faces, uvs = decimate(
            vertices[used], local.reshape(-1, 3), budget[k], uvs
        )
        mesh = trimesh.Trimesh(part_vertices, part_faces, process=False)
        mean = colors[mine].mean(axis=0)
        part_color = color if k == main else (float(mean[0]), float(mean[1]), float(mean[2]))
        texture = None
        if uvs is not None:
            picture = asset.images[int(keys[k][3])]
            tint = base[mine].mean(axis=0)
            scale = color if k == main else (float(tint[0]), float(tint[1]), float(tint[2]))
            texture = PartTexture(picture.name, picture.png, uvs, scale)
        parts.append(Part(mesh, part_color, texture))
    sx, sy, sz = factor
    surfaces = [
        Surface(s.x0 * sx, s.y0 * sy, s.x1 * sx, s.y1 * sy, s.z * sz, s.clearance * sz, s.inside)
        for s in asset.surfaces
    ]
    return ShapeBuild(parts=parts, surfaces=surfaces)


@lru_cache(maxsize=1024)
def mesh_footprint(spec: ClassSpec, size: tuple[float, float, float], variant: int) -> np.ndarray:
    """(K, 2) floor outline of variant ``variant`` of a mesh class scaled to ``size``, in the
    object's local frame: the convex hull of its projection, counter-clockwise (read-only)."""
    asset = class_assets(spec)[variant % len(spec.mesh.files)]  # type: ignore[union-attr]
    factor = np.array(size[:2], np.float64) / np.maximum(np.array(asset.size[:2]), 1e-9)
    outline = np.asarray(asset.footprint, np.float64) * factor
    outline.flags.writeable = False
    return outline


def class_shape(
    spec: ClassSpec,
    size: tuple[float, float, float],
    variant: int,
    color: tuple[float, float, float] = (0.5, 0.5, 0.5),
) -> ShapeBuild:
    """The shape of any class: its mesh files' (:func:`mesh_build`) or its recipe's."""
    if spec.mesh is not None:
        return mesh_build(spec, size, variant, color)
    from sgdata.world.shapes import build_shape

    return build_shape(spec.shape, size, variant, color)


def asset_files(catalog: Catalog) -> list[tuple[str, str]]:
    """(absolute path, sha256) of every mesh and texture file the catalog's classes read,
    sorted by path: what the manifest records and ``validate --sources`` checks."""
    seen: dict[str, str] = {}
    for spec in catalog.classes.values():
        if spec.mesh is None:
            continue
        for asset in class_assets(spec):
            seen[asset.path] = asset.sha256
            seen.update(zip(asset.textures, asset.texture_sha256, strict=True))
    return sorted(seen.items())
