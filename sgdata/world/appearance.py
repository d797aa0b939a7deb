"""Appearance: the looks of a room's surfaces and each layout's light, drawn from seeds.

A *look* is a texture kind, a variant of it and a tint. A room's base looks
(:func:`room_looks`) fix the texture variant of its floor, walls, ceiling and every object from
the room's seed; they never change, so the static structure stays a reliable cue. Each layout
then draws its own :class:`LayoutAppearance` (:func:`sample_appearance`): a light intensity
and colour temperature within the configured ranges, and a new look (texture variant and a
tint of the body colours) for every low- and high-dynamic object, so a tier-0 positive (same
pose, other layout) also differs in light and materials, as a real revisit does.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from sgdata.errors import ConfigError
from sgdata.seeds import rng_for, room_look_seed
from sgdata.world.materials import body_texture, structure_texture
from sgdata.world.scene import Dynamics, Room
from sgdata.world.textures import DEFAULT_TEXTURE_SIZE, TEXTURE_KINDS, check_texture_size

__all__ = [
    "NEUTRAL_TINT",
    "REFERENCE_TEMPERATURE",
    "STRUCTURE_PARTS",
    "AppearanceConfig",
    "LayoutAppearance",
    "Look",
    "RoomLooks",
    "light_color",
    "room_looks",
    "sample_appearance",
    "tinted",
]

REFERENCE_TEMPERATURE = 6500.0  # Kelvin: white light, the renderer's default colour
NEUTRAL_TINT = (1.0, 1.0, 1.0)
STRUCTURE_PARTS = ("Floor", "Ceiling", "Walls")  # the structure meshes under /Room/Structure
_TEMPERATURES = (1000.0, 40000.0)  # where the colour approximation below holds


@dataclass(frozen=True)
class AppearanceConfig:
    """How surfaces look and how each layout is lit (``[appearance]`` of a generation config)."""

    textures: bool = True  # procedural textures on structure and objects; false: flat colours
    texture_size: int = DEFAULT_TEXTURE_SIZE  # pixels per side of every texture image
    randomize: bool = True  # each layout draws its light and its low/high objects' looks
    light_intensity: tuple[float, float] = (0.8, 1.2)  # scale of the renderer's lights
    color_temperature: tuple[float, float] = (4000.0, 6500.0)  # Kelvin; 6500 is white
    tint: float = 0.15  # low/high objects' body colours times 1 +- tint, per channel

    def __post_init__(self) -> None:
        try:
            check_texture_size(self.texture_size)
        except ConfigError as exc:
            raise ConfigError(f"appearance.texture_size: {exc}") from None
        _check_range("light_intensity", self.light_intensity, (0.01, 10.0))
        _check_range("color_temperature", self.color_temperature, _TEMPERATURES)
        if not 0.0 <= self.tint <= 0.9:
            raise ConfigError(f"appearance.tint must be within [0, 0.9], got {self.tint}")


def _check_range(name: str, value: tuple[float, ...], bounds: tuple[float, float]) -> None:
    lo, hi = bounds
    if len(value) != 2 or not (lo <= value[0] <= value[1] <= hi):
        raise ConfigError(
            f"appearance.{name} {list(value)}: expected [low, high] with "
            f"{lo:g} <= low <= high <= {hi:g}"
        )


@dataclass(frozen=True)
class Look:
    """How one surface looks: a texture kind, its variant, and a tint of its colours."""

    texture: str  # a kind of sgdata.world.textures.TEXTURE_KINDS
    variant: int
    tint: tuple[float, float, float] = NEUTRAL_TINT  # per-channel factor on body colours


@dataclass(frozen=True)
class RoomLooks:
    """A room's base looks: its structure meshes by name, its objects by instance."""

    structure: dict[str, Look]
    objects: dict[int, Look]


@dataclass(frozen=True)
class LayoutAppearance:
    """What one layout draws: its light, and new looks of its low- and high-dynamic objects."""

    light_intensity: float  # scale of the renderer's default lights
    color_temperature: float  # Kelvin
    looks: dict[int, Look] = field(default_factory=dict)  # instance -> look


