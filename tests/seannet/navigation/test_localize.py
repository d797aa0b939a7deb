"""Topological maps and localization: nodes, edges, shortest paths, files, matching views."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from seannet.errors import MapError, NavigationError
from seannet.navigation.localizer import load_localizer, run_epsilon
from seannet.navigation.map_localization import moved_bin, run_localize
from seannet.navigation.maps import (
    MAP_META,
    TopoMap,
    build_maps,
    check_map,
    derive_map,
    load_map,
    map_dirs,
    map_nodes,
    save_map,
    translation_edges,
)
from seannet.navigation.motion import HEADINGS, local_offset
from sgdata.dataset import Dataset
from sgdata.world.poses import pose_grid


def _fake_map(reachable: np.ndarray, spacing: int, dim: int = 8) -> TopoMap:
    """A map of a mask with random unit embeddings and no images (no renderer needed)."""
    nodes = map_nodes(reachable, spacing)
    keys = [(i, j, h) for i, j in nodes for h in range(4)]
    rng = np.random.default_rng(0)
    emb = rng.normal(size=(len(keys), dim)).astype(np.float32)
    emb /= np.linalg.norm(emb, axis=1, keepdims=True)
    meta = {
        "format": 1,
        "room_id": "r",
        "layout": 0,
        "spacing": spacing,
        "edges": [list(e) for e in translation_edges(reachable, nodes, spacing)],
        "checkpoint_sha256": "x",
        "dataset": {"name": "d"},
    }
    return TopoMap(
        meta=meta,
        i=np.array([k[0] for k in keys]),
        j=np.array([k[1] for k in keys]),
        heading=np.array([k[2] for k in keys]),
        obs_ids=[f"r/0/{i}/{j}/{h}" for i, j, h in keys],
        embeddings=emb,
        images=[b"png"] * len(keys),
    )


def test_nodes_and_edges_on_a_hand_made_mask() -> None:
    reachable = np.ones((5, 5), dtype=bool)
    reachable[1, 0] = False  # blocks the run from (0, 0) to (2, 0)
    reachable[4, 4] = False  # a node cell itself
    nodes = map_nodes(reachable, 2)
    assert nodes == [(0, 0), (0, 2), (0, 4), (2, 0), (2, 2), (2, 4), (4, 0), (4, 2)]
    edges = translation_edges(reachable, nodes, 2)
    assert (0, 0, 2, 0) not in edges and (0, 0, 0, 2) in edges
    assert (2, 4, 4, 4) not in edges and (4, 0, 4, 2) in edges
    assert len(map_nodes(reachable, 1)) == 23
    with pytest.raises(MapError, match="spacing"):
        map_nodes(reachable, 0)


def test_map_of_the_tiny_room_and_its_shortest_paths(tiny_room, tmp_path: Path) -> None:
    grid = pose_grid(tiny_room.room)
    topo = _fake_map(grid.reachable, 2)
    nodes = {(i, j) for i, j, _ in topo.sub_nodes()}
    assert nodes and all(grid.reachable[i, j] and i % 2 == 0 == j % 2 for i, j in nodes)
    g = topo.graph()
    assert g.number_of_nodes() == 4 * len(nodes)
    # directed: a turn both ways (8 per cell); a move along its heading one way only (the
    # robot has no backward move), sideways both ways: 6 per map edge
    assert g.number_of_edges() == 8 * len(nodes) + 6 * len(topo.meta["edges"])
    for a, b, kind in g.edges(data="kind"):
        if kind == "translation":
            assert local_offset(a, b[:2])[0] >= 0, (a, b)  # never backward
    i1, j1, i2, j2 = topo.meta["edges"][0]
    # an about-turn is two rotations; a move keeps the heading and costs its Manhattan length
    assert topo.shortest_path((i1, j1, 0), (i1, j1, 2)) in (
        [(i1, j1, 0), (i1, j1, 1), (i1, j1, 2)],
        [(i1, j1, 0), (i1, j1, 3), (i1, j1, 2)],
    )
    assert topo.shortest_path((i1, j1, 1), (i2, j2, 1)) == [(i1, j1, 1), (i2, j2, 1)]
    # a sub-goal behind the robot is reached by turning first
    h = next(h for h in range(HEADINGS) if local_offset((i2, j2, h), (i1, j1))[0] < 0)
    assert not g.has_edge((i2, j2, h), (i1, j1, h))
    path = topo.shortest_path((i2, j2, h), (i1, j1, h))
    # a quarter turn, a sidestep, a quarter turn back (cheaper than about-turns)
    assert [p[:2] for p in path] == [(i2, j2)] * 2 + [(i1, j1)] * 2
    assert all(g.has_edge(a, b) for a, b in zip(path, path[1:], strict=False))
    assert g.edges[(i1, j1, 1), (i2, j2, 1)]["cost"] == 2
    far = max(topo.sub_nodes(), key=lambda k: abs(k[0] - i1) + abs(k[1] - j1))
    path = topo.shortest_path((i1, j1, far[2]), far)
    for a, b in zip(path, path[1:], strict=False):
        assert g.has_edge(a, b)
    with pytest.raises(MapError, match="no sub-node"):
        topo.shortest_path((i1, j1, 0), (99, 99, 0))
    # files round trip
    save_map(topo, tmp_path / "m")
    back = load_map(tmp_path / "m")
    assert back.sub_nodes() == topo.sub_nodes() and back.obs_ids == topo.obs_ids
    np.testing.assert_array_equal(back.embeddings, topo.embeddings)
    assert back.meta == topo.meta and map_dirs(tmp_path) == [tmp_path / "m"]
    (tmp_path / "m" / MAP_META).write_text("{}")
    with pytest.raises(MapError, match="format"):
        load_map(tmp_path / "m")
    with pytest.raises(MapError, match="no map here"):
        load_map(tmp_path / "none")


def test_moved_bins_and_epsilon_files(tmp_path: Path) -> None:
    assert [moved_bin(n) for n in (0, 1, 2, 3, 5, 6, 40)] == [
        "0",
        "1-2",
        "1-2",
        "3-5",
        "3-5",
        "6+",
        "6+",
    ]
    assert run_epsilon(tmp_path) is None
    (tmp_path / "eval_test.json").write_text(json.dumps({"threshold": {"epsilon": 0.8}}))
    assert run_epsilon(tmp_path) == (0.8, "eval_test.json")
    (tmp_path / "eval_val.json").write_text(json.dumps({"threshold": {"epsilon": float("nan")}}))
    assert run_epsilon(tmp_path) == (0.8, "eval_test.json")  # NaN: not chosen, skipped


@pytest.fixture(scope="module")
def mini_maps(localizer_run: Path, mini_dataset: Path, tmp_path_factory) -> Path:
    """Maps (spacing 2, layout 0) of the mini dataset's test room, by the tiny run."""
    out = tmp_path_factory.mktemp("maps")
    localizer = load_localizer(localizer_run, mini_dataset, require_epsilon=False)
    build_maps(localizer, mini_dataset, Dataset.open(mini_dataset).rooms("test"), out)
    return out


