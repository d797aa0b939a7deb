"""Arrow tables from generation records, and their deterministic, atomic Parquet files.

:func:`observation_table` turns a room's :class:`~sgdata.views.ViewRecord` s into rows of
``observations_schema()``; :func:`triplet_table` turns a split's
:class:`~sgdata.triplets.Triplet` s into rows of ``triplets_schema()``; :func:`write_parquet`
writes either so that identical tables give identical bytes (and so identical sha256 in the
manifest).
"""

from __future__ import annotations

import io
import zlib
from collections.abc import Collection, Sequence
from pathlib import Path
from typing import NamedTuple

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
from PIL import Image

from sgdata.annotate.records import ViewRecord
from sgdata.dataset.camera import camera_columns
from sgdata.dataset.channels import encode_depth, encode_mask
from sgdata.dataset.paths import SCENE_LAYER, obs_id
from sgdata.dataset.schema import observations_schema, triplets_schema
from sgdata.dataset.storage import file_table
from sgdata.errors import DatasetError
from sgdata.fileio import atomic_file
from sgdata.fileio import sha256_file as _sha256_file  # the bare name is the old one, below
from sgdata.world.triplets import Triplet

__all__ = [
    "IMAGE_FORMATS",
    "PNG_STRATEGY_SINCE",
    "PARQUET_OPTIONS",
    "EncodedImages",
    "ParquetInfo",
    "encode_image",
    "encode_view",
    "observation_table",
    "triplet_table",
    "write_parquet",
]

IMAGE_FORMATS = ("png", "jpeg")
# PNGs are deflated with zlib's run-length strategy since format 2.0.1: on rendered views it
# encodes 4x faster than the default strategy for 4 % more bytes (docs/benchmarks.md); the
# pixels are the same, only the bytes differ, so `sgdata migrate` re-encodes older PNGs.
PNG_STRATEGY_SINCE = "2.0.1"
DOMAIN_SYNTHETIC = "synthetic"
# Fixed writer options: the same table always gives the same bytes (for a given pyarrow).
# 256 rows per row group keeps random access to one view cheap for data loaders.
PARQUET_OPTIONS: dict[str, object] = {
    "compression": "zstd",
    "compression_level": 3,
    "row_group_size": 256,
    "use_dictionary": True,
    "write_statistics": True,
    "data_page_version": "2.0",
}


class ParquetInfo(NamedTuple):
    """What :func:`write_parquet` wrote: rows, sha256 hex digest, size in bytes."""

    rows: int
    sha256: str
    bytes: int


def encode_image(rgb: np.ndarray, image_format: str = "png", *, jpeg_quality: int = 92) -> bytes:
    """Encode an ``(H, W, 3)`` uint8 image deterministically (no metadata, fixed settings)."""
    if image_format not in IMAGE_FORMATS:
        raise DatasetError(f"image format {image_format!r}: expected one of {IMAGE_FORMATS}")
    if rgb.dtype != np.uint8 or rgb.ndim != 3 or rgb.shape[2] != 3:
        raise DatasetError(f"image of shape {rgb.shape} {rgb.dtype}: expected (H, W, 3) uint8")
    buffer = io.BytesIO()
    image = Image.fromarray(np.ascontiguousarray(rgb), mode="RGB")
    if image_format == "png":
        image.save(buffer, format="PNG", optimize=False, compress_level=6, compress_type=zlib.Z_RLE)
    else:
        # 4:2:0 subsampling and no progressive/optimize passes: fixed, widely decodable output.
        image.save(buffer, format="JPEG", quality=int(jpeg_quality), subsampling=2, optimize=False)
    return buffer.getvalue()


class EncodedImages(NamedTuple):
    """A view's image cells as stored: its encoded image, and its channels where kept."""

    image: bytes
    depth: bytes | None
    instances: bytes | None
    structure: bytes | None


def encode_view(
    rec: ViewRecord, image_format: str = "png", *, jpeg_quality: int = 92
) -> EncodedImages:
    """The image cells of one view (:func:`encode_image`, and 16-bit PNGs for its channels).

    Raises:
        DatasetError: inconsistent record columns or image shapes, an unknown image format.
    """
    _check_record(rec)
    return EncodedImages(
        image=encode_image(rec.rgb, image_format, jpeg_quality=jpeg_quality),
        depth=None if rec.depth is None else encode_depth(rec.depth),
        instances=None if rec.instances is None else encode_mask(rec.instances),
        structure=None if rec.structure is None else encode_mask(rec.structure.astype(np.uint16)),
    )


