"""A view's graph from its detections: threshold, slots by score, relations by the generator's
rules; the threshold chosen by F1 on val."""

from __future__ import annotations

import numpy as np
import pytest


def _view(scores, classes, boxes2d, lo, hi, lifted=None):  # noqa: ANN001, ANN202
    from seannet.detection.graphs import ViewDetections

    n = len(scores)
    return ViewDetections(
        np.asarray(boxes2d, np.float32).reshape(n, 4),
        np.asarray(classes, np.int64),
        np.asarray(scores, float),
        np.asarray(lo, float).reshape(n, 3),
        np.asarray(hi, float).reshape(n, 3),
        np.ones(n, bool) if lifted is None else np.asarray(lifted, bool),
    )


SLOT_RUNS = np.array([[0, 2], [2, 1], [3, 4]], np.int64)  # class 0: 2 slots, 1: 1, 2: 4


def test_detections_fill_a_class_run_best_first_and_drop_past_its_end() -> None:
    from seannet.detection.graphs import view_graph

    found = _view(
        [0.9, 0.8, 0.7, 0.6, 0.2],
        [1, 0, 1, 0, 0],
        [[0, 0, 10, 10]] * 5,
        [[0, 0, 0], [5, 5, 0], [9, 9, 0], [12, 12, 0], [20, 20, 0]],
        [[1, 1, 1], [6, 6, 1], [10, 10, 1], [13, 13, 1], [21, 21, 1]],
    )
    (instance, class_id, slot, box), _ = view_graph(found, 0.5, SLOT_RUNS)
    # class 1 has one slot: its second detection (0.7) is dropped; 0.2 is under the threshold
    assert class_id.tolist() == [1, 0, 0]
    assert slot.tolist() == [2, 0, 1]
    assert instance.tolist() == [1, 2, 3]
    assert box.shape == (3, 4)


def test_relations_follow_the_generator_rules_on_the_lifted_boxes() -> None:
    from seannet.detection.graphs import view_graph
    from sgdata.annotate.relations import RelationType

    # a table, a mug standing on it, a bowl far away, a cup whose depth was not seen
    found = _view(
        [0.9, 0.8, 0.7, 0.6],
        [2, 2, 2, 2],
        [[0, 0, 50, 50], [10, 10, 20, 20], [60, 60, 70, 70], [30, 30, 40, 40]],
        [[0, 0, 0], [0.4, 0.4, 0.76], [5, 5, 0], [0, 0, 0]],
        [[1, 1, 0.75], [0.5, 0.5, 0.86], [5.2, 5.2, 0.2], [0, 0, 0]],
        lifted=[True, True, True, False],
    )
    (instance, _, _, _), (src, dst, kind) = view_graph(found, 0.5, SLOT_RUNS)
    edges = {
        (int(s), int(d)): RelationType(int(k)).name for s, d, k in zip(src, dst, kind, strict=True)
    }
    assert edges[(2, 1)] == "ON"  # the mug (2nd best) on the table (best)
    assert (1, 2) not in edges
    assert edges[(1, 3)] == edges[(3, 1)] == "DISJOINT"
    assert not any(4 in pair for pair in edges)  # no depth, no relation
    assert instance.tolist() == [1, 2, 3, 4]  # ... but still an object of the graph


def test_a_box_under_a_pixel_wide_is_left_out() -> None:
    from seannet.detection.graphs import view_graph

    found = _view(
        [0.9, 0.8], [0, 0], [[5, 5, 5.5, 20], [0, 0, 10, 10]], [[0] * 3] * 2, [[1] * 3] * 2
    )
    (instance, _, _, box), _ = view_graph(found, 0.5, SLOT_RUNS)
    assert box.tolist() == [[0, 0, 10, 10]]


def test_the_threshold_is_the_best_f1_on_val() -> None:
    from seannet.detection.graphs import choose_threshold

    truth = {"a": (np.array([0, 1]), np.array([[0, 0, 10, 10], [20, 20, 30, 30]], float))}
    # right boxes scored 0.8 and 0.6, a false one 0.4 and a wrong class 0.3
    found = {
        "a": _view(
            [0.8, 0.6, 0.4, 0.3],
            [0, 1, 0, 0],
            [[0, 0, 10, 10], [20, 20, 30, 30], [50, 50, 60, 60], [20, 20, 30, 30]],
            [[0] * 3] * 4,
            [[1] * 3] * 4,
        )
    }
    threshold, curve = choose_threshold(found, truth)
    assert 0.4 < threshold <= 0.6  # both right boxes, no false one: F1 = 1
    assert curve[threshold] == 1.0
    assert curve[0.3] == pytest.approx(2 * 2 / (4 + 2))  # 4 predicted, 2 hits, 2 true
    assert curve[0.7] == pytest.approx(2 * 1 / (1 + 2))


def test_a_view_with_no_detected_graph_is_a_one_line_error() -> None:
    from seannet.detection.graphs import DetectedGraphs
    from seannet.errors import DataError

    graphs = DetectedGraphs.of({}, "ab" * 32, 0.5)
    assert graphs.active and graphs.label() == "detected-abababab-t0.5"
    with pytest.raises(DataError, match="view r/0/1/2/3: no detected graph"):
        graphs.apply("r/0/1/2/3", (), (), slot_runs=SLOT_RUNS, image_hw=(8, 8))
