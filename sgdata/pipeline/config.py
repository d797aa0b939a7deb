"""Generation config: TOML files and presets mapped one to one onto frozen dataclasses.

Each TOML table is one dataclass: ``[dataset]`` -> :class:`DatasetConfig`, ``[rooms]`` ->
:class:`RoomsConfig`, ``[dynamics]`` -> :class:`sgdata.world.dynamics.DynamicsConfig`, ``[camera]``
-> :class:`sgdata.render.camera.CameraConfig`, ``[appearance]`` ->
:class:`sgdata.world.appearance.AppearanceConfig`, and so on. Unknown keys and wrong types are
refused with the file and key path in the message; every dataclass validates its own values.

Fields marked :data:`INTERNAL` are set by the loader, never read from TOML nor written to the
manifest (``RoomsConfig.base_dir``: the folder ``[rooms] files`` are relative to). Fields marked
:data:`SPARSE` reach the manifest only when set away from their default.
"""

from __future__ import annotations

import dataclasses
import math
import re
import types
import typing
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any, ClassVar

from sgdata.annotate.records import MIN_VISIBLE_PIXELS
from sgdata.annotate.relations import RelationRules
from sgdata.dataset.paths import SPLITS
from sgdata.errors import ConfigError, SgdataError
from sgdata.fileio import parse_toml
from sgdata.render.camera import CameraConfig
from sgdata.world.appearance import AppearanceConfig
from sgdata.world.catalog import Catalog, load_catalog
from sgdata.world.dynamics import DynamicsConfig
from sgdata.world.poses import PosesConfig
from sgdata.world.room_recipes import ROOM_TYPES
from sgdata.world.triplets import DEFAULT_SHARES, check_shares

__all__ = [
    "PRESETS",
    "AnnotationConfig",
    "AssetFile",
    "CatalogConfig",
    "DatasetConfig",
    "GenerateConfig",
    "ImagesConfig",
    "LayoutsConfig",
    "OutputsConfig",
    "PosesConfig",
    "INTERNAL",
    "SPARSE",
    "ROOM_TYPE_NAME",
    "RoomFile",
    "RoomsConfig",
    "TripletsConfig",
    "config_to_dict",
    "load_config",
]

PRESETS = ("tiny", "small", "medium", "paper")
INTERNAL = {"internal": True}  # field metadata: set by load_config, not a TOML key
# field metadata: written to the manifest only when set away from its default, so a knob added
# later leaves the bytes of every dataset made without it unchanged
SPARSE = {"sparse": True}
_ROOM_ID = re.compile(r"[A-Za-z0-9][A-Za-z0-9_-]*")
ROOM_TYPE_NAME = re.compile(r"[a-z][a-z0-9_]*")  # what a user room's type may be


@dataclass(frozen=True)
class DatasetConfig:
    """Identity of the dataset and the seed every random draw derives from."""

    name: str = "sgdata"
    version: str = "0.1.0"  # the dataset's own version (not the format's)
    seed: int = 0

    def __post_init__(self) -> None:
        if not self.name or any(c in self.name for c in "/\\ "):
            raise ConfigError(
                f"dataset.name {self.name!r}: expected a non-empty name without spaces or slashes"
            )
        if not 0 <= self.seed < 2**63:
            raise ConfigError(f"dataset.seed must be within [0, 2**63), got {self.seed}")


@dataclass(frozen=True)
class RoomFile:
    """A room the user brings (one ``[rooms] files`` entry): a USD file, tagged or not.

    In TOML a bare string is the path: ``files = ["a.usda", { path = "b.usda", split = "test" }]``.
    """

    SHORTHAND: ClassVar[str] = "path"  # a bare string in TOML sets this field

    path: str  # the USD file, relative to the config file's folder (or absolute); only read
    split: str = "train"  # train | val | test
    id: str = ""  # room id; default: the file's stem, characters other than A-Z a-z 0-9 _ - as _
    type: str = ""  # room_type of its rows; default: the file's sgdata:roomType, else "custom"
    sha256: str = ""  # the file's SHA-256, filled in by generation; pin it to refuse a change

    def __post_init__(self) -> None:
        where = f"rooms.files entry {self.path!r}"
        if not self.path:
            raise ConfigError("rooms.files: an entry with an empty path; expected a USD file")
        if self.split not in SPLITS:
            raise ConfigError(f"{where}: split {self.split!r}; expected one of {list(SPLITS)}")
        if not self.id:
            stem = re.sub(r"[^A-Za-z0-9_-]+", "_", Path(self.path).stem).strip("_-")
            object.__setattr__(self, "id", stem or "room")
        if not _ROOM_ID.fullmatch(self.id):
            raise ConfigError(
                f"{where}: id {self.id!r}; expected letters, digits, '_' and '-' "
                "(starting with a letter or digit)"
            )
        if self.type and not ROOM_TYPE_NAME.fullmatch(self.type):
            raise ConfigError(
                f"{where}: type {self.type!r}; expected lower-case letters, digits and '_'"
            )
        if self.sha256 and not re.fullmatch(r"[0-9a-f]{64}", self.sha256):
            raise ConfigError(f"{where}: sha256 {self.sha256!r}; expected 64 lower-case hex digits")