def _check_record(rec: ViewRecord) -> int:
    k = len(rec.obj_instance)
    lengths = {
        "obj_class": len(rec.obj_class),
        "obj_slot": len(rec.obj_slot),
        "obj_dynamics": len(rec.obj_dynamics),
        "obj_box2d": len(rec.obj_box2d),
        "obj_visible_pixels": len(rec.obj_visible_pixels),
        "obj_box3d_min": len(rec.obj_box3d_min),
        "obj_box3d_max": len(rec.obj_box3d_max),
        "obj_obb": len(rec.obj_obb),
        "obj_support": len(rec.obj_support),
    }
    bad = {name: n for name, n in lengths.items() if n != k}
    if bad:
        raise DatasetError(
            f"view {rec.room_id} layout {rec.layout} ({rec.grid_i}, {rec.grid_j}, {rec.heading}): "
            f"{k} objects but {bad}; every obj_* column must have one entry per object"
        )
    if not len(rec.rel_src) == len(rec.rel_dst) == len(rec.rel_type):
        raise DatasetError(f"view {rec.room_id}: rel_src, rel_dst, rel_type lengths differ")
    for name in ("rgb", "depth", "instances", "structure"):
        image = getattr(rec, name)
        if image is not None and image.shape[:2] != (rec.image_height, rec.image_width):
            raise DatasetError(
                f"view {rec.room_id}: {name} is {image.shape[:2]} but the camera says "
                f"{rec.image_height} x {rec.image_width}"
            )
    return k


def _fixed(values: np.ndarray, t: pa.DataType, width: int) -> pa.Array:
    flat = pa.array(np.asarray(values).reshape(-1, width).ravel(), type=t.value_type)
    return pa.FixedSizeListArray.from_arrays(flat, type=t)


def _concat(parts: Sequence[np.ndarray], dtype: type, shape: tuple[int, ...] = ()) -> np.ndarray:
    if not parts:
        return np.zeros((0, *shape), dtype=dtype)
    return np.concatenate([np.asarray(p, dtype=dtype).reshape(-1, *shape) for p in parts])


def _offsets(counts: Sequence[int]) -> pa.Array:
    return pa.array(np.concatenate([[0], np.cumsum(counts, dtype=np.int64)]), type=pa.int32())


def _objects_column(
    records: Sequence[ViewRecord], counts: list[int], class_ids: dict[str, int], t: pa.ListType
) -> pa.Array:
    st = t.value_type
    names = [c for r in records for c in r.obj_class]
    missing = sorted({c for c in names if c not in class_ids})
    if missing:
        raise DatasetError(f"object classes {missing} are not in class_ids (the class vocabulary)")
    support = _concat([r.obj_support for r in records], np.int64)
    children = {
        "instance": pa.array(_concat([r.obj_instance for r in records], np.int32)),
        "class_name": pa.array(names, type=pa.string()),
        "class_id": pa.array(np.fromiter((class_ids[c] for c in names), np.int16, len(names))),
        "slot": pa.array(_concat([r.obj_slot for r in records], np.int16)),
        "dynamics": pa.array([str(d) for r in records for d in r.obj_dynamics], type=pa.string()),
        "visible_pixels": pa.array(_concat([r.obj_visible_pixels for r in records], np.int32)),
        "support": pa.array(support.astype(np.int32), mask=support < 0),
    }
    for name, width in (("box2d", 4), ("box3d_min", 3), ("box3d_max", 3), ("obb", 7)):
        ft = st.field(name).type
        dtype = np.int16 if pa.types.is_int16(ft.value_type) else np.float32
        parts = [getattr(r, f"obj_{name}") for r in records]
        children[name] = _fixed(_concat(parts, dtype, (width,)), ft, width)
    fields = [st.field(i) for i in range(st.num_fields)]
    values = pa.StructArray.from_arrays([children[f.name] for f in fields], fields=fields)
    return pa.ListArray.from_arrays(_offsets(counts), values, type=t)


