"""``seannet localize``: match views against topological maps, and retrieval metrics.

Two modes:

- **queries**: observation ids of a dataset (rendered views or real labeled photos) are
  embedded and matched against the map of their room (every map when none is of their room);
  the best sub-nodes come back with their similarity S and whether S > epsilon.
- **split**: every view of a split taken in a layout other than its map's, at a pose that is
  a sub-node of the map, is a query whose true sub-node is known: recall@1 and recall@5 of
  it, overall and by the number of moved objects in view (0, 1-2, 3-5, 6+). An object is
  moved when its 3D box differs between the query's layout and the map's
  (:func:`seannet.data.moved.moved_instances`).

S is the localizer's own similarity: cosine for a run, whatever the method's ``similarity``
computes (its boxes included) for a method.
"""

from __future__ import annotations

import json
from collections import defaultdict
from pathlib import Path
from typing import Any

import numpy as np

from seannet.data.datasets import ObservationDataset, dataset_identity, open_dataset
from seannet.data.live_views import layout_boxes
from seannet.data.moved import BIN_NAMES, moved_bin, moved_instances
from seannet.data.opening import DataSource
from seannet.errors import DataError, MapError
from seannet.evaluation.retrieval import recall_at_k
from seannet.markdown import table
from seannet.navigation.localizer import AnyLocalizer, open_localizer
from seannet.navigation.maps import TopoMap, check_map, load_map, map_dirs
from seannet.training.runs import MODEL_KEYS
from sgdata.dataset.paths import MANIFEST
from sgdata.fileio import atomic_write_text

__all__ = ["match", "localize_queries", "retrieval", "run_localize"]

TOP = 5


def match(
    topo: TopoMap, vector: np.ndarray, top: int = TOP, localizer: AnyLocalizer | None = None
) -> list[tuple[int, float]]:
    """The ``top`` rows of ``topo`` most similar to ``vector`` by ``localizer``'s similarity
    (None: cosine of unit vectors): (row, S), best first."""
    sims = topo.embeddings @ vector if localizer is None else _sims(localizer, topo, vector)
    order = np.argsort(-sims, kind="stable")[:top]
    return [(int(k), float(sims[k])) for k in order]


def _sims(localizer: AnyLocalizer, topo: TopoMap, vector: np.ndarray) -> np.ndarray:
    """(N,) similarity of ``vector`` to every row of ``topo`` by the localizer's measure."""
    return np.asarray(localizer.similarities(vector, topo.embeddings), dtype=np.float64)


def _open_maps(localizer: AnyLocalizer, paths: list[Path]) -> list[TopoMap]:
    maps = []
    for path in paths:
        topo = load_map(path)
        check_map(topo, localizer, path)
        maps.append(topo)
    return maps


def _find_views(data: DataSource, obs_ids: list[str], localizer: AnyLocalizer) -> dict[str, Any]:
    """obs id -> ObservationItem, searching every split of ``data``.

    Raises:
        DataError: an id is in no split.
    """
    ds = open_dataset(data)
    found: dict[str, Any] = {}
    for split in ds.splits:
        views = ObservationDataset(ds, split, transform=localizer.transform)
        index = {o: k for k, o in enumerate(views.obs_ids)}
        for o in obs_ids:
            if o in index and o not in found:
                found[o] = views[index[o]]
    missing = [o for o in obs_ids if o not in found]
    if missing:
        raise DataError(f"{ds.root}: observation {missing[0]!r} is in none of its splits")
    return found


def _check_query_data(localizer: AnyLocalizer, data: DataSource) -> None:
    """A query dataset must share the run's vocabulary (a photo dataset is another dataset)."""
    ds = open_dataset(data)
    current = dataset_identity(ds)
    for key in MODEL_KEYS:
        if current.get(key) != localizer.identity.get(key):
            raise DataError(
                f"{ds.root}/dataset.json: {key} differs from the dataset {localizer.source} was "
                f"trained on; queries need the same class vocabulary"
            )