@dataclass(frozen=True)
class RoomsConfig:
    """Which rooms: procedural ones (per type, how many to each split; paper: 21 / 4 / 5) and
    the user's own USD rooms (``files``), which go to the split their entry names."""

    types: tuple[str, ...] | None = None  # None: all four types, or none when files are listed
    train: int = 21  # procedural rooms per type
    val: int = 4
    test: int = 5
    files: tuple[RoomFile, ...] = ()  # user rooms, in this order after the procedural ones
    classes: str = ""  # class file for the files' classes (aliases of catalog classes)
    base_dir: str = field(default="", metadata=INTERNAL)  # files' folder ("": working dir)
    # the largest room side and object side (metres) a user room may measure: beyond them it was
    # most likely modelled in other units (docs/rooms.md); raise them for rooms really that large
    max_room_size: float = field(default=30.0, metadata=SPARSE)
    max_object_size: float = field(default=5.0, metadata=SPARSE)

    def __post_init__(self) -> None:
        if self.types is None:
            object.__setattr__(self, "types", () if self.files else ROOM_TYPES)
        types = self.procedural_types
        unknown = [t for t in types if t not in ROOM_TYPES]
        if unknown or not (types or self.files):
            raise ConfigError(
                f"rooms.types {list(types)}: expected some of {list(ROOM_TYPES)} "
                "(or user rooms in rooms.files)"
            )
        for split in SPLITS:
            if getattr(self, split) < 0:
                raise ConfigError(f"rooms.{split} must be >= 0")
        if not self.files and self.train + self.val + self.test < 1:
            raise ConfigError("rooms: train + val + test must be at least 1")
        seen: dict[str, str] = {}
        for entry in self.files:
            if entry.id in seen:
                raise ConfigError(
                    f"rooms.files: {entry.path!r} and {seen[entry.id]!r} both get room id "
                    f'{entry.id!r}; give one another: {{ path = {entry.path!r}, id = "..." }}'
                )
            seen[entry.id] = entry.path
        for key in ("max_room_size", "max_object_size"):
            value = getattr(self, key)
            if not math.isfinite(value) or value <= 0:
                raise ConfigError(f"rooms.{key} must be a positive number of metres, got {value}")

    @property
    def procedural_types(self) -> tuple[str, ...]:
        """The room types of the procedural rooms (resolved: never ``None``)."""
        return self.types or ()

    def per_split(self) -> dict[str, int]:
        """Procedural rooms per type in each split."""
        return {s: getattr(self, s) for s in SPLITS}

    def resolve(self, path: str) -> Path:
        """A path of this section (a file entry, ``classes``) against ``base_dir``."""
        return Path(self.base_dir or ".") / Path(path).expanduser()


@dataclass(frozen=True)
class AssetFile:
    """A file the user's catalog reads (the catalog file, a mesh, a texture) with its SHA-256,
    filled in by generation (:func:`sgdata.pipeline.user_assets.resolve_user_assets`)."""

    SHORTHAND: ClassVar[str] = "path"  # a bare string in TOML sets this field

    path: str  # relative to the config file's folder (or absolute)
    sha256: str = ""

    def __post_init__(self) -> None:
        if not self.path:
            raise ConfigError("catalog.assets: an entry with an empty path")
        if self.sha256 and not re.fullmatch(r"[0-9a-f]{64}", self.sha256):
            raise ConfigError(
                f"catalog.assets entry {self.path!r}: sha256 {self.sha256!r}; expected 64 "
                "lower-case hex digits"
            )


