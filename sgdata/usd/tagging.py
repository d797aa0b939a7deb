"""``sgdata tag``: a user's own USD room made an sgdata room by a layer of the attributes it lacks.

The user's file is never written: the tag layer (by default ``<stem>_sgdata/room.usda`` beside
it, a room directory that ``sgdata layouts`` and ``sgdata render`` take) sublayers it and holds
``over`` specs with only the ``sgdata:*`` values the file lacks, measured by
:mod:`sgdata.usd.user_rooms`, plus ``sgdata:roomOrigin`` and ``sgdata:placements = "measured"``
(objects keep their own frames; placements are measured from geometry on every read).
Objects whose class the class file makes an alias get the catalog class as ``sgdata:class``.

``sgdata generate`` tags the rooms of ``[rooms] files`` the same way, over a flattened copy of
the user's stage inside the dataset (:func:`write_flattened`), naming each room's id, type and
seed itself.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from pxr import Gf, Sdf, Usd, UsdGeom

from sgdata.errors import ConfigError
from sgdata.scene_files import ROOM_FILE
from sgdata.usd.prims import ROOM_ORIGIN
from sgdata.usd.room_io import read_room
from sgdata.usd.stage import open_stage, validate_stage, write_usd_file
from sgdata.usd.stage_frame import room_prim
from sgdata.usd.user_rooms import MEASURED, measure_stage
from sgdata.world.catalog import Catalog, load_catalog
from sgdata.world.room_checks import room_problems
from sgdata.world.scene import Room
from sgdata.world.user_classes import read_class_file

__all__ = ["RoomNames", "TagReport", "default_output", "tag_stage", "write_flattened"]


@dataclass(frozen=True)
class TagReport:
    """What ``sgdata tag`` wrote and found."""

    source: Path  # the user's file, unchanged
    output: Path  # the tag layer written
    room: Room  # the room read back from the tagged stage
    inferred: tuple[str, ...]  # one line per value measured or assigned
    problems: tuple[str, ...]  # physical problems of the room (room_checks), for the user to fix
    usd_problems: tuple[str, ...]  # what USD's validators report on the tagged stage


@dataclass(frozen=True)
class RoomNames:
    """Room-prim values the tag layer authors even over the user's own (``sgdata generate``)."""

    room_id: str
    room_type: str
    seed: int


def default_output(stage_path: Path) -> Path:
    """``<folder>/<stem>_sgdata/room.usda``: a room directory beside the user's file."""
    return stage_path.parent / f"{stage_path.stem}_sgdata" / ROOM_FILE


def tag_stage(
    stage_path: Path,
    *,
    classes: Path | None = None,
    output: Path | None = None,
    catalog: Catalog | None = None,
    names: RoomNames | None = None,
    checks: bool = True,
) -> TagReport:
    """Write the tag layer of ``stage_path`` and read the tagged room back.

    Args:
        stage_path: the user's USD file (any up axis and ``metersPerUnit``).
        classes: a class file naming non-catalog classes with their dynamics, or aliases of
            catalog classes (:mod:`sgdata.world.user_classes`).
        output: the tag layer to write (default :func:`default_output`).
        catalog: the catalog giving known classes' dynamics (the shipped one when ``None``).
        names: the room's id, type and seed, authored whatever the file says (default: the
            file's own values, else its stem, ``custom`` and 0).
        checks: run the physical checks and USD's validators for the report (``problems``
            and ``usd_problems`` stay empty without).

    Raises:
        ConfigError: ``output`` would overwrite the user's file.
        UsdError: the stage cannot be read or measured (names the prim and attribute).
    """
    source = Path(stage_path)
    out = Path(output) if output is not None else default_output(source)
    if out.resolve() == source.resolve():
        raise ConfigError(f"{out}: is the stage itself; the user's file is never written")
    catalog = catalog or load_catalog()
    user_classes = read_class_file(classes, catalog)
    stage = open_stage(source)
    measured = measure_stage(stage, source, classes=user_classes.dynamics, catalog=catalog)
    layer = Sdf.Layer.CreateAnonymous(".usda")
    layer.subLayerPaths.append(_relative(source, out.parent))
    root = room_prim(stage)
    layer.defaultPrim = root.GetName()
    layer.pseudoRoot.SetInfo(UsdGeom.Tokens.upAxis, UsdGeom.GetStageUpAxis(stage))
    units = UsdGeom.StageHasAuthoredMetersPerUnit(stage)
    layer.pseudoRoot.SetInfo(
        UsdGeom.Tokens.metersPerUnit, float(UsdGeom.GetStageMetersPerUnit(stage)) if units else 1.0
    )
    _tag_room(layer, root, measured.room, measured.origin, names)
    by_instance = measured.room.by_instance()
    for instance, key in measured.paths.items():
        obj = by_instance[instance]
        _tag_object(layer, stage.GetPrimAtPath(key), obj, measured.paths)
        alias = user_classes.aliases.get(obj.class_name)
        if alias is not None:  # the catalog class it stands for, over the user's name
            spec = _spec(layer, stage.GetPrimAtPath(key))
            _attr(spec, None, "sgdata:class", Sdf.ValueTypeNames.String, alias)
    write_usd_file(out, layer.ExportToString())
    room = read_room(out)
    return TagReport(
        source=source,
        output=out,
        room=room,
        inferred=measured.inferred,
        problems=_problems(room, catalog) if checks else (),
        usd_problems=tuple(validate_stage(out)) if checks else (),
    )


