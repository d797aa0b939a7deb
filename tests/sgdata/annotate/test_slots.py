"""GCN node slots: runs in catalog order, deterministic fill, drops counted (DESIGN §8)."""

from __future__ import annotations

import logging

import numpy as np
import pytest

from sgdata.annotate.slots import NUM_SLOTS, SlotTable
from sgdata.errors import CatalogError


def _table() -> SlotTable:
    return SlotTable.from_counts([("Chair", 3), ("Mug", 2), ("Table", 1)])


def test_runs_follow_order() -> None:
    t = _table()
    assert t.runs == {"Chair": (0, 3), "Mug": (3, 2), "Table": (5, 1)}
    assert t.to_dict()["Mug"] == [3, 2]
    assert NUM_SLOTS == 256


def test_fill_by_instance_id_within_class() -> None:
    a = _table().assign([(40, "Mug"), (7, "Chair"), (3, "Mug"), (9, "Table"), (2, "Chair")])
    assert a.slots.tolist() == [4, 1, 3, 5, 0]
    assert a.dropped == 0


def test_overflow_is_dropped_and_counted(caplog: pytest.LogCaptureFixture) -> None:
    with caplog.at_level(logging.WARNING, logger="sgdata.annotate.slots"):
        a = _table().assign([(i, "Table") for i in (5, 1, 3)] + [(8, "Mug")])
    assert a.slots.tolist() == [-1, 5, -1, 3]
    assert a.dropped == 2
    assert "dropped" in caplog.text


def test_unknown_class_and_too_many_slots() -> None:
    with pytest.raises(CatalogError, match="Sofa"):
        _table().assign([(1, "Sofa")])
    with pytest.raises(CatalogError, match="256"):
        SlotTable.from_counts([("A", 200), ("B", 57)])
    assert len(_table().assign([]).slots) == 0


def test_from_catalog_uses_max_instances() -> None:
    from types import SimpleNamespace

    specs = {"Chair": SimpleNamespace(max_instances=4), "Mug": SimpleNamespace(max_instances=6)}
    fake = type(
        "Cat", (), {"names": lambda self: list(specs), "__getitem__": lambda self, k: specs[k]}
    )()
    t = SlotTable.from_catalog(fake)  # type: ignore[arg-type]
    assert t.runs == {"Chair": (0, 4), "Mug": (4, 6)}


def test_matches_plain_reference() -> None:
    rng = np.random.default_rng(3)
    t = SlotTable.from_counts([("A", 2), ("B", 3), ("C", 1)])
    for _ in range(50):
        n = int(rng.integers(0, 12))
        inst = rng.choice(100, n, replace=False).tolist()
        cls = rng.choice(["A", "B", "C"], n).tolist()
        got = t.assign(list(zip(inst, cls, strict=True))).slots.tolist()
        want = [-1] * n
        for name, (start, count) in t.runs.items():
            members = sorted(
                (i, k) for k, (i, c) in enumerate(zip(inst, cls, strict=True)) if c == name
            )
            for rank, (_, k) in enumerate(members[:count]):
                want[k] = start + rank
        assert got == want