def room_looks(room: Room) -> RoomLooks:
    """The base looks of ``room``: texture kinds by room type and class, variants from its seed."""
    rng = rng_for(room_look_seed(room.seed))
    structure = {}
    for name in STRUCTURE_PARTS:
        kind = structure_texture(name, room.room_type)
        structure[name] = Look(kind, int(rng.integers(TEXTURE_KINDS[kind].variants)))
    objects = {}
    for obj in room.objects:
        kind = body_texture(obj.class_name)
        objects[obj.instance] = Look(kind, int(rng.integers(TEXTURE_KINDS[kind].variants)))
    return RoomLooks(structure, objects)


def sample_appearance(room: Room, config: AppearanceConfig, seed: int) -> LayoutAppearance:
    """One layout's appearance, drawn from ``seed`` (:func:`sgdata.seeds.appearance_seed`).

    Light intensity (4 decimals) and colour temperature (whole Kelvin) are uniform within the
    configured ranges; every low- and high-dynamic object gets a texture variant of its class's
    kind and a tint ``1 +- config.tint`` per channel (4 decimals). Static objects and the
    structure keep their base looks.
    """
    rng = rng_for(seed)
    intensity = _uniform(rng, config.light_intensity, 4)
    temperature = _uniform(rng, config.color_temperature, 0)
    looks = {}
    for obj in room.objects:
        if obj.dynamics == Dynamics.STATIC:
            continue
        kind = body_texture(obj.class_name)
        variant = int(rng.integers(TEXTURE_KINDS[kind].variants))
        factors = rng.uniform(1.0 - config.tint, 1.0 + config.tint, 3)
        tint = (
            round(float(factors[0]), 4),
            round(float(factors[1]), 4),
            round(float(factors[2]), 4),
        )
        looks[obj.instance] = Look(kind, variant, tint)
    return LayoutAppearance(intensity, temperature, looks)


def _uniform(rng: np.random.Generator, bounds: tuple[float, float], digits: int) -> float:
    lo, hi = bounds
    value = round(float(rng.uniform(lo, hi)), digits)
    return float(min(max(value, lo), hi))  # rounding must not leave the configured range


def tinted(
    color: tuple[float, ...], tint: tuple[float, float, float]
) -> tuple[float, float, float]:
    """``color`` times ``tint`` per channel, clipped to [0, 1], at float32 precision (as USD
    stores colours)."""
    out = np.clip(np.asarray(color, np.float32) * np.asarray(tint, np.float32), 0.0, 1.0)
    return (float(out[0]), float(out[1]), float(out[2]))


def light_color(kelvin: float) -> tuple[float, float, float]:
    """The RGB colour of a light of ``kelvin``, relative to white at 6500 K (which gives
    exactly (1, 1, 1)): warmer lights have less blue and green, cooler ones less red.

    Tanner Helland's fit of the blackbody colours (1000-40000 K), in Python's scalar maths
    so the value is the same in every process.

    Raises:
        ConfigError: ``kelvin`` outside [1000, 40000].
    """
    if not _TEMPERATURES[0] <= kelvin <= _TEMPERATURES[1]:
        raise ConfigError(f"colour temperature {kelvin} K: expected 1000..40000")
    ref = _blackbody(REFERENCE_TEMPERATURE)
    rgb = _blackbody(float(kelvin))
    return (rgb[0] / ref[0], rgb[1] / ref[1], rgb[2] / ref[2])


def _blackbody(kelvin: float) -> tuple[float, float, float]:
    t = kelvin / 100.0
    red = 255.0 if t <= 66 else 329.698727446 * math.pow(t - 60, -0.1332047592)
    if t <= 66:
        green = 99.4708025861 * math.log(t) - 161.1195681661
    else:
        green = 288.1221695283 * math.pow(t - 60, -0.0755148492)
    if t >= 66:
        blue = 255.0
    elif t <= 19:
        blue = 0.0
    else:
        blue = 138.5177312231 * math.log(t - 10) - 305.0447927307
    clamp = lambda x: min(max(x, 1.0), 255.0)  # noqa: E731  (1, not 0: a channel never vanishes)
    return (clamp(red), clamp(green), clamp(blue))
