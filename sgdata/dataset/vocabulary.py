"""The class vocabulary of a dataset: class ids and GCN slot runs, from the catalog (one source)."""

from __future__ import annotations

from sgdata.annotate.slots import SlotTable
from sgdata.dataset import ClassEntry, classes_from_slots
from sgdata.world.catalog import Catalog, load_catalog

__all__ = ["class_vocabulary"]


def class_vocabulary(catalog: Catalog | None = None) -> tuple[SlotTable, tuple[ClassEntry, ...]]:
    """The slot table and the manifest's class entries (``id`` is what rows store)."""
    catalog = catalog or load_catalog()
    slots = SlotTable.from_catalog(catalog)
    dynamics = {name: catalog[name].dynamics.value for name in catalog.names()}
    return slots, classes_from_slots(slots.runs, dynamics)
