"""The per-view channels beside the RGB: metric depth, the instance mask and the structure
mask, as 16-bit PNGs.

Both are single-channel uint16 PNGs, stored as Hugging Face ``Image`` columns like ``image``
(:mod:`sgdata.dataset.storage`), and both are optional (null when generation did not ask for
them, ``[outputs]`` in the config, and for real photos):

- ``depth``: millimetres along the camera's view axis (the z of the camera frame, not the ray
  length), 0 where nothing is drawn: NYUv2 / ScanNet's convention, 1 mm steps up to 65.5 m.
- ``instances``: 0 for background and room structure, ``k`` where the k-th entry of the row's
  ``objects`` list (1-based, the list's order) is seen. Objects not listed (fewer pixels than
  ``min_visible_pixels``, or dropped for want of a slot) leave 0.
- ``structure`` (since 2.3.0, stored with ``instances``): the part of the room seen where no
  object is, ``k + 1`` for the k-th of :data:`STRUCTURE_PARTS` (wall, floor, ceiling, door:
  the door's opening), 0 where an object is seen or nothing is drawn; drawn by the same id
  pass as the instances (:mod:`sgdata.render.structure` says how a face's part is read).

The class (semantic) mask is not stored: it is a function of the stored facts, the instance
mask, the objects' ``class_id`` and the structure mask (:func:`class_mask`), so it costs no
bytes and cannot disagree with them. Its values are the manifest class index + 1 for objects,
``n_classes + k + 1`` for the k-th structure part, 0 for nothing.

Encoding is deterministic (no metadata, fixed zlib settings as the RGB PNGs).
"""

from __future__ import annotations

import io
import zlib
from typing import Any

import numpy as np
from PIL import Image

from sgdata.dataset.schema import parse_version
from sgdata.errors import DatasetError
from sgdata.room_parts import STRUCTURE_PARTS

__all__ = [
    "CHANNELS",
    "CHANNELS_SINCE",
    "DEPTH_UNITS_PER_METRE",
    "STRUCTURE_PARTS",
    "STRUCTURE_SINCE",
    "class_mask",
    "decode_channel",
    "depth_metres",
    "encode_depth",
    "encode_mask",
    "stored_channels",
]

CHANNELS = ("depth", "instances", "structure")  # the optional observation columns, schema order
CHANNELS_SINCE = "2.1.0"  # the format version that added depth and instances
STRUCTURE_SINCE = "2.3.0"  # the format version that added structure, stored with instances
_SWITCH = {"depth": "depth", "instances": "instances", "structure": "instances"}  # [outputs]
DEPTH_UNITS_PER_METRE = 1000  # depth PNG values are millimetres
_UINT16_MAX = np.iinfo(np.uint16).max


def stored_channels(config: dict[str, Any] | None, format_version: str) -> tuple[str, ...]:
    """The channels a dataset's rows carry, from its manifest's resolved ``config`` (its
    ``[outputs]``) and ``format_version``, in schema order; none for a config without
    ``[outputs]`` (real photos, datasets older than :data:`CHANNELS_SINCE`)."""
    outputs = (config or {}).get("outputs") or {}
    since = parse_version(format_version) >= parse_version(STRUCTURE_SINCE)
    return tuple(c for c in CHANNELS if outputs.get(_SWITCH[c]) and (c != "structure" or since))


def _encode_uint16(values: np.ndarray) -> bytes:
    buffer = io.BytesIO()
    image = Image.fromarray(np.ascontiguousarray(values, dtype=np.uint16))
    image.save(buffer, format="PNG", optimize=False, compress_level=6, compress_type=zlib.Z_RLE)
    return buffer.getvalue()


def encode_depth(metres: np.ndarray) -> bytes:
    """A 16-bit PNG of ``(H, W)`` depth in metres (0: no hit), rounded to millimetres.

    Raises:
        DatasetError: not a 2-D array, a negative or non-finite value, or one beyond 65.535 m.
    """
    depth = np.asarray(metres)
    if depth.ndim != 2:
        raise DatasetError(f"depth of shape {depth.shape}: expected (H, W) metres")
    mm = np.rint(depth.astype(np.float64) * DEPTH_UNITS_PER_METRE)
    if not np.isfinite(mm).all() or mm.min(initial=0) < 0 or mm.max(initial=0) > _UINT16_MAX:
        raise DatasetError(
            f"depth within [{np.nanmin(depth)}, {np.nanmax(depth)}] m: expected finite values "
            f"in [0, {_UINT16_MAX / DEPTH_UNITS_PER_METRE}] m"
        )
    return _encode_uint16(mm.astype(np.uint16))


def encode_mask(mask: np.ndarray) -> bytes:
    """A 16-bit PNG of an ``(H, W)`` uint16 instance mask.

    Raises:
        DatasetError: not a 2-D uint16 array.
    """
    if mask.ndim != 2 or mask.dtype != np.uint16:
        raise DatasetError(f"mask of shape {mask.shape} {mask.dtype}: expected (H, W) uint16")
    return _encode_uint16(mask)


def decode_channel(data: bytes, *, where: str = "channel") -> np.ndarray:
    """The ``(H, W)`` uint16 array of a depth or mask PNG.

    Raises:
        DatasetError: the bytes are not a single-channel 16-bit PNG; ``where`` names the cell.
    """
    try:
        with Image.open(io.BytesIO(data)) as image:
            fmt, mode = image.format, image.mode
            values = np.asarray(image) if (fmt, mode) == ("PNG", "I;16") else None
    except Exception as exc:  # PIL raises many types for bad bytes
        raise DatasetError(f"{where}: not a decodable PNG ({type(exc).__name__})") from None
    if values is None:
        raise DatasetError(f"{where}: a {fmt} of mode {mode}; expected a 16-bit greyscale PNG")
    return values.astype(np.uint16, copy=False)


def depth_metres(depth: np.ndarray) -> np.ndarray:
    """Decoded depth (uint16 millimetres) as float32 metres, 0 where nothing was hit."""
    return depth.astype(np.float32) / np.float32(DEPTH_UNITS_PER_METRE)


def class_mask(
    instances: np.ndarray,
    class_ids: np.ndarray,
    structure: np.ndarray | None = None,
    *,
    n_classes: int = 0,
) -> np.ndarray:
    """The class mask of a view: ``class_id + 1`` of the object seen at each pixel
    (``class_ids`` is the row's ``objects[].class_id`` in list order); with the view's
    ``structure`` mask, ``n_classes + k + 1`` where the k-th structure part is seen
    (``n_classes``: the manifest's class count); 0 elsewhere.

    Raises:
        DatasetError: the mask names an object the list does not have, or a structure part
            beyond :data:`STRUCTURE_PARTS`.
    """
    lut = np.concatenate([[0], np.asarray(class_ids, dtype=np.int64) + 1]).astype(np.uint16)
    if int(instances.max(initial=0)) >= len(lut):
        raise DatasetError(
            f"instance mask holds {int(instances.max())} but the view lists {len(lut) - 1} objects"
        )
    classes = lut[instances]
    if structure is None:
        return classes
    if int(structure.max(initial=0)) > len(STRUCTURE_PARTS):
        raise DatasetError(
            f"structure mask holds {int(structure.max())}; expected 0 to {len(STRUCTURE_PARTS)}"
        )
    seen = (instances == 0) & (structure > 0)
    classes[seen] = n_classes + structure[seen].astype(np.uint16)
    return classes