@dataclass(frozen=True)
class CatalogConfig:
    """The object catalog: the shipped one merged with the user's catalog files, whose classes
    may be made of mesh files (docs/rooms.md, "Objects you bring")."""

    files: tuple[str, ...] = ()  # user catalog files, relative to the config's folder, in order
    assets: tuple[AssetFile, ...] = ()  # filled by generation: every file they read, hashed
    base_dir: str = field(default="", metadata=INTERNAL, compare=False)  # the config's folder

    def paths(self) -> tuple[Path, ...]:
        """The user catalog files, resolved against the config's folder."""
        return tuple(Path(self.base_dir or ".") / Path(p).expanduser() for p in self.files)

    def load(self) -> Catalog:
        """The catalog of a run: the shipped one with :meth:`paths` merged in (cached); its
        mesh classes may name USD / USDZ files too."""
        if self.files:
            from sgdata.usd.mesh_files import register_usd_mesh_reader  # late: pxr

            register_usd_mesh_reader()
        return load_catalog(extra=self.paths())


@dataclass(frozen=True)
class LayoutsConfig:
    """How many layouts each room gets (layout 0 is the base arrangement)."""

    count: int = 5  # the authors' code used 5

    def __post_init__(self) -> None:
        if self.count < 2:
            raise ConfigError(
                f"layouts.count must be >= 2 (tier 0 needs another layout), got {self.count}"
            )


@dataclass(frozen=True)
class AnnotationConfig:
    """What counts as visible, and the relation rules."""

    min_visible_pixels: int = MIN_VISIBLE_PIXELS  # fewer visible pixels: not in the view
    relations: RelationRules = field(default_factory=RelationRules)

    def __post_init__(self) -> None:
        if self.min_visible_pixels < 1:
            raise ConfigError(
                f"annotation.min_visible_pixels must be >= 1, got {self.min_visible_pixels}"
            )


@dataclass(frozen=True)
class TripletsConfig:
    """Triplets per split and the cascaded tier shares (paper Table I)."""

    train: int = 6650
    val: int = 1425
    test: int = 1425
    shares: tuple[float, ...] = DEFAULT_SHARES

    def __post_init__(self) -> None:
        for split in SPLITS:
            if getattr(self, split) < 0:
                raise ConfigError(f"triplets.{split} must be >= 0")
        check_shares(self.shares)

    def per_split(self) -> dict[str, int]:
        """Triplets in each split."""
        return {s: getattr(self, s) for s in SPLITS}


@dataclass(frozen=True)
class ImagesConfig:
    """How images are encoded in the observation rows."""

    format: str = "png"  # png (lossless, default) | jpeg
    jpeg_quality: int = 92

    def __post_init__(self) -> None:
        if self.format not in ("png", "jpeg"):
            raise ConfigError(f"images.format {self.format!r}: expected 'png' or 'jpeg'")
        if not 1 <= self.jpeg_quality <= 100:
            raise ConfigError(
                f"images.jpeg_quality must be within [1, 100], got {self.jpeg_quality}"
            )


@dataclass(frozen=True)
class OutputsConfig:
    """Which per-view channels the observation rows carry besides the RGB
    (:mod:`sgdata.dataset.channels`); each costs its encoding and bytes, not another render."""

    depth: bool = False  # metric depth, uint16 millimetres along the view axis, 0 = no hit
    instances: bool = False  # instance mask, uint16: 0 background, k = the k-th listed object


@dataclass(frozen=True)
class GenerateConfig:
    """Everything ``sgdata generate`` needs; the resolved form goes into the manifest."""

    dataset: DatasetConfig = field(default_factory=DatasetConfig)
    rooms: RoomsConfig = field(default_factory=RoomsConfig)
    layouts: LayoutsConfig = field(default_factory=LayoutsConfig)
    dynamics: DynamicsConfig = field(default_factory=DynamicsConfig)
    poses: PosesConfig = field(default_factory=PosesConfig)
    camera: CameraConfig = field(default_factory=CameraConfig)
    annotation: AnnotationConfig = field(default_factory=AnnotationConfig)
    triplets: TripletsConfig = field(default_factory=TripletsConfig)
    images: ImagesConfig = field(default_factory=ImagesConfig)
    appearance: AppearanceConfig = field(default_factory=AppearanceConfig)  # [appearance]
    outputs: OutputsConfig = field(default_factory=OutputsConfig)  # [outputs]: extra channels
    catalog: CatalogConfig = field(default_factory=CatalogConfig, metadata=SPARSE)  # [catalog]


