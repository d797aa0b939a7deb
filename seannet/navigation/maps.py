"""Topological maps of rooms (paper §VI-A): sub-nodes with views and embeddings, on disk.

A map covers one layout of one room. Its nodes are the cells of the layout's reachable grid
whose indices are multiples of ``spacing`` (1: every cell; the authors used 2); each node has
four heading sub-nodes ``(i, j, h)``, each holding its observation id, its image and its
vector by one localizer (a trained run or any method: what the method's similarity reads,
boxes included for a method that scores them). Edges (networkx, directed):

- **translation** between the same heading of two neighbouring nodes (``spacing`` cells apart
  along i or j, every cell on the way reachable), cost the Manhattan distance in cells;
  forward or sideways of the heading, never backward: the robot has no backward move, so a
  sub-goal behind it is reached by turning first;
- **rotation** between headings 90 degrees apart inside a node, cost 1, both ways.

Every sub-node is rendered live from the room's scene files
(:class:`seannet.data.live_views.LiveRooms`),
so a map has no holes even though a dataset holds only the views its triplets referenced.

On disk, a map directory holds ``map.parquet`` (one row per sub-node: obs_id, i, j, heading,
embedding, image) and ``map.json`` (graph parameters and edges, the localizer's digest: a
run's checkpoint sha256 or a method's, and the dataset's identity); both are written
atomically, so a map is built once and reused.
"""

from __future__ import annotations

import io
import json
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import networkx as nx
import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from seannet.data.live_views import LiveRooms
from seannet.data.opening import DataSource
from seannet.errors import MapError
from seannet.navigation.config import MAP_SPACING
from seannet.navigation.localizer import AnyLocalizer
from seannet.navigation.motion import HEADINGS, local_offset
from sgdata.dataset import decode_image
from sgdata.dataset.paths import obs_id
from sgdata.dataset.rows import encode_image
from sgdata.fileio import atomic_write_bytes, atomic_write_text

__all__ = [
    "MAP_META",
    "MAP_TABLE",
    "SubNode",
    "TopoMap",
    "build_map",
    "build_maps",
    "check_map",
    "current_map",
    "derive_map",
    "ensure_map",
    "load_map",
    "map_dirs",
    "map_nodes",
    "save_map",
    "translation_edges",
]

MAP_TABLE, MAP_META = "map.parquet", "map.json"
MAP_FORMAT = 1  # bump when the map files change
ROTATION_COST = 1  # one 90 degree turn

SubNode = tuple[int, int, int]  # (grid i, grid j, heading index)


def map_nodes(reachable: np.ndarray, spacing: int) -> list[tuple[int, int]]:
    """Node cells: reachable cells whose indices are both multiples of ``spacing``."""
    if spacing < 1:
        raise MapError(f"map spacing {spacing}: expected >= 1 cell")
    return [
        (int(i), int(j))
        for i, j in zip(*np.nonzero(reachable), strict=True)
        if i % spacing == 0 and j % spacing == 0
    ]


def translation_edges(
    reachable: np.ndarray, nodes: Iterable[tuple[int, int]], spacing: int
) -> list[tuple[int, int, int, int]]:
    """``(i1, j1, i2, j2)`` of neighbouring nodes joined by a reachable straight run of cells."""
    have = set(nodes)
    edges = []
    for i, j in sorted(have):
        for di, dj in ((1, 0), (0, 1)):
            other = (i + di * spacing, j + dj * spacing)
            if other not in have:
                continue
            if all(reachable[i + di * k, j + dj * k] for k in range(1, spacing)):
                edges.append((i, j, *other))
    return edges


