"""Localization metrics on hand-made similarities and boxes."""

from __future__ import annotations

import numpy as np
import pytest

from seannet.evaluation.retrieval import accuracy_by_moved, map_recall, recall_at_k, separation


def test_recall_at_k_on_a_hand_made_matrix() -> None:
    sim = np.array(
        [
            [0.9, 0.1, 0.2, 0.0],  # truth 0 ranks first
            [0.5, 0.4, 0.8, 0.3],  # truth 1 ranks third
            [0.1, 0.2, 0.3, 0.7],  # truth 2 ranks second
            [0.6, 0.6, 0.1, 0.2],  # truth 0 tied with column 1: counts against it (second)
        ]
    )
    truth = np.array([0, 1, 2, 0])
    assert recall_at_k(sim, truth, ks=(1, 2, 3)) == {1: 0.25, 2: 0.75, 3: 1.0}
    assert np.isnan(recall_at_k(np.zeros((0, 3)), np.zeros(0), ks=(1,))[1])


class _E:
    """A minimal embeddings record: two rooms, map layout 0, queries in layout 1."""

    def __init__(self) -> None:
        rng = np.random.default_rng(0)
        poses = [(i, j, h) for i in range(2) for j in range(2) for h in (0, 1)]
        base = rng.normal(size=(len(poses), 8))
        rows, vecs = [], []
        for room in ("a", "b"):
            for layout in (0, 1):
                for n, pose in enumerate(poses):
                    noise = 0.05 * rng.normal(size=8) if layout else 0
                    rows.append((room, layout, *pose))
                    vecs.append(base[n] + noise + (3.0 if room == "b" else 0.0))
        v = np.array(vecs)
        self.vectors = v / np.linalg.norm(v, axis=1, keepdims=True)
        self.room = np.array([r[0] for r in rows])
        self.layout = np.array([r[1] for r in rows])
        self.grid_i = np.array([r[2] for r in rows])
        self.grid_j = np.array([r[3] for r in rows])
        self.heading = np.array([r[4] for r in rows])


def test_map_recall_finds_the_same_pose_across_layouts() -> None:
    result = map_recall(_E(), ks=(1, 5))
    assert result["queries"] == 16 and result["rooms"] == 2
    assert result["recall"] == {1: 1.0, 5: 1.0}
    assert result["map_views_per_room"] == {"a": 8, "b": 8}


def test_accuracy_by_moved_bins_and_separation() -> None:
    correct = np.array([1, 1, 0, 1, 0, 0], dtype=bool)
    moved = np.array([0, 0, 1, 2, 4, 9])
    bins = accuracy_by_moved(correct, moved)
    assert bins["0"] == {"triplets": 2, "accuracy": 1.0}
    assert bins["1-2"] == {"triplets": 2, "accuracy": 0.5}
    assert bins["3-5"]["triplets"] == 1 and bins["6+"]["accuracy"] == 0.0
    sep = separation(np.array([0.9, 0.95, 1.0]), np.array([0.7, 0.75, 0.8]))
    assert sep["d_prime"] == pytest.approx(0.2 / np.sqrt(np.var([0.9, 0.95, 1.0])))
