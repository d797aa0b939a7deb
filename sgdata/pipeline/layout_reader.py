"""A room's layout stages read one ahead, on a background thread, while the one before renders.

Reading a layout (:func:`sgdata.usd.room_io.read_scene`: open and compose its stage, read its
meshes) is pure CPU, about a quarter of a second for a textured room on a 2-core host, and
the views of the layout before it spend most of their time in the renderer's draw and
read-back, which release the GIL. So one reading thread overlaps the two: a worker with a spare
core hides the reads of every layout but a room's first (with as many workers as cores there
is no core to spare, and no gain). The layouts are read in order, each
by itself, with the room's :class:`~sgdata.usd.layout_meshes.LayoutMeshes`, so what comes back
is what reading them one after the other in the worker's own thread gives. A worker hands
every room the same one-thread pool (:func:`reading_pool`), so its threads do not grow with
the rooms it renders.
"""

from __future__ import annotations

from collections.abc import Sequence
from concurrent.futures import Future, ThreadPoolExecutor, wait
from pathlib import Path
from types import TracebackType

from sgdata.usd.layout_meshes import LayoutMeshes
from sgdata.usd.meshes import SceneGeometry
from sgdata.usd.room_io import read_scene
from sgdata.world.scene import Room

__all__ = ["LayoutReader", "reading_pool"]


def reading_pool() -> ThreadPoolExecutor:
    """A pool of the one thread layouts are read on (a worker keeps one for all its rooms)."""
    return ThreadPoolExecutor(max_workers=1, thread_name_prefix="sgdata-read")


class LayoutReader:
    """The scenes of ``paths`` (one room's layout stages), in order; each call of :meth:`next`
    starts reading the one after it.

    Use as a context manager: leaving it (an error included) waits for the read in flight, so
    nothing of the room is still being read once the room's task ends.
    """

    def __init__(self, paths: Sequence[Path], pool: ThreadPoolExecutor) -> None:
        self._paths = list(paths)
        self._pool = pool
        self._meshes = LayoutMeshes()  # what the room's layouts share is read once
        self._read = 0  # layouts handed out
        self._pending: Future[tuple[Room, SceneGeometry]] | None = self._start(0)

    def __enter__(self) -> LayoutReader:
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        if self._pending is not None:
            self._pending.cancel()
            wait([self._pending])
            self._pending = None

    def next(self) -> tuple[Room, SceneGeometry]:
        """The next layout's room and meshes, once read; the one after it starts reading.

        Raises:
            UsdError: the layout cannot be read (as :func:`~sgdata.usd.room_io.read_scene`).
            IndexError: every layout was handed out already.
        """
        if self._pending is None:
            raise IndexError(f"all {len(self._paths)} layouts were read")
        scene = self._pending.result()
        self._read += 1
        self._pending = self._start(self._read)
        return scene

    def _start(self, k: int) -> Future[tuple[Room, SceneGeometry]] | None:
        if k >= len(self._paths):
            return None
        return self._pool.submit(read_scene, self._paths[k], self._meshes)