def test_localize_returns_the_true_sub_node_for_an_unchanged_view(
    localizer_run: Path, mini_dataset: Path, mini_maps: Path, tmp_path: Path
) -> None:
    with pytest.raises(NavigationError, match="--epsilon"):
        run_localize(localizer_run, mini_maps, mini_dataset, queries=["x"], out=tmp_path)
    rows = (
        Dataset.open(mini_dataset)
        .observations("test", columns=["obs_id", "layout", "grid_i", "grid_j"])
        .to_pylist()
    )
    unchanged = [
        r["obs_id"]
        for r in rows
        if r["layout"] == 0 and r["grid_i"] % 2 == 0 and r["grid_j"] % 2 == 0
    ]
    assert unchanged, "the mini test room has no layout-0 view on the map's spacing"
    result = run_localize(
        localizer_run, mini_maps, mini_dataset, queries=unchanged[:3], epsilon=0.99, out=tmp_path
    )
    for query in result["queries"]:
        best = query["matches"][0]
        assert best["obs_id"] == query["query"]  # rendered again as the dataset stored it
        assert best["similarity"] == pytest.approx(1.0, abs=1e-4) and best["passes_epsilon"]
        assert len(query["matches"]) == 5
    assert "| rank |" in (tmp_path / "localize.md").read_text()
    split = run_localize(
        localizer_run, mini_maps, mini_dataset, split="test", epsilon=0.99, out=tmp_path
    )
    written = json.loads((tmp_path / "localize_test.json").read_text())
    assert (
        written["queries"]
        == split["queries"]
        == sum(b["queries"] for b in split["by_moved"].values())
    )
    assert set(split["by_moved"]) == {"0", "1-2", "3-5", "6+"}
    assert all(not r["query"].split("/")[1] == "0" for r in split["rows"])  # other layouts


def test_a_map_built_by_another_run_is_refused(
    localizer_run: Path, mini_dataset: Path, mini_maps: Path, tmp_path: Path
) -> None:
    (room_dir,) = map_dirs(mini_maps)
    copy = tmp_path / room_dir.name
    shutil.copytree(room_dir, copy)
    meta = json.loads((copy / MAP_META).read_text())
    meta["checkpoint_sha256"] = "0" * 64
    (copy / MAP_META).write_text(json.dumps(meta))
    localizer = load_localizer(localizer_run, mini_dataset, epsilon=0.5)
    check_map(load_map(room_dir), localizer, room_dir)
    with pytest.raises(MapError, match="checkpoint_sha256"):
        check_map(load_map(copy), localizer, copy)


def test_a_map_derived_from_the_full_map_is_the_map_built_at_its_spacing() -> None:
    reachable = np.ones((6, 7), dtype=bool)
    reachable[1, 0] = False  # cuts the run from (0, 0) to (2, 0): no edge there at spacing 2
    reachable[4, 4] = False  # a node cell of spacing 2 that is not reachable
    full = _fake_map(reachable, 1)
    full.meta["grid_shape"] = list(reachable.shape)
    derived = derive_map(full, 2)
    built = _fake_map(reachable, 2)
    assert derived.sub_nodes() == built.sub_nodes() and derived.obs_ids == built.obs_ids
    assert derived.meta["edges"] == built.meta["edges"] and derived.spacing == 2
    assert [0, 0, 2, 0] not in derived.meta["edges"] and [0, 0, 0, 2] in derived.meta["edges"]
    # each kept sub-node keeps its own row of the full map (view and embedding)
    for key in derived.sub_nodes():
        np.testing.assert_array_equal(derived.embedding(key), full.embedding(key))
    assert derived.meta["sub_nodes"] == 4 * len(map_nodes(reachable, 2))
    with pytest.raises(MapError, match="derive from a spacing-1 map"):
        derive_map(derived, 4)
