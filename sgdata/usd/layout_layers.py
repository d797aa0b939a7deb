"""Layouts as USD layers: ``layout_<k>.usda`` overrides the moved objects of its ``room.usda``.

A layout layer sublayers ``./room.usda`` and holds only ``over`` specs for
``/Room/Objects/<prim>``: ``xformOp:translate`` and ``xformOp:rotateZ`` for an object whose
placement differs from the room's, and ``sgdata:support`` where its support changed (an
explicit empty target list when it now rests on the floor). Read a layout's composed room with
:func:`sgdata.usd.room_io.read_room`. A layout that draws its own appearance also overrides its
light and the looks of its low- and high-dynamic objects (:mod:`sgdata.usd.looks`).

Provenance lives in the layer's ``customLayerData``: ``sgdata:layout`` (int, the layout index),
``sgdata:seed`` (int64) and ``sgdata:moves``, a JSON string holding the list of move records
(``{instance, class, rule, from, to, fromSupport, toSupport, moved}``). JSON because USD text
layers cannot hold a list of dictionaries nor ``None``; it round-trips any JSON-able moves.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
from pxr import Gf, Sdf, UsdGeom, Vt

from sgdata.errors import SceneError, UsdError
from sgdata.scene_files import ROOM_FILE
from sgdata.usd.looks import RoomParts, define_layout_materials, override_light, override_look
from sgdata.usd.prims import ROOT, object_path
from sgdata.usd.stage import open_layer, write_usd_file
from sgdata.usd.user_layouts import UserFrame, override_user
from sgdata.world.appearance import LayoutAppearance
from sgdata.world.scene import Room, SceneObject

__all__ = ["PLACEMENT_TOLERANCE", "write_layout", "read_layout_provenance"]

PLACEMENT_TOLERANCE = 1e-9  # placements closer than this (m, rad) count as unchanged

_KEY_LAYOUT, _KEY_SEED, _KEY_MOVES = "sgdata:layout", "sgdata:seed", "sgdata:moves"


def write_layout(
    base: Room,
    layout: Room,
    path: Path,
    *,
    index: int,
    seed: int,
    moves: list[dict],
    user: UserFrame | None = None,
    appearance: LayoutAppearance | None = None,
    parts: RoomParts | None = None,
) -> None:
    """Write ``layout`` as a layer over ``base``, atomically and byte-reproducibly.

    Args:
        base: the room as written to ``room.usda`` next to ``path``.
        layout: the same objects (same instances and classes), some moved.
        path: the layer to write, conventionally ``sgdata.scene_files.layout_file(room_dir, k)``.
        index: the layout index k, stored as provenance.
        seed: the seed the layout was sampled from, stored as provenance.
        moves: one record per object move (JSON-able values), stored as provenance.
        user: for a room authored elsewhere (:func:`sgdata.usd.user_layouts.user_frame`): its
            prim paths and frame; moves are then written as each prim's local matrix.
        appearance: the layout's light and object looks (:func:`sgdata.world.appearance.
            sample_appearance`), written with ``parts`` (:func:`sgdata.usd.looks.
            read_room_parts` of the room); ``None`` keeps the room's looks and light.

    Raises:
        SceneError: ``layout`` does not hold the same objects as ``base``, or the moves are
            not JSON-able.
        UsdError: the file cannot be written.
    """
    before = base.by_instance()
    after = layout.by_instance()
    if set(before) != set(after):
        extra = sorted(set(before) ^ set(after))
        raise SceneError(
            f"layout {index} of room {base.room_id}: instances {extra[:5]} are not in both the "
            f"room and the layout; a layout only moves the room's objects"
        )
    if not -(2**63) <= seed < 2**63:
        raise SceneError(f"layout {index} seed {seed} does not fit USD's int64; use one < 2**63")
    layer = Sdf.Layer.CreateAnonymous(".usda")
    layer.subLayerPaths.append(f"./{ROOM_FILE}")
    layer.defaultPrim = user.default_prim if user else ROOT.name
    layer.pseudoRoot.SetInfo(UsdGeom.Tokens.upAxis, user.up_axis if user else UsdGeom.Tokens.z)
    layer.pseudoRoot.SetInfo(UsdGeom.Tokens.metersPerUnit, user.meters_per_unit if user else 1.0)
    try:
        moves_json = json.dumps(moves, sort_keys=True, allow_nan=False, default=_plain)
    except (TypeError, ValueError) as exc:
        raise SceneError(
            f"layout {index} of room {base.room_id}: moves not JSON-able ({exc})"
        ) from None
    layer.customLayerData = {
        _KEY_LAYOUT: int(index),
        _KEY_SEED: Vt.Int64(int(seed)),
        _KEY_MOVES: moves_json,
    }
    materials: dict = {}  # tinted materials the new looks use, defined after the objects
    for old in base.objects:  # in room order, so the composed prim order stays the room's
        new = after[old.instance]
        if new.class_name != old.class_name:
            raise SceneError(
                f"layout {index}: instance {old.instance} is a {new.class_name} in the layout "
                f"but a {old.class_name} in room {base.room_id}"
            )
        _override(layer, old, new, before, after, user)
        if appearance is not None and parts is not None and old.instance in appearance.looks:
            override_look(layer, parts, old.instance, appearance.looks[old.instance], materials)
    if appearance is not None and parts is not None:
        define_layout_materials(layer, materials)
        override_light(layer, parts, appearance)
    write_usd_file(path, layer.ExportToString())


def _override(
    layer: Sdf.Layer,
    old: SceneObject,
    new: SceneObject,
    objects: dict[int, SceneObject],
    after: dict[int, SceneObject],
    user: UserFrame | None,
) -> None:
    a, b = old.placement, new.placement
    moved = any(
        abs(u - v) > PLACEMENT_TOLERANCE
        for u, v in ((a.x, b.x), (a.y, b.y), (a.z, b.z), (a.yaw, b.yaw))
    )
    resupported = old.support != new.support
    if not (moved or resupported):
        return
    where = Sdf.Path(user.paths[old.instance]) if user else object_path(old)
    spec = Sdf.CreatePrimInLayer(layer, where)
    if moved and user is not None:
        override_user(layer, user, objects, after, old.instance)
    elif moved:
        translate = Sdf.AttributeSpec(
            spec, "xformOp:translate", Sdf.ValueTypeNames.Double3, Sdf.VariabilityVarying, False
        )
        translate.default = Gf.Vec3d(b.x, b.y, b.z)
        rotate = Sdf.AttributeSpec(
            spec, "xformOp:rotateZ", Sdf.ValueTypeNames.Double, Sdf.VariabilityVarying, False
        )
        rotate.default = math.degrees(b.yaw)
    if resupported:
        rel = Sdf.RelationshipSpec(spec, "sgdata:support", True)
        rel.targetPathList.ClearEditsAndMakeExplicit()
        if new.support is not None:
            if new.support not in objects:
                raise SceneError(
                    f"layout: object {new.prim_name} rests on instance {new.support}, "
                    f"not in the room"
                )
            target = objects[new.support]
            rel.targetPathList.explicitItems = [
                Sdf.Path(user.paths[target.instance]) if user else object_path(target)
            ]


def read_layout_provenance(path: Path) -> dict[str, Any]:
    """The provenance of a layout layer: ``{"layout": k, "seed": int, "moves": [...]}``.

    Only the layer itself is read (its room need not be present).

    Raises:
        UsdError: the file is missing or unreadable, or holds no sgdata layout provenance.
    """
    path = Path(path)
    data = dict(open_layer(path).customLayerData)
    missing = [k for k in (_KEY_LAYOUT, _KEY_SEED, _KEY_MOVES) if k not in data]
    if missing:
        raise UsdError(f"{path}: customLayerData lacks {missing[0]}; not an sgdata layout layer")
    try:
        moves = json.loads(data[_KEY_MOVES])
    except (TypeError, ValueError):
        raise UsdError(f"{path}: customLayerData {_KEY_MOVES} is not a JSON list") from None
    if not isinstance(moves, list):
        raise UsdError(f"{path}: customLayerData {_KEY_MOVES} is not a JSON list")
    return {"layout": int(data[_KEY_LAYOUT]), "seed": int(data[_KEY_SEED]), "moves": moves}


def _plain(value: Any) -> Any:
    """JSON fallback for numpy scalars and arrays, and tuples nested in them."""
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    raise TypeError(f"{type(value).__name__} is not JSON-able")
