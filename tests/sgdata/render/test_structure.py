"""The structure mask drawn by the id pass: each structure pixel names the part of the room
the pixel's depth puts it on (wall, floor, ceiling), the door's opening is drawn only where
the wall has a gap, and objects keep their instance ids."""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from sgdata.pinhole import camera_to_world
from sgdata.render.renderer import Renderer
from sgdata.render.structure import face_parts
from sgdata.room_parts import CEILING, DOOR, FLOOR, STRUCTURE_PARTS, WALL
from sgdata.usd.room_io import door_quad

# views of the tiny room looking down, level, up, and along its walls
VIEWS = [(2.5, 1.0, np.pi / 2), (1.0, 1.0, 0.3), (4.2, 3.5, -2.5), (0.6, 2.0, np.pi)]


def room_points(renderer: Renderer, depth: np.ndarray, x: float, y: float, theta: float):
    """The room-frame point each pixel's depth (metres along the view axis) puts it on."""
    cam = renderer.camera
    v, u = np.mgrid[0 : cam.height, 0 : cam.width] + 0.5
    f = cam.focal
    xc, yc = (u - cam.width / 2) / f * depth, (v - cam.height / 2) / f * depth
    local = np.stack([xc, yc, depth, np.ones_like(depth)], axis=-1)  # OpenCV camera axes
    pose = camera_to_world(x, y, theta, cam.eye_height, cam.pitch_deg)
    return (local @ pose.T)[..., :3]


def test_each_structure_pixel_lies_on_its_part(tiny_renderer: Renderer, tiny_room: Any) -> None:
    room = tiny_room.room
    seen = set()
    for view in VIEWS:
        out = tiny_renderer.render(*view)
        assert out.structure.dtype == np.uint8 and out.structure.shape == out.instance.shape
        # every pixel is an object or a part of the closed room, never both
        assert np.array_equal(out.instance >= 0, out.structure == 0)
        p = room_points(tiny_renderer, out.depth, *view)
        z = p[..., 2]
        on_wall = np.minimum.reduce(
            [np.abs(p[..., 0]), np.abs(p[..., 0] - room.width),
             np.abs(p[..., 1]), np.abs(p[..., 1] - room.depth)]
        )  # fmt: skip
        tol = 0.02  # depth is float32 metres; a pixel's centre lies on its face
        assert np.all(np.abs(z[out.structure == FLOOR]) < tol)
        assert np.all(np.abs(z[out.structure == CEILING] - room.height) < tol)
        walls = out.structure == WALL
        assert np.all(on_wall[walls] < tol)
        assert np.all((z[walls] > -tol) & (z[walls] < room.height + tol))
        seen |= set(np.unique(out.structure).tolist())
    assert {WALL, FLOOR, CEILING} <= seen and DOOR not in seen  # the tiny room has no gap


def test_raster_and_raycast_agree_on_structure(tiny_renderer: Renderer) -> None:
    for view in VIEWS[:2]:
        raster = tiny_renderer.render(*view).structure
        tiny_renderer.id_pass = "raycast"
        try:
            raycast = tiny_renderer.render(*view).structure
        finally:
            tiny_renderer.id_pass = "raster"
        assert (raster != raycast).sum() <= 20  # only pixel centres on a shared edge


def test_the_door_is_drawn_where_the_wall_has_a_gap(renderer: Renderer, tiny_room: Any) -> None:
    """Cut a gap into the tiny room's south wall: the door's opening fills it, nothing is
    drawn there by the RGB pass (depth 0), and the instance ids do not change."""
    room = tiny_room.room
    door = dataclasses.replace(room.door, wall="south", center=2.5, width=1.0, top=2.0)
    room = dataclasses.replace(room, door=door)
    walls = tiny_room.geometry.structure[2]
    tris = walls.vertices[walls.faces]
    # drop the south wall (the faces all of whose corners lie at y <= 0) and rebuild it
    # around the gap as three boxes
    keep = ~np.all(tris[:, :, 1] <= 1e-9, axis=1)
    cut = dataclasses.replace(walls, faces=walls.faces[keep], face_colors=walls.face_colors[keep])
    pieces = [((-0.1, 2.0), (0.0, 2.6)), ((3.0, 5.1), (0.0, 2.6)), ((2.0, 3.0), (2.0, 2.6))]
    boxes = [_box(x0, x1, -0.1, 0.0, z0, z1) for (x0, x1), (z0, z1) in pieces]
    structure = (*tiny_room.geometry.structure[:2], cut, *boxes)
    geometry = dataclasses.replace(tiny_room.geometry, structure=structure)
    view = (2.5, 2.5, -np.pi / 2)  # facing the gap from the room's middle
    try:
        renderer.load(geometry)
        without = renderer.render(*view)
        renderer.load(dataclasses.replace(geometry, door=door_quad(room)))
        out = renderer.render(*view)
    finally:
        renderer.load(tiny_room.geometry)
    gap = out.structure == DOOR
    assert gap.sum() > 1000 and np.array_equal(without.instance, out.instance)
    assert np.all(out.depth[gap] == 0) and np.all(without.structure[gap] == 0)
    assert np.all(out.depth[~gap & (out.structure > 0)] > 0)
    assert np.array_equal(out.structure[~gap], without.structure[~gap])


def test_a_lintel_underside_is_wall_not_ceiling(tiny_room: Any) -> None:
    floor, ceiling, walls = tiny_room.geometry.structure
    lintel = _box(2.0, 3.0, -0.1, 0.0, 2.0, 2.6)  # its underside faces down at 2.0 m
    parts = face_parts((floor, ceiling, walls, lintel))
    assert set(parts[0].tolist()) == {FLOOR, WALL}  # the slab's top; its sides and bottom
    assert set(parts[1].tolist()) == {CEILING, WALL}
    assert set(parts[2].tolist()) == {WALL} and set(parts[3].tolist()) == {WALL}
    assert len(STRUCTURE_PARTS) == DOOR


def _box(x0: float, x1: float, y0: float, y1: float, z0: float, z1: float) -> Any:
    import trimesh

    from sgdata.usd.meshes import MeshData

    m = trimesh.creation.box(bounds=[(x0, y0, z0), (x1, y1, z1)])
    colors = np.full((len(m.faces), 3), 0.8, np.float32)
    return MeshData(np.asarray(m.vertices), np.asarray(m.faces, np.int32), colors)