@dataclass
class TopoMap:
    """One room's map in one layout: sub-node rows plus graph parameters (see module doc)."""

    meta: dict[str, Any]  # map.json: room_id, layout, spacing, cell, edges, run, dataset, ...
    i: np.ndarray  # (N,) int
    j: np.ndarray  # (N,) int
    heading: np.ndarray  # (N,) int
    obs_ids: list[str]
    embeddings: np.ndarray  # (N, D) float32: the localizer's vectors (unit rows for cosine)
    images: list[bytes]  # encoded in the dataset's image format
    _graph: nx.DiGraph | None = field(default=None, repr=False)
    _index: dict[SubNode, int] | None = field(default=None, repr=False)

    @property
    def room_id(self) -> str:
        return str(self.meta["room_id"])

    @property
    def layout(self) -> int:
        return int(self.meta["layout"])

    @property
    def spacing(self) -> int:
        return int(self.meta["spacing"])

    def sub_nodes(self) -> list[SubNode]:
        """Sub-nodes ``(i, j, h)`` in row order."""
        return [
            (int(a), int(b), int(c)) for a, b, c in zip(self.i, self.j, self.heading, strict=True)
        ]

    def index(self, key: SubNode) -> int:
        """Row of sub-node ``key``.

        Raises:
            MapError: ``key`` is not a sub-node of this map.
        """
        if self._index is None:
            self._index = {k: n for n, k in enumerate(self.sub_nodes())}
        try:
            return self._index[tuple(int(v) for v in key)]  # type: ignore[index]
        except KeyError:
            raise MapError(f"map of {self.room_id}: no sub-node {key}") from None

    def image(self, key: SubNode) -> np.ndarray:
        """The stored view of a sub-node, (H, W, 3) uint8."""
        return decode_image(self.images[self.index(key)])

    def embedding(self, key: SubNode) -> np.ndarray:
        return self.embeddings[self.index(key)]

    def graph(self) -> nx.DiGraph:
        """Sub-node graph: translation and rotation edges with ``cost`` and ``kind``;
        directed, a translation never backward of its heading (see the module doc)."""
        if self._graph is None:
            g = nx.DiGraph()
            g.add_nodes_from(self.sub_nodes())
            for i, j in sorted({(a, b) for a, b, _ in self.sub_nodes()}):
                for h in range(HEADINGS):
                    turn = ((i, j, h), (i, j, (h + 1) % HEADINGS))
                    g.add_edge(*turn, cost=ROTATION_COST, kind="rotation")
                    g.add_edge(*turn[::-1], cost=ROTATION_COST, kind="rotation")
            for i1, j1, i2, j2 in self.meta["edges"]:
                cost = abs(i2 - i1) + abs(j2 - j1)
                for h in range(HEADINGS):
                    for a, b in (((i1, j1), (i2, j2)), ((i2, j2), (i1, j1))):
                        if local_offset((*a, h), b)[0] >= 0:  # ahead or sideways
                            g.add_edge((*a, h), (*b, h), cost=cost, kind="translation")
            self._graph = g
        return self._graph

    def shortest_path(
        self,
        start: SubNode,
        goal: SubNode,
        *,
        avoid: Iterable[frozenset[tuple[int, int]]] = (),
    ) -> list[SubNode]:
        """Dijkstra's path from ``start`` to ``goal`` (both included).

        Args:
            avoid: translation edges, each the pair of its node cells, not to use (at any
                heading): edges a robot found blocked.

        Raises:
            MapError: either is not a sub-node, or the goal cannot be reached.
        """
        self.index(start), self.index(goal)
        graph = self.graph()
        cut = [
            ((*a, h), (*b, h))
            for pair in avoid
            for a, b in (sorted(pair), sorted(pair)[::-1])
            for h in range(HEADINGS)
            if graph.has_edge((*a, h), (*b, h))
        ]
        if cut:
            graph = nx.restricted_view(graph, [], cut)
        try:
            return list(nx.dijkstra_path(graph, tuple(start), tuple(goal), weight="cost"))
        except nx.NetworkXNoPath:
            raise MapError(f"map of {self.room_id}: no path from {start} to {goal}") from None


# ---------------------------------------------------------------------------------- building