def load_config(source: str | Path) -> GenerateConfig:
    """A config from a TOML file, or from a preset name (``tiny``, ``small``, ``paper``).

    Raises:
        ConfigError: unknown preset, unreadable or malformed TOML, unknown key, wrong type or
            out-of-range value — naming the file and the key.
    """
    text, where = _read(source)
    data = parse_toml(text, where)
    try:
        config = _build(GenerateConfig, data, "")
    except ConfigError as exc:
        raise ConfigError(f"{where}: {exc}") from None
    if isinstance(source, str) and source in PRESETS:
        return config
    folder = str(Path(source).resolve().parent)
    return dataclasses.replace(
        config,
        rooms=dataclasses.replace(config.rooms, base_dir=folder),
        catalog=dataclasses.replace(config.catalog, base_dir=folder),
    )


def config_to_dict(config: Any) -> Any:
    """Plain JSON-able form of a config (tuples become lists), for the manifest."""
    if dataclasses.is_dataclass(config):
        return {
            f.name: config_to_dict(getattr(config, f.name))
            for f in _public_fields(config)
            if not (f.metadata.get("sparse") and getattr(config, f.name) == _default(f))
        }
    if isinstance(config, dict):
        return {str(k): config_to_dict(v) for k, v in config.items()}
    if isinstance(config, tuple | list):
        return [config_to_dict(v) for v in config]
    return config


def _default(f: dataclasses.Field) -> Any:
    """A field's default value (made by its factory when it has one)."""
    if f.default_factory is not dataclasses.MISSING:
        return f.default_factory()
    return f.default


def _read(source: str | Path) -> tuple[str, str]:
    if isinstance(source, str) and source in PRESETS:
        preset = resources.files("sgdata_configs").joinpath(f"{source}.toml")
        return preset.read_text(encoding="utf-8"), f"preset {source}"
    path = Path(source)
    if not path.is_file():
        raise ConfigError(
            f"{path}: no such config file (or preset: expected one of {', '.join(PRESETS)})"
        )
    return path.read_text(encoding="utf-8"), str(path)


def _build(cls: type, data: Any, prefix: str) -> Any:
    """Instantiate dataclass ``cls`` from a TOML table, recursively, checking keys and types."""
    if not isinstance(data, dict):
        raise ConfigError(f"{prefix or 'config'}: expected a table")
    hints = typing.get_type_hints(cls)
    names = {f.name for f in _public_fields(cls)}
    unknown = sorted(set(data) - names)
    if unknown:
        key = f"{prefix}{unknown[0]}"
        raise ConfigError(f"unknown key {key!r}; known keys here: {', '.join(sorted(names))}")
    kwargs = {name: _convert(hints[name], value, f"{prefix}{name}") for name, value in data.items()}
    try:
        return cls(**kwargs)
    except SgdataError as exc:  # sections validate themselves (a camera raises RenderError)
        raise ConfigError(str(exc)) from None
    except TypeError as exc:
        raise ConfigError(f"{prefix.rstrip('.') or 'config'}: {exc}") from None


def _public_fields(cls: Any) -> list[dataclasses.Field]:
    """The fields a TOML table and the manifest have (not the :data:`INTERNAL` ones)."""
    return [f for f in dataclasses.fields(cls) if not f.metadata.get("internal")]


def _convert(hint: Any, value: Any, key: str) -> Any:
    if dataclasses.is_dataclass(hint):
        shorthand = getattr(hint, "SHORTHAND", None)
        if shorthand is not None and isinstance(value, str):
            value = {shorthand: value}
        return _build(hint, value, f"{key}.")
    origin = typing.get_origin(hint)
    args = typing.get_args(hint)
    if origin is tuple:
        if not isinstance(value, list):
            raise ConfigError(f"key {key!r}: expected a list, got {value!r}")
        item = args[0] if args else Any
        return tuple(_convert(item, v, f"{key}[{i}]") for i, v in enumerate(value))
    if origin is dict:
        if not isinstance(value, dict):
            raise ConfigError(f"key {key!r}: expected a table, got {value!r}")
        return {k: _convert(args[1], v, f"{key}.{k}") for k, v in value.items()}
    if origin in (typing.Union, types.UnionType):
        if value is None:
            return None
        return _convert(next(a for a in args if a is not type(None)), value, key)
    if hint is float:
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise ConfigError(f"key {key!r}: expected a number, got {value!r}")
        if not math.isfinite(value):  # TOML has nan and inf; no knob means them
            raise ConfigError(f"key {key!r}: expected a finite number, got {value!r}")
        return float(value)
    if hint is int or hint is bool or hint is str:
        if type(value) is not hint:
            raise ConfigError(f"key {key!r}: expected {hint.__name__}, got {value!r}")
        return value
    return value
