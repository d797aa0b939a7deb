"""The prim-path contract of a room stage: prim paths and attribute names read and written alike.

Writers (:mod:`sgdata.usd.room_io`, :mod:`sgdata.usd.looks`, :mod:`sgdata.usd.materials`,
:mod:`sgdata.usd.tagging`) and readers (:mod:`sgdata.usd.geometry`,
:mod:`sgdata.usd.stage_frame`, :mod:`sgdata.usd.user_rooms`) import these names from here, so
this module imports nothing of sgdata's at run time and can never close an import circle.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from pxr import Sdf

if TYPE_CHECKING:
    from sgdata.world.scene import SceneObject

__all__ = [
    "LIGHT_INTENSITY",
    "LIGHT_TEMPERATURE",
    "LOOKS",
    "LOOK_TEXTURE",
    "LOOK_TINT",
    "LOOK_VARIANT",
    "OBJECTS",
    "ROOM_ORIGIN",
    "ROOT",
    "STRUCTURE",
    "object_path",
]

ROOT = Sdf.Path("/Room")  # the room prim of sgdata's own stages
OBJECTS = ROOT.AppendChild("Objects")  # one child per object instance
STRUCTURE = ROOT.AppendChild("Structure")  # Floor, Ceiling, Walls meshes
LOOKS = ROOT.AppendChild("Looks")  # the materials of a textured room

# on the room prim: the point (double3, metres, up-corrected axes) that becomes the room origin
ROOM_ORIGIN = "sgdata:roomOrigin"
# on the room prim: scale of the renderer's default lights (float) and their colour (Kelvin)
LIGHT_INTENSITY = "sgdata:light:intensity"
LIGHT_TEMPERATURE = "sgdata:light:colorTemperature"
# on each object prim: its body's texture kind (token), texture variant (int) and tint (color3f)
LOOK_TEXTURE = "sgdata:look:texture"
LOOK_VARIANT = "sgdata:look:variant"
LOOK_TINT = "sgdata:look:tint"


def object_path(obj: SceneObject) -> Sdf.Path:
    """The prim path of an object: ``/Room/Objects/<Class>_<instance:04d>``."""
    return OBJECTS.AppendChild(obj.prim_name)