def build_map(
    localizer: AnyLocalizer,
    live: LiveRooms,
    room_id: str,
    *,
    layout: int = 0,
    spacing: int = MAP_SPACING,
) -> TopoMap:
    """Render every sub-node of ``room_id``'s ``layout`` and embed it with ``localizer``.

    Raises:
        DataError: no such room or layout in the dataset.
        MapError: bad spacing, or the layout has no node.
    """
    live.load(room_id, layout)
    grid = live.grid
    nodes = map_nodes(grid.reachable, spacing)
    if not nodes:
        raise MapError(f"{room_id} layout {layout}: no reachable cell on a {spacing}-cell spacing")
    keys = [(i, j, h) for i, j in nodes for h in range(HEADINGS)]
    transform = localizer.transform
    fmt, quality = live.settings.image_format, live.settings.jpeg_quality
    views, images = [], []
    for i, j, h in keys:
        record = live.view(i, j, h)
        views.append(live.tensors(record, transform))
        images.append(encode_image(record.rgb, fmt, jpeg_quality=quality))
    embeddings = localizer.embed(views)
    meta = {
        "format": MAP_FORMAT,
        "room_id": room_id,
        "layout": int(layout),
        "spacing": int(spacing),
        "cell": float(grid.cell),
        "grid_shape": list(grid.shape),
        "rotation_cost": ROTATION_COST,
        "edges": [list(e) for e in translation_edges(grid.reachable, nodes, spacing)],
        "nodes": len(nodes),
        "sub_nodes": len(keys),
        "image_format": fmt,
        "run": localizer.source,
        "model": localizer.name,
        "checkpoint_sha256": localizer.digest,
        "embed_dim": int(embeddings.shape[1]),
        "dataset": localizer.identity,
        "data": str(live.data.resolve()),
    }
    return TopoMap(
        meta=meta,
        i=np.array([k[0] for k in keys]),
        j=np.array([k[1] for k in keys]),
        heading=np.array([k[2] for k in keys]),
        obs_ids=[obs_id(room_id, layout, *k) for k in keys],
        embeddings=embeddings,
        images=images,
    )


def derive_map(full: TopoMap, spacing: int) -> TopoMap:
    """The map at ``spacing`` that :func:`build_map` would build, taken from ``full``, a map of
    the same run, room and layout at spacing 1: its nodes are every reachable cell, so it
    holds the reachable grid, and the sub-nodes kept need no render or embedding again.

    Raises:
        MapError: ``full`` is not a spacing-1 map, or no node is left.
    """
    if full.spacing != 1:
        raise MapError(
            f"map of {full.room_id}: spacing {full.spacing}; derive from a spacing-1 map"
        )
    reachable = np.zeros(tuple(full.meta["grid_shape"]), dtype=bool)
    reachable[full.i, full.j] = True
    nodes = map_nodes(reachable, spacing)
    if not nodes:
        raise MapError(f"{full.room_id}: no reachable cell on a {spacing}-cell spacing")
    keep = np.flatnonzero((full.i % spacing == 0) & (full.j % spacing == 0))
    meta = {
        **full.meta,
        "spacing": int(spacing),
        "edges": [list(e) for e in translation_edges(reachable, nodes, spacing)],
        "nodes": len(nodes),
        "sub_nodes": len(keep),
    }
    return TopoMap(
        meta=meta,
        i=full.i[keep],
        j=full.j[keep],
        heading=full.heading[keep],
        obs_ids=[full.obs_ids[k] for k in keep],
        embeddings=full.embeddings[keep],
        images=[full.images[k] for k in keep],
    )


def save_map(topo: TopoMap, directory: Path) -> None:
    """Write ``map.parquet`` then ``map.json`` (each atomically) into ``directory``."""
    dim = topo.embeddings.shape[1]
    flat = pa.array(topo.embeddings.astype(np.float32).ravel(), type=pa.float32())
    table = pa.table(
        {
            "obs_id": pa.array(topo.obs_ids, type=pa.string()),
            "grid_i": pa.array(topo.i, type=pa.int16()),
            "grid_j": pa.array(topo.j, type=pa.int16()),
            "heading": pa.array(topo.heading, type=pa.int8()),
            "embedding": pa.FixedSizeListArray.from_arrays(flat, dim),
            "image": pa.array(topo.images, type=pa.binary()),
        }
    )
    buffer = io.BytesIO()
    pq.write_table(table, buffer)
    atomic_write_bytes(directory / MAP_TABLE, buffer.getvalue())
    atomic_write_text(directory / MAP_META, json.dumps(topo.meta, indent=1))


