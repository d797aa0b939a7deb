"""GCN node slots (DESIGN §8): each class owns a fixed run of the M = 256 slots.

A class's run starts after the runs of the classes before it in catalog order and is as long
as its ``max_instances``. Within a view, the instances of a class fill its run in ascending
instance-id order; instances past the end of the run are dropped and counted (a warning is
logged), never an error.
"""

from __future__ import annotations

import logging
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np

from sgdata.errors import CatalogError
from sgdata.world.catalog import Catalog

__all__ = ["NUM_SLOTS", "SlotTable", "SlotAssignment"]

NUM_SLOTS = 256  # M in the paper: node slots of the GCN input

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class SlotAssignment:
    """Slot per input object (-1 where dropped) and how many were dropped."""

    slots: np.ndarray  # (n,) int64, aligned with the input order
    dropped: int


@dataclass(frozen=True)
class SlotTable:
    """Class name -> (first slot, run length), in catalog order."""

    runs: dict[str, tuple[int, int]]
    num_slots: int = NUM_SLOTS

    def __post_init__(self) -> None:
        used = sum(count for _, count in self.runs.values())
        if used > self.num_slots:
            raise CatalogError(
                f"class slot runs need {used} slots but the model has M = {self.num_slots}: "
                f"lower max_instances in the catalog"
            )

    @classmethod
    def from_catalog(cls, catalog: Catalog, *, num_slots: int = NUM_SLOTS) -> SlotTable:
        """Runs from the catalog's ``max_instances``, in catalog order.

        Raises:
            CatalogError: the runs total more than ``num_slots``.
        """
        return cls.from_counts(
            ((name, catalog[name].max_instances) for name in catalog.names()), num_slots=num_slots
        )

    @classmethod
    def from_counts(
        cls, counts: Iterable[tuple[str, int]], *, num_slots: int = NUM_SLOTS
    ) -> SlotTable:
        """Runs from (class name, max instances) pairs, in the given order."""
        runs: dict[str, tuple[int, int]] = {}
        start = 0
        for name, count in counts:
            if name in runs:
                raise CatalogError(f"class {name!r} listed twice for slot runs")
            if count < 1:
                raise CatalogError(f"class {name!r}: max_instances={count}; expected >= 1")
            runs[name] = (start, int(count))
            start += int(count)
        return cls(runs=runs, num_slots=num_slots)

    def to_dict(self) -> dict[str, list[int]]:
        """Plain dict for the manifest: class -> [start, count]."""
        return {name: [start, count] for name, (start, count) in self.runs.items()}

    def assign(self, instances: Sequence[tuple[int, str]]) -> SlotAssignment:
        """Slots for one view's objects given as (instance id, class name) pairs.

        Raises:
            CatalogError: a class has no slot run (not in the catalog).
        """
        n = len(instances)
        slots = np.full(n, -1, dtype=np.int64)
        if n == 0:
            return SlotAssignment(slots, 0)
        inst = np.fromiter((int(i) for i, _ in instances), dtype=np.int64, count=n)
        names = [c for _, c in instances]
        try:
            start = np.fromiter((self.runs[c][0] for c in names), dtype=np.int64, count=n)
            count = np.fromiter((self.runs[c][1] for c in names), dtype=np.int64, count=n)
        except KeyError as exc:
            raise CatalogError(
                f"object class {exc.args[0]!r} has no slot run: it is not in the catalog"
            ) from None
        # rank within class by instance id: sort by (class start, instance id)
        order = np.lexsort((inst, start))
        s_sorted = start[order]
        first = np.ones(n, dtype=bool)
        first[1:] = s_sorted[1:] != s_sorted[:-1]
        group_start = np.maximum.accumulate(np.where(first, np.arange(n), 0))
        rank = np.arange(n) - group_start
        keep = rank < count[order]
        slots[order[keep]] = s_sorted[keep] + rank[keep]
        dropped = int((~keep).sum())
        if dropped:
            log.warning("%d object(s) beyond their class's slot run were dropped", dropped)
        return SlotAssignment(slots, dropped)