def write_flattened(source: Path, output: Path, *, doc: str) -> None:
    """Write the composed stage of ``source`` as one self-contained layer at ``output``.

    Sublayers, references and variants are resolved into it, so a dataset's copy of a user's
    room depends on no file outside the dataset. ``doc`` replaces the layer's documentation
    (USD's default names the absolute path of ``source``, which would make the bytes depend on
    where the file lies).

    Raises:
        UsdError: ``source`` cannot be opened or composed, or ``output`` cannot be written.
    """
    layer = open_stage(Path(source)).Flatten()
    layer.documentation = doc
    write_usd_file(Path(output), layer.ExportToString())


def _relative(source: Path, folder: Path) -> str:
    rel = Path(os.path.relpath(source.resolve(), folder.resolve())).as_posix()
    return rel if rel.startswith("../") else f"./{rel}"


def _spec(layer: Sdf.Layer, prim: Usd.Prim) -> Sdf.PrimSpec:
    return Sdf.CreatePrimInLayer(layer, prim.GetPath())


def _attr(
    spec: Sdf.PrimSpec,
    prim: Usd.Prim | None,
    name: str,
    type_name: Sdf.ValueTypeName,
    value: object,
) -> None:
    """Author ``name`` on the over when the user's prim lacks a value for it (always when
    ``prim`` is ``None``)."""
    attr = prim.GetAttribute(name) if prim is not None else None
    if attr and attr.Get() is not None:
        return
    Sdf.AttributeSpec(spec, name, type_name, Sdf.VariabilityVarying, True).default = value


def _tag_room(
    layer: Sdf.Layer, root: Usd.Prim, room: Room, origin: tuple, names: RoomNames | None
) -> None:
    spec = _spec(layer, root)
    types = Sdf.ValueTypeNames
    if names is None:
        _attr(spec, root, "sgdata:roomId", types.String, room.room_id)
        _attr(spec, root, "sgdata:roomType", types.Token, room.room_type)
        _attr(spec, root, "sgdata:seed", types.Int64, room.seed)
    else:  # authored over whatever the user's file says
        _attr(spec, None, "sgdata:roomId", types.String, names.room_id)
        _attr(spec, None, "sgdata:roomType", types.Token, names.room_type)
        _attr(spec, None, "sgdata:seed", types.Int64, names.seed)
    _attr(
        spec, root, "sgdata:roomSize", types.Double3, Gf.Vec3d(room.width, room.depth, room.height)
    )
    _attr(spec, root, ROOM_ORIGIN, types.Double3, Gf.Vec3d(*origin))
    _attr(spec, root, MEASURED, types.Token, "measured")
    door = room.door
    _attr(spec, root, "sgdata:door:wall", types.Token, door.wall)
    _attr(spec, root, "sgdata:door:center", types.Double, door.center)
    _attr(spec, root, "sgdata:door:width", types.Double, door.width)
    _attr(spec, root, "sgdata:door:top", types.Double, door.top)


def _tag_object(layer: Sdf.Layer, prim: Usd.Prim, obj, paths: dict[int, str]) -> None:  # noqa: ANN001
    spec = _spec(layer, prim)
    types = Sdf.ValueTypeNames
    _attr(spec, prim, "sgdata:instance", types.Int, obj.instance)
    _attr(spec, prim, "sgdata:dynamics", types.Token, str(obj.dynamics))
    _attr(spec, prim, "sgdata:size", types.Float3, Gf.Vec3f(*obj.size))
    if obj.support is not None and not prim.GetRelationship("sgdata:support"):
        rel = Sdf.RelationshipSpec(spec, "sgdata:support", True)
        rel.targetPathList.explicitItems = [Sdf.Path(paths[obj.support])]


def _problems(room: Room, catalog: Catalog) -> tuple[str, ...]:
    """Physical problems (room_checks); they need every class's recipe, so only catalog rooms."""
    unknown = sorted({o.class_name for o in room.objects if o.class_name not in catalog})
    if unknown:
        return (f"physical checks skipped: classes {unknown} are not in the catalog",)
    return tuple(room_problems(room, catalog))