def _relations_column(records: Sequence[ViewRecord], t: pa.ListType) -> pa.Array:
    st = t.value_type
    fields = [st.field(i) for i in range(st.num_fields)]
    values = pa.StructArray.from_arrays(
        [
            pa.array(_concat([r.rel_src for r in records], np.int32)),
            pa.array(_concat([r.rel_dst for r in records], np.int32)),
            pa.array(_concat([r.rel_type for r in records], np.int8)),
        ],
        fields=fields,
    )
    return pa.ListArray.from_arrays(_offsets([len(r.rel_src) for r in records]), values, type=t)


def observation_table(
    records: Sequence[ViewRecord],
    *,
    room_type: str,
    split: str,
    class_ids: dict[str, int],
    scene_path: str | None = SCENE_LAYER,
    scene_paths: Sequence[str | None] | None = None,
    image_format: str = "png",
    jpeg_quality: int = 92,
    encoded: Sequence[EncodedImages] | None = None,
) -> pa.Table:
    """Rows of ``observations_schema()`` for the rendered views of one room, in record order.

    Args:
        records: the room's views (the pipeline passes them sorted by obs id).
        room_type: ``kitchen``, ``living_room``, ``bedroom`` or ``bathroom``.
        split: ``train``, ``val`` or ``test``.
        class_ids: class name -> index in the manifest's class vocabulary.
        scene_path: template of the ``scene`` column, formatted with ``room_id`` and
            ``layout`` (default ``scenes/{room_id}/layout_{layout}.usda``); ``None`` for null.
        scene_paths: the ``scene`` column given per record instead (overrides
            ``scene_path``); must have one entry per record.
        image_format: ``png`` (lossless, default) or ``jpeg``.
        jpeg_quality: JPEG quality, 1..100 (ignored for PNG).
        encoded: the records' image cells already encoded (:func:`encode_view` with the same
            format), one per record; the records' pixel arrays are then not read.

    Raises:
        DatasetError: inconsistent record columns, an unknown class or image format.
    """
    schema = observations_schema()
    counts = [_check_record(r) for r in records]
    n = len(records)
    if encoded is None:
        encoded = [encode_view(r, image_format, jpeg_quality=jpeg_quality) for r in records]
    elif len(encoded) != n:
        raise DatasetError(f"{len(encoded)} encoded views for {n} records; expected one each")
    ids = [obs_id(r.room_id, r.layout, r.grid_i, r.grid_j, r.heading) for r in records]
    cam_t = schema.field("camera").type
    camera = pa.StructArray.from_arrays(
        [
            pa.array([r.image_width for r in records], type=pa.int16()),
            pa.array([r.image_height for r in records], type=pa.int16()),
            pa.array([r.hfov_deg for r in records], type=pa.float32()),
            pa.array([r.eye_height for r in records], type=pa.float32()),
            pa.array([r.pitch_deg for r in records], type=pa.float32()),
        ],
        fields=[cam_t.field(i) for i in range(cam_t.num_fields)],
    )
    if scene_paths is not None:
        if len(scene_paths) != n:
            raise DatasetError(f"{len(scene_paths)} scene_paths for {n} records; expected one each")
        scenes = list(scene_paths)
    else:
        scenes = [
            None if scene_path is None else scene_path.format(room_id=r.room_id, layout=r.layout)
            for r in records
        ]
    columns = {
        "obs_id": pa.array(ids, type=pa.string()),
        "room_id": pa.array([r.room_id for r in records], type=pa.string()),
        "room_type": pa.array([room_type] * n, type=pa.string()),
        "layout": pa.array([r.layout for r in records], type=pa.int16()),
        "split": pa.array([split] * n, type=pa.string()),
        "domain": pa.array([DOMAIN_SYNTHETIC] * n, type=pa.string()),
        "x": pa.array([r.x for r in records], type=pa.float64()),
        "y": pa.array([r.y for r in records], type=pa.float64()),
        "theta": pa.array([r.theta for r in records], type=pa.float64()),
        "grid_i": pa.array([r.grid_i for r in records], type=pa.int16()),
        "grid_j": pa.array([r.grid_j for r in records], type=pa.int16()),
        "heading": pa.array([r.heading for r in records], type=pa.int8()),
        "camera": camera,
        "image": pa.array([e.image for e in encoded], type=pa.binary()),
        "image_format": pa.array([image_format] * n, type=pa.string()),
        "objects": _objects_column(records, counts, class_ids, schema.field("objects").type),
        "relations": _relations_column(records, schema.field("relations").type),
        "dropped_objects": pa.array([r.dropped_objects for r in records], type=pa.int16()),
        "scene": pa.array(scenes, type=pa.string()),
        "seed": pa.array([r.seed for r in records], type=pa.int64()),
        "textures": pa.array([r.textures for r in records], type=pa.bool_()),
        "light_intensity": pa.array([r.light_intensity for r in records], type=pa.float32()),
        "light_temperature": pa.array([r.light_temperature for r in records], type=pa.float32()),
        "depth": pa.array([e.depth for e in encoded], pa.binary()),
        "instances": pa.array([e.instances for e in encoded], pa.binary()),
        "structure": pa.array([e.structure for e in encoded], pa.binary()),
    }
    columns["intrinsics"], columns["camera_to_world"] = camera_columns(columns)
    return pa.Table.from_arrays([columns[f.name] for f in schema], schema=schema)