def localize_queries(
    localizer: AnyLocalizer,
    maps: list[TopoMap],
    data: DataSource,
    queries: list[str],
    *,
    top: int = TOP,
) -> list[dict[str, Any]]:
    """The best ``top`` sub-nodes for each query (see the module doc)."""
    ds = open_dataset(data)
    _check_query_data(localizer, ds)
    items = _find_views(ds, queries, localizer)
    vectors = localizer.embed([items[q].view for q in queries])
    out = []
    for q, vector in zip(queries, vectors, strict=True):
        own = [m for m in maps if m.room_id == items[q].room_id] or maps
        scored = [(m, k, s) for m in own for k, s in match(m, vector, top, localizer)]
        scored.sort(key=lambda t: -t[2])
        out.append(
            {
                "query": q,
                "room_id": items[q].room_id,
                "matches": [
                    {
                        "room_id": m.room_id,
                        "sub_node": list(m.sub_nodes()[k]),
                        "obs_id": m.obs_ids[k],
                        "similarity": round(s, 6),
                        "passes_epsilon": bool(s > localizer.epsilon),
                    }
                    for m, k, s in scored[:top]
                ],
            }
        )
    return out


def retrieval(
    localizer: AnyLocalizer, maps: list[TopoMap], data: DataSource, split: str
) -> dict[str, Any]:
    """Recall@1 / @5 of the true sub-node for the split's views in other layouts.

    Raises:
        MapError: no map is of a room of ``split``.
    """
    ds = open_dataset(data)
    views = ObservationDataset(ds, split, transform=localizer.transform)
    position = {o: k for k, o in enumerate(views.obs_ids)}
    columns = ["obs_id", "room_id", "layout", "grid_i", "grid_j", "heading", "objects"]
    meta = ds.observations(split, columns=columns).to_pylist()
    rooms = {m.room_id: m for m in maps}
    if not rooms.keys() & {r["room_id"] for r in meta}:
        raise MapError(f"no map is of a room of split {split!r}; build them with `seannet map`")
    picked: dict[str, list[dict[str, Any]]] = defaultdict(list)
    for row in meta:
        topo = rooms.get(row["room_id"])
        if topo is None or row["layout"] == topo.layout or row["grid_i"] is None:
            continue
        try:
            topo.index((row["grid_i"], row["grid_j"], row["heading"]))
        except MapError:
            continue  # not a sub-node (off the map's spacing, or blocked in the map's layout)
        picked[row["room_id"]].append(row)
    rows = []
    for room_id, queries in picked.items():
        topo = rooms[room_id]
        boxes = {topo.layout: layout_boxes(ds.root, room_id, topo.layout)}
        vectors = localizer.embed([views[position[q["obs_id"]]].view for q in queries])
        for q, vector in zip(queries, vectors, strict=True):
            if q["layout"] not in boxes:
                boxes[q["layout"]] = layout_boxes(ds.root, room_id, q["layout"])
            moved = moved_instances(boxes[topo.layout], boxes[q["layout"]])
            true_row = topo.index((q["grid_i"], q["grid_j"], q["heading"]))
            sims = _sims(localizer, topo, vector)
            recall = recall_at_k(sims[None], np.array([true_row]), (1, 5))
            rows.append(
                {
                    "query": q["obs_id"],
                    "moved_in_view": len(moved & {o["instance"] for o in q["objects"]}),
                    "rank1": bool(recall[1]),
                    "rank5": bool(recall[5]),
                    "true_similarity": float(sims[true_row]),
                }
            )
    return _summarise(rows, localizer.epsilon, split)


def _summarise(rows: list[dict[str, Any]], epsilon: float, split: str) -> dict[str, Any]:
    def block(part: list[dict[str, Any]]) -> dict[str, Any]:
        n = len(part)
        return {
            "queries": n,
            "recall@1": sum(r["rank1"] for r in part) / n if n else None,
            "recall@5": sum(r["rank5"] for r in part) / n if n else None,
            "true_passes_epsilon": sum(r["true_similarity"] > epsilon for r in part) / n
            if n
            else None,
        }

    by_bin = {b: block([r for r in rows if moved_bin(r["moved_in_view"]) == b]) for b in BIN_NAMES}
    return {"split": split, "epsilon": epsilon, **block(rows), "by_moved": by_bin, "rows": rows}


