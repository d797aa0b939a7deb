"""``sgdata validate``: check a dataset on disk against its format and collect every problem.

One entry point, :func:`validate_dataset`, runs the check families in order (see
docs/validate.md): manifest, files, metadata (card and Croissant), tables,
rows/objects/relations, relation recompute, triplets, images, channels (depth and masks),
scenes, with ``sources`` the user room files, and with ``against`` a reference dataset
(:mod:`sgdata.dataset.diff`). Nothing stops at the first failure: the report lists every
:class:`Problem` with its file, row and field.
"""

from __future__ import annotations

import time
from pathlib import Path

from sgdata.dataset.schema import FORMAT_VERSION, parse_version
from sgdata.validate.appearance_checks import check_appearance
from sgdata.validate.channel_checks import CHANNEL_CHECKS, check_channels
from sgdata.validate.composition_checks import (
    check_counts,
    check_rooms_across_splits,
    check_triplets,
)
from sgdata.validate.image_checks import check_images
from sgdata.validate.logic_checks import check_objects, check_relations, check_rows
from sgdata.validate.manifest_checks import (
    check_files,
    check_manifest,
    check_splits,
    read_raw_manifest,
)
from sgdata.validate.metadata_checks import check_metadata
from sgdata.validate.problems import Collector, Problem, ValidationReport
from sgdata.validate.reference_checks import check_against
from sgdata.validate.relation_checks import check_recompute
from sgdata.validate.scene_checks import check_scenes
from sgdata.validate.source_checks import CHECK as SOURCES_CHECK
from sgdata.validate.source_checks import catalog_asset_files, check_sources, user_room_files
from sgdata.validate.table_checks import check_ids, compare_schema, load_split

__all__ = ["Problem", "ValidationReport", "compare_schema", "validate_dataset"]


def validate_dataset(
    root: str | Path,
    *,
    quick: bool = False,
    usd: bool = False,
    sources: Path | None = None,
    against: Path | None = None,
) -> ValidationReport:
    """Check the dataset at ``root``; every failure becomes a :class:`Problem`.

    Args:
        root: the dataset directory (holding ``dataset.json``).
        quick: skip decoding the images (the slowest check).
        usd: also run USD's validators on every referenced scene layer.
        sources: the folder of the config that generated the dataset: its ``[rooms] files``
            and the files of its ``[catalog]`` (catalogs, meshes, textures) must still have the
            sha256 the manifest records.
        against: a reference dataset: differences beyond :class:`~sgdata.dataset.diff.Tolerance`
            fail the ``against.reference`` check; those within it are the report's ``notes``.

    Returns:
        the report; ``report.ok`` is True only when no check failed.

    Raises:
        DatasetError: ``root`` is not a directory or has no ``dataset.json`` (not a dataset).
    """
    start = time.perf_counter()
    root = Path(root)
    out = Collector()
    raw = read_raw_manifest(root, out)
    if raw is not None and check_manifest(raw, out):
        _check_contents(root, raw, out, quick=quick, usd=usd)
        if sources is not None:
            check_sources(raw, Path(sources), out)
        elif user_room_files(raw) or catalog_asset_files(raw):
            out.skipped.append(SOURCES_CHECK)
        if against is not None:
            check_against(root, Path(against), out)
    if quick:
        out.skipped.append("images.decode")
        out.skipped.append("images.size")
        out.skipped.extend(CHANNEL_CHECKS)
    if not usd:
        out.skipped.append("scenes.usd")
    return ValidationReport(
        root=str(root),
        problems=out.problems,
        checked=dict(out.checked),
        skipped=out.skipped,
        elapsed=time.perf_counter() - start,
        notes=out.notes,
    )


def _check_contents(root: Path, raw: dict, out: Collector, *, quick: bool, usd: bool) -> None:
    check_splits(raw, out)
    check_files(root, raw, out)
    check_metadata(root, raw, out)
    newer = parse_version(raw["format_version"])[:2] > parse_version(FORMAT_VERSION)[:2]
    splits = []
    for split in raw["splits"]:
        tables = load_split(root, raw, split, out, extra_ok=newer)
        splits.append(tables)
        check_ids(tables, out)
        check_rows(tables, raw, out)
        check_appearance(tables, raw, out)
        objects = check_objects(tables, raw, out)
        if objects is not None:
            relations = check_relations(tables, raw, objects, out)
            check_recompute(tables, raw, objects, relations, out)
        check_triplets(tables, raw, out)
        if not quick:
            check_images(root, tables.files, out)
            check_channels(root, raw, tables.files, out)
    check_rooms_across_splits(splits, out)
    check_counts(splits, raw, out)
    check_scenes(root, splits, out, usd=usd)
