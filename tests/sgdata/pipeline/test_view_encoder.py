"""A room's views encoded on a background thread (sgdata.pipeline.view_encoder): the same rows
and Parquet bytes as encoding after the room, no pixels kept, and a failed encode raised."""

from __future__ import annotations

import dataclasses
import threading
from pathlib import Path

import numpy as np
import pytest

from sgdata.dataset.rows import observation_table, write_parquet
from sgdata.errors import DatasetError
from sgdata.pipeline.view_encoder import ViewEncoder, encoding_pool

from ..dataset.test_dataset_format import CLASS_IDS, H, W, room_records

ROWS = {"room_type": "kitchen", "split": "train", "class_ids": CLASS_IDS}


def records_with_channels() -> list:
    """The format test's room, half its views with depth, instance and structure masks."""
    rng = np.random.default_rng(3)
    out = []
    for k, rec in enumerate(room_records("kitchen_000")):
        if k % 2:
            rec = dataclasses.replace(
                rec,
                depth=rng.uniform(0.5, 4.0, (H, W)).astype(np.float32),
                instances=rng.integers(0, 4, (H, W)).astype(np.uint16),
                structure=rng.integers(0, 5, (H, W)).astype(np.uint8),
            )
        out.append(rec)
    return out


@pytest.mark.parametrize("image_format", ["png", "jpeg"])
def test_the_encoder_writes_the_bytes_of_encoding_after_the_room(
    tmp_path: Path, image_format: str
) -> None:
    records = records_with_channels()
    scenes = [f"scenes/{r.room_id}/layout_{r.layout}.usda" for r in records]
    with ViewEncoder(image_format, jpeg_quality=80) as encoder:
        for rec in records:
            encoder.add(rec)
        table = encoder.table(scene_paths=scenes, **ROWS)
    assert len(encoder) == len(records)
    after = observation_table(
        records, scene_paths=scenes, image_format=image_format, jpeg_quality=80, **ROWS
    )
    assert table.equals(after)
    assert table.column("depth").null_count == len(records) // 2
    one, two = tmp_path / "background.parquet", tmp_path / "after.parquet"
    assert write_parquet(table, one).sha256 == write_parquet(after, two).sha256
    # the views it keeps hold no pixels: a room's memory does not grow with its images
    assert all(r.rgb is None and r.depth is None for r in encoder._records)


def test_a_view_that_cannot_be_encoded_fails_the_table_and_stops_the_thread() -> None:
    records = room_records("kitchen_000")
    bad = dataclasses.replace(records[1], rgb=np.zeros((H, W + 1, 3), np.uint8))
    before = threading.active_count()
    with pytest.raises(DatasetError, match="rgb is"), ViewEncoder() as encoder:
        for rec in (records[0], bad, *records[2:]):
            encoder.add(rec)
        encoder.table(scene_paths=["s"] * len(records), **ROWS)
    assert threading.active_count() == before


def test_a_workers_pool_serves_room_after_room_and_outlives_a_failed_one() -> None:
    records = room_records("kitchen_000")
    scenes = ["s"] * len(records)
    pool = encoding_pool()
    try:
        with ViewEncoder(pool=pool) as encoder:
            for rec in records:
                encoder.add(rec)
            first = encoder.table(scene_paths=scenes, **ROWS)
        threads = threading.active_count()
        bad = dataclasses.replace(records[0], depth=np.zeros((H + 1, W), np.float32))
        with pytest.raises(DatasetError, match="depth is"), ViewEncoder(pool=pool) as failed:
            failed.add(bad)
            failed.table(scene_paths=["s"], **ROWS)
        with ViewEncoder(pool=pool) as again:  # the next room, on the same thread
            for rec in records:
                again.add(rec)
            assert again.table(scene_paths=scenes, **ROWS).equals(first)
        assert threading.active_count() == threads
    finally:
        pool.shutdown()