def run_localize(
    run: Path | str,
    map_path: Path,
    data: DataSource,
    *,
    queries: list[str] | None = None,
    split: str | None = None,
    epsilon: float | None = None,
    out: Path | None = None,
    top: int = TOP,
) -> dict[str, Any]:
    """``seannet localize``: queries mode (``queries``) or split mode (``split``).

    Writes ``localize.json`` / ``.md`` (queries) or ``localize_<split>.json`` / ``.md`` into
    ``out`` (default: the run or method directory). ``run`` names the localizer
    (:func:`~seannet.navigation.localizer.open_localizer`: a run directory, a method directory
    such as a benchmark card's, or a method's name).

    Raises:
        MapError: no map, or a map another run, method or dataset built.
        NavigationError, MethodError: no epsilon.
        DataError: an unknown query id, or a query dataset with another vocabulary.
    """
    if (queries is None) == (split is None):
        raise DataError("localize: give query ids or --split, not both and not neither")
    if out is None and not Path(run).is_dir():
        raise DataError(f"localize: {run} is a method's name, not a directory: pass --out")
    paths = map_dirs(map_path)
    first = load_map(paths[0])
    source = Path(str(first.meta.get("data", "")))
    if not (source / MANIFEST).is_file():
        raise MapError(f"{paths[0]}/map.json: data {str(source)!r} is not a dataset any more")
    ds = open_dataset(data)
    # the map's dataset is most often the queries' own: one opening serves both
    same = source.resolve() == ds.root.resolve()
    localizer = open_localizer(run, ds if same else source, epsilon=epsilon)
    maps = _open_maps(localizer, paths)
    head = {
        "run": str(run),
        "model": localizer.name,
        "epsilon": localizer.epsilon,
        "epsilon_source": localizer.epsilon_source,
        "maps": [str(p) for p in paths],
    }
    if queries is not None:
        result = {**head, "queries": localize_queries(localizer, maps, ds, queries, top=top)}
        name, text = "localize", _queries_markdown(result)
    else:
        assert split is not None
        result = {**head, **retrieval(localizer, maps, ds, split)}
        name, text = f"localize_{split}", _retrieval_markdown(result)
    out = out or Path(run)
    atomic_write_text(out / f"{name}.json", json.dumps(result, indent=2))
    atomic_write_text(out / f"{name}.md", text)
    result["written"] = str(out / f"{name}.md")
    return result


def _queries_markdown(result: dict[str, Any]) -> str:
    lines = [
        f"# {result['model']} localization (epsilon {result['epsilon']:.3f}, "
        f"{result['epsilon_source']})",
        "",
    ]
    matches = [
        (
            q["query"],
            rank,
            m["room_id"],
            tuple(m["sub_node"]),
            f"{m['similarity']:.4f}",
            "yes" if m["passes_epsilon"] else "no",
        )
        for q in result["queries"]
        for rank, m in enumerate(q["matches"], 1)
    ]
    header = ("query", "rank", "room", "sub-node (i, j, h)", "S", "S > epsilon")
    lines += table(header, matches)
    return "\n".join(lines) + "\n"


def _pct(value: float | None) -> str:
    return "-" if value is None else f"{100 * value:.1f} %"


def _retrieval_markdown(result: dict[str, Any]) -> str:
    lines = [
        f"# {result['model']} retrieval on {result['split']} (other layouts than the map's)",
        "",
        f"epsilon {result['epsilon']:.3f} ({result['epsilon_source']})",
        "",
    ]
    bins = [("all", result), *result["by_moved"].items()]
    rows = [
        (b, r["queries"], _pct(r["recall@1"]), _pct(r["recall@5"]), _pct(r["true_passes_epsilon"]))
        for b, r in bins
    ]
    header = ("moved objects in view", "queries", "recall@1", "recall@5", "S(true) > epsilon")
    lines += table(header, rows)
    return "\n".join(lines) + "\n"