def triplet_table(triplets: Sequence[Triplet], obs_ids: Collection[str] | None = None) -> pa.Table:
    """Rows of ``triplets_schema()`` for one split; ``triplet_id`` is the row index.

    Args:
        triplets: the split's triplets, in the order they are to be stored.
        obs_ids: if given, the observation ids present in the split: every anchor, positive
            and negative must be one of them.

    Raises:
        DatasetError: triplets of several splits, or a referenced view that is not in
            ``obs_ids``.
    """
    schema = triplets_schema()
    splits = sorted({t.split for t in triplets})
    if len(splits) > 1:
        raise DatasetError(f"triplets of splits {splits} given together; write one split a table")

    def ids(role: str) -> list[str]:
        keys = ((t.room_id, getattr(t, role)) for t in triplets)
        return [obs_id(room, p.layout, p.i, p.j, p.heading) for room, p in keys]

    anchors, positives, negatives = ids("anchor"), ids("positive"), ids("negative")
    if obs_ids is not None:
        known = obs_ids if isinstance(obs_ids, set | frozenset) else set(obs_ids)
        missing = sorted({o for o in (*anchors, *positives, *negatives) if o not in known})
        if missing:
            raise DatasetError(
                f"{len(missing)} observation id(s) referenced by triplets are not in the "
                f"split's observations, e.g. {missing[:3]}; render referenced_poses() first"
            )
    off_t = schema.field("positive_offset").type
    columns = {
        "triplet_id": pa.array(np.arange(len(triplets), dtype=np.int64)),
        "split": pa.array([t.split for t in triplets], type=pa.string()),
        "room_id": pa.array([t.room_id for t in triplets], type=pa.string()),
        "tier": pa.array([t.tier for t in triplets], type=pa.int8()),
        "anchor": pa.array(anchors, type=pa.string()),
        "positive": pa.array(positives, type=pa.string()),
        "negative": pa.array(negatives, type=pa.string()),
        "positive_offset": _fixed(
            np.array([t.positive_offset for t in triplets], np.int8).reshape(-1, 3), off_t, 3
        ),
        "negative_offset": _fixed(
            np.array([t.negative_offset for t in triplets], np.int8).reshape(-1, 3), off_t, 3
        ),
    }
    return pa.Table.from_arrays([columns[f.name] for f in schema], schema=schema)


def write_parquet(table: pa.Table, path: Path) -> ParquetInfo:
    """Write ``table`` to ``path`` atomically with :data:`PARQUET_OPTIONS`.

    Image columns (bytes in memory) are stored as the Hugging Face ``Image`` struct, with the
    ``huggingface`` schema metadata (:func:`sgdata.dataset.storage.file_table`).

    The file is written to a temporary name in the same directory and renamed over ``path``
    only once complete, so a reader never sees half a file and a failure leaves none.

    Raises:
        DatasetError: the directory cannot be created or written, or the table cannot be
            stored as Parquet.
    """
    path = Path(path)
    try:
        with atomic_file(path) as tmp:
            with open(tmp, "wb") as handle:
                pq.write_table(file_table(table), handle, **PARQUET_OPTIONS)
            digest, size = _sha256_file(tmp)
    except pa.ArrowException as exc:
        raise DatasetError(f"{path}: cannot write the table as Parquet ({exc})") from None
    except OSError as exc:
        raise DatasetError(f"{path}: cannot write here ({exc.strerror or exc})") from None
    return ParquetInfo(rows=table.num_rows, sha256=digest, bytes=size)