def load_map(directory: Path) -> TopoMap:
    """Read a map written by :func:`save_map`.

    Raises:
        MapError: a file is missing, unreadable, or of another map format.
    """
    meta_path, table_path = directory / MAP_META, directory / MAP_TABLE
    for path in (meta_path, table_path):
        if not path.is_file():
            raise MapError(f"{path}: no map here (build one with `seannet map`)")
    try:
        meta = json.loads(meta_path.read_text())
    except ValueError as exc:
        raise MapError(f"{meta_path}: not JSON ({exc})") from None
    if not isinstance(meta, dict) or meta.get("format") != MAP_FORMAT:
        raise MapError(f"{meta_path}: format is not {MAP_FORMAT}; rebuild the map")
    for key in ("room_id", "layout", "spacing", "edges", "checkpoint_sha256", "dataset"):
        if key not in meta:
            raise MapError(f"{meta_path}: field {key!r} is missing; rebuild the map")
    try:
        table = pq.read_table(table_path)
        emb = table.column("embedding").combine_chunks()
        dim = emb.type.list_size
        return TopoMap(
            meta=meta,
            i=table.column("grid_i").to_numpy().astype(np.int64),
            j=table.column("grid_j").to_numpy().astype(np.int64),
            heading=table.column("heading").to_numpy().astype(np.int64),
            obs_ids=table.column("obs_id").to_pylist(),
            embeddings=emb.flatten().to_numpy().astype(np.float32).reshape(-1, dim),
            images=table.column("image").to_pylist(),
        )
    except (pa.ArrowException, KeyError, AttributeError) as exc:
        raise MapError(f"{table_path}: unreadable map table ({exc})") from None


def check_map(topo: TopoMap, localizer: AnyLocalizer, where: Path) -> None:
    """Refuse a map whose vectors another checkpoint, method or dataset made.

    Raises:
        MapError: naming ``map.json`` and the field that differs.
    """
    path = where / MAP_META
    if topo.meta["checkpoint_sha256"] != localizer.digest:
        raise MapError(
            f"{path}: checkpoint_sha256 differs from {localizer.source}'s; the map was built "
            f"by another run or method (rebuild it with `seannet map {localizer.source}`)"
        )
    if topo.meta["dataset"] != localizer.identity:
        raise MapError(f"{path}: dataset differs from the localizer's; use the map's dataset")


def current_map(
    localizer: AnyLocalizer,
    room_id: str,
    directory: Path,
    *,
    layout: int = 0,
    spacing: int = MAP_SPACING,
) -> TopoMap | None:
    """The map in ``directory`` if this run built it for ``room_id`` with these parameters;
    None when it is missing, stale or damaged (then it is to be built again)."""
    if not (directory / MAP_META).is_file():
        return None
    try:
        topo = load_map(directory)
        check_map(topo, localizer, directory)
    except MapError:
        return None
    return topo if (topo.room_id, topo.layout, topo.spacing) == (room_id, layout, spacing) else None


def ensure_map(
    localizer: AnyLocalizer,
    live: LiveRooms,
    room_id: str,
    directory: Path,
    *,
    layout: int = 0,
    spacing: int = MAP_SPACING,
) -> TopoMap:
    """The map in ``directory`` if it was built by this run with these parameters, else a new
    one built and saved there."""
    topo = current_map(localizer, room_id, directory, layout=layout, spacing=spacing)
    if topo is not None:
        return topo
    topo = build_map(localizer, live, room_id, layout=layout, spacing=spacing)
    save_map(topo, directory)
    return topo


def map_dirs(path: Path) -> list[Path]:
    """``path`` itself when it holds a map, else its sub-directories that hold one.

    Raises:
        MapError: no map there.
    """
    if (path / MAP_META).is_file():
        return [path]
    found = sorted(p.parent for p in path.glob(f"*/{MAP_META}")) if path.is_dir() else []
    if not found:
        raise MapError(f"{path}: no {MAP_META} here or in its sub-directories")
    return found


def build_maps(
    localizer: AnyLocalizer,
    data: DataSource,
    rooms: list[str],
    out: Path,
    *,
    layout: int = 0,
    spacing: int = MAP_SPACING,
) -> list[Path]:
    """Build (or reuse) one map per room into ``out/<room_id>/``; their directories."""
    done = []
    with LiveRooms(data) as live:
        for room_id in rooms:
            ensure_map(localizer, live, room_id, out / room_id, layout=layout, spacing=spacing)
            done.append(out / room_id)
    return done
