"""Procedural texture images: wood, tiles, plaster, fabric, metal and plain surfaces, in numpy.

Every image is a seamless tile (it repeats without a visible edge) that covers ``tile`` metres
of surface, so texture scale is physical: a floor's planks are as wide in a small room as in a
large one. Images are grey detail maps: a material multiplies them by its colour (the catalog
palette, or a layout's tinted version of it), so one image serves every colour of a surface.

Values are designed in linear reflectance (mean 0.8-0.93, so a textured surface is a little
darker than its flat colour, as real surfaces are) and stored sRGB-encoded, as
``UsdUVTexture`` with ``sourceColorSpace = "sRGB"`` and pyrender both expect. Every image
depends only on (kind, variant, size) through :func:`sgdata.seeds.texture_seed`, and is made
of integer lattices, smoothsteps and triangle waves (no transcendental numpy kernels whose
SIMD paths differ between CPUs), so the bytes are the same in every process.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cache

import numpy as np

from sgdata.errors import ConfigError
from sgdata.seeds import rng_for, texture_seed

__all__ = [
    "DEFAULT_TEXTURE_SIZE",
    "TEXTURE_KINDS",
    "TextureKind",
    "check_texture_size",
    "texture_file_name",
    "texture_image",
]

DEFAULT_TEXTURE_SIZE = 256  # pixels per side


@dataclass(frozen=True)
class TextureKind:
    """One kind of surface: how much surface an image covers and how many variants exist."""

    name: str
    tile: float  # metres of surface one repeat of the image covers
    variants: int  # distinct images of this kind (variant 0 .. variants - 1)
    roughness: float  # UsdPreviewSurface roughness of materials using it


TEXTURE_KINDS: dict[str, TextureKind] = {
    k.name: k
    for k in (
        TextureKind("wood", 1.0, 4, 0.7),  # planks along u, staggered joints, wavy grain
        TextureKind("tiles", 0.6, 3, 0.35),  # square tiles and grout lines
        TextureKind("plaster", 1.0, 3, 0.95),  # mottled wall paint
        TextureKind("fabric", 0.2, 3, 1.0),  # woven threads with mottling
        TextureKind("metal", 0.5, 2, 0.4),  # brushed streaks
        TextureKind("smooth", 0.5, 2, 0.3),  # ceramic, plastic, glass: a faint cloud
        TextureKind("matte", 0.5, 3, 0.9),  # stone, paper, organic: speckled noise
    )
}

_LUT_STEPS = 4095


def texture_file_name(kind: str, variant: int, size: int) -> str:
    """The file name of one texture image: ``<kind>_<variant>_<size>px.png``."""
    return f"{kind}_{variant}_{size}px.png"


def texture_image(kind: str, variant: int, size: int = DEFAULT_TEXTURE_SIZE) -> np.ndarray:
    """The sRGB image of texture ``kind`` / ``variant``: ``(size, size, 3)`` uint8, read-only.

    Row 0 is the top of the image (v = 1 in USD's ``st``); the image tiles seamlessly.

    Raises:
        ConfigError: unknown kind, variant out of range, or a size that is not a power of two
            in [32, 2048].
    """
    if kind not in TEXTURE_KINDS:
        raise ConfigError(f"texture kind {kind!r}: expected one of {sorted(TEXTURE_KINDS)}")
    spec = TEXTURE_KINDS[kind]
    if not 0 <= variant < spec.variants:
        raise ConfigError(f"texture {kind} variant {variant}: expected 0..{spec.variants - 1}")
    check_texture_size(size)
    return _image(kind, int(variant), int(size))


def check_texture_size(size: int) -> None:
    """Raise ConfigError unless ``size`` is a power of two within [32, 2048]."""
    if isinstance(size, bool) or not isinstance(size, int) or not 32 <= size <= 2048:
        raise ConfigError(f"texture size {size!r}: expected a power of two in [32, 2048]")
    if size & (size - 1):
        raise ConfigError(f"texture size {size}: expected a power of two such as 128, 256, 512")


@cache
def _image(kind: str, variant: int, size: int) -> np.ndarray:
    rng = rng_for(texture_seed(kind, variant))
    linear = _MAKERS[kind](rng, variant, size)
    grey = _LUT[np.clip(np.rint(linear * _LUT_STEPS), 0, _LUT_STEPS).astype(np.int64)]
    image = np.repeat(grey[:, :, None], 3, axis=2)
    image.setflags(write=False)
    return image


def _srgb_lut() -> np.ndarray:
    """Linear [0, 1] in 4096 steps -> sRGB uint8, computed with Python's scalar math."""

    def encode(x: float) -> float:
        return 12.92 * x if x <= 0.0031308 else 1.055 * math.pow(x, 1 / 2.4) - 0.055

    return np.array(
        [round(255 * encode(i / _LUT_STEPS)) for i in range(_LUT_STEPS + 1)], dtype=np.uint8
    )


_LUT = _srgb_lut()


# ------------------------------------------------------------------------------- building blocks


def _smooth(f: np.ndarray) -> np.ndarray:
    return f * f * (3.0 - 2.0 * f)


def _axis(size: int, cells: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Lattice indices either side of each pixel and the smoothstep weight between them."""
    coords = np.arange(size, dtype=np.float64) * (cells / size)
    i0 = np.floor(coords).astype(np.int64)
    return i0 % cells, (i0 + 1) % cells, _smooth(coords - i0)


def _noise(
    rng: np.random.Generator, size: int, cells_u: int, cells_v: int | None = None
) -> np.ndarray:
    """Periodic value noise in [0, 1], shape (size, size) as (v rows, u columns)."""
    cells_v = cells_u if cells_v is None else cells_v
    lattice = rng.random((cells_v, cells_u))
    u0, u1, su = _axis(size, cells_u)
    v0, v1, sv = _axis(size, cells_v)
    top = lattice[v0][:, u0] + (lattice[v0][:, u1] - lattice[v0][:, u0]) * su[None, :]
    bottom = lattice[v1][:, u0] + (lattice[v1][:, u1] - lattice[v1][:, u0]) * su[None, :]
    return top + (bottom - top) * sv[:, None]


def _fbm(rng: np.random.Generator, size: int, cells: int, octaves: int = 4) -> np.ndarray:
    """Fractal noise in [0, 1]: octaves of value noise, each twice as fine and half as strong."""
    total, weight, amp = np.zeros((size, size)), 0.0, 1.0
    for k in range(octaves):
        c = min(cells << k, size)
        total += amp * _noise(rng, size, c)
        weight += amp
        amp *= 0.5
    return total / weight


def _tri(x: np.ndarray) -> np.ndarray:
    """Triangle wave in [0, 1]: 0 at integers, 1 half-way between."""
    return 2.0 * np.abs(x - np.floor(x + 0.5))


def _grid(size: int) -> tuple[np.ndarray, np.ndarray]:
    """(u, v) in [0, 1) per pixel as (size, size) arrays; v grows upwards like USD's st."""
    t = (np.arange(size, dtype=np.float64) + 0.5) / size
    return np.broadcast_to(t[None, :], (size, size)), np.broadcast_to(t[::-1, None], (size, size))


# ------------------------------------------------------------------------------------- kinds


def _wood(rng: np.random.Generator, variant: int, size: int) -> np.ndarray:
    rows = (6, 5, 8, 7)[variant]  # planks across one metre: 17, 20, 12.5, 14 cm wide
    u, v = _grid(size)
    row = np.minimum((v * rows).astype(np.int64), rows - 1)
    across = v * rows - row  # 0..1 across the plank
    joints = rng.random(rows)  # where each row's planks end (0.5 m planks, staggered rows)
    along = (u - joints[row]) % 1.0
    plank = row * 2 + (along < 0.5)  # the row's two planks in one repeat
    tone = rng.uniform(-0.09, 0.09, 2 * rows)[plank]
    warp = _noise(rng, size, 3, rows * 2)
    grain = _tri(across * 5.0 + warp * 1.6 + joints[row] * 7.0)
    fine = _noise(rng, size, 8, size // 4)  # streaks along the plank
    value = 0.7 + tone + 0.16 * grain + 0.06 * (fine - 0.5)
    edge = np.minimum(across, 1.0 - across) * size / rows  # pixels to the long edge
    end = along % 0.5
    gap = (edge < 1.2) | (np.minimum(end, 0.5 - end) * size < 1.0)
    return np.where(gap, 0.32, value)


def _tiles(rng: np.random.Generator, variant: int, size: int) -> np.ndarray:
    n = (2, 4, 3)[variant]  # tiles per 0.6 m repeat: 30, 15, 20 cm
    u, v = _grid(size)
    cu, cv = u * n, v * n
    iu, iv = cu.astype(np.int64), cv.astype(np.int64)
    tone = rng.uniform(-0.035, 0.035, (n, n))[iv % n, iu % n]
    grout = size / n * 0.035  # grout half-width in pixels, 3.5 % of a tile
    du = np.minimum(cu - iu, 1.0 - (cu - iu)) * size / n
    dv = np.minimum(cv - iv, 1.0 - (cv - iv)) * size / n
    surface = 0.9 + tone + 0.04 * (_fbm(rng, size, 8, 3) - 0.5)
    return np.where((du < grout) | (dv < grout), 0.5, surface)


def _plaster(rng: np.random.Generator, variant: int, size: int) -> np.ndarray:
    cells = (4, 8, 6)[variant]
    mottle = _fbm(rng, size, cells, 5)
    return 0.86 + 0.16 * (mottle - 0.5) + 0.03 * (_noise(rng, size, size // 2) - 0.5)


def _fabric(rng: np.random.Generator, variant: int, size: int) -> np.ndarray:
    threads = (32, 32, 16)[variant]  # per 0.2 m repeat
    u, v = _grid(size)
    tu, tv = u * threads, v * threads
    iu, iv = tu.astype(np.int64), tv.astype(np.int64)
    over = ((iu + iv) % 2 == 0) if variant != 1 else ((iu + iv) % 4 < 2)  # plain or twill
    across = np.where(over, _tri(tu), _tri(tv))  # 0 at a thread's edge, 1 at its middle
    mottle = _fbm(rng, size, 4, 3)
    return 0.7 + 0.14 * across + 0.12 * (mottle - 0.5)


def _metal(rng: np.random.Generator, variant: int, size: int) -> np.ndarray:
    streaks = _noise(rng, size, 2, size // (2 + 2 * variant))  # long along u, fine across
    broad = _fbm(rng, size, 2, 3)
    return 0.84 + 0.09 * (streaks - 0.5) + 0.06 * (broad - 0.5)


def _smooth_kind(rng: np.random.Generator, variant: int, size: int) -> np.ndarray:
    return 0.92 + 0.05 * (_fbm(rng, size, 2 + 2 * variant, 3) - 0.5)


def _matte(rng: np.random.Generator, variant: int, size: int) -> np.ndarray:
    base = _fbm(rng, size, (4, 8, 16)[variant], 4)
    speckle = rng.random((size, size)) < 0.04
    return 0.8 + 0.14 * (base - 0.5) - 0.1 * speckle


_MAKERS = {
    "wood": _wood,
    "tiles": _tiles,
    "plaster": _plaster,
    "fabric": _fabric,
    "metal": _metal,
    "smooth": _smooth_kind,
    "matte": _matte,
}
