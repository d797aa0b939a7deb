"""Procedural shapes: one recipe per kind of object, composed from trimesh primitives.

A recipe turns (size, variant, colour) into a :class:`ShapeBuild` in the object's local frame
(origin at the bottom centre, front facing -Y, see :mod:`sgdata.world.scene`): coloured parts, the
surfaces it offers to other objects, and the attached parts it brings along (shelf boards,
sink basins) which become objects of their own. Recipes are deterministic: the same inputs
give the same mesh, so a room's USD file is reproducible.
"""

from __future__ import annotations

# importing the recipe modules registers their recipes
from sgdata.world.shapes import fixtures, furniture, household, kitchenware, small, toiletries  # noqa: F401
from sgdata.world.shapes.base import (
    RECIPES,
    Attachment,
    Part,
    PartTexture,
    ShapeBuild,
    Surface,
    build_shape,
    merged_mesh,
    merged_textures,
)
from sgdata.world.shapes.uvs import box_uvs

__all__ = [
    "RECIPES",
    "Attachment",
    "Part",
    "PartTexture",
    "ShapeBuild",
    "Surface",
    "box_uvs",
    "build_shape",
    "merged_mesh",
    "merged_textures",
]
