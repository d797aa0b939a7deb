"""One annotated view of a scene directory, for people to check (``sgdata render``)."""

from __future__ import annotations

from pathlib import Path

from sgdata.annotate.annotator import ViewAnnotator
from sgdata.annotate.records import ViewPose, ViewRecord
from sgdata.annotate.slots import SlotTable
from sgdata.errors import ConfigError
from sgdata.pipeline.config import AnnotationConfig
from sgdata.render.camera import CameraConfig
from sgdata.render.renderer import Renderer
from sgdata.usd.geometry import read_geometry
from sgdata.usd.scene_dirs import layout_stage_file, load_layout
from sgdata.world.catalog import Catalog, load_catalog
from sgdata.world.poses import HEADINGS_DEG, PosesConfig

__all__ = ["render_snapshot"]


def render_snapshot(
    room_dir: Path,
    *,
    layout: int,
    cell: tuple[int, int] | None,
    heading: int,
    camera: CameraConfig | None = None,
    poses: PosesConfig | None = None,
    annotation: AnnotationConfig | None = None,
    catalog: Catalog | None = None,
    textures: bool = True,
) -> ViewRecord:
    """Render and annotate the view at grid ``cell`` and ``heading`` (0..3) of a layout.

    ``cell=None`` takes the middle one of the layout's reachable cells (in index order);
    ``textures=False`` draws a textured room in its flat colours. ``camera``, ``poses`` and
    ``annotation`` are a run's ``[camera]``, ``[poses]`` and ``[annotation]`` (default: the
    defaults ``sgdata generate`` uses), so the view is the one that run would record.

    Raises:
        ConfigError: unknown room directory or layout, heading out of range, or a cell off the
            grid or not reachable in that layout (the message names reachable neighbours).
    """
    catalog = catalog or load_catalog()
    if not 0 <= heading < len(HEADINGS_DEG):
        raise ConfigError(f"heading {heading}: expected 0..3 (0/90/180/270 degrees)")
    room = load_layout(room_dir, layout, catalog)
    grid = (poses or PosesConfig()).grid(room)
    annotation = annotation or AnnotationConfig()
    if cell is None:
        if not grid.cells:
            raise ConfigError(f"{room_dir}: layout {layout} has no reachable cell to render from")
        cell = grid.cells[len(grid.cells) // 2]
    i, j = cell
    nx, ny = grid.shape
    if not (0 <= i < nx and 0 <= j < ny):
        raise ConfigError(f"pose {i},{j}: off the grid; this room's grid is {nx} x {ny} cells")
    if not grid.reachable[i, j]:
        nearest = sorted(grid.cells, key=lambda c: abs(c[0] - i) + abs(c[1] - j))[:3]
        raise ConfigError(
            f"pose {i},{j}: cell is blocked or unreachable in layout {layout}; "
            f"reachable cells nearby: {' '.join(f'{a},{b}' for a, b in nearest)}"
        )
    x, y, theta = grid.pose_world(i, j, heading)
    with Renderer(camera, textures=textures) as renderer:
        annotator = ViewAnnotator(
            renderer,
            SlotTable.from_catalog(catalog),
            min_visible_pixels=annotation.min_visible_pixels,
            rules=annotation.relations,
            keep_depth=True,  # read in the RGB pass: the channel strip costs no extra render
            keep_instances=True,
        )
        annotator.set_layout(room, read_geometry(layout_stage_file(room_dir, layout)), layout)
        return annotator.view(ViewPose(x, y, theta, i, j, heading))
