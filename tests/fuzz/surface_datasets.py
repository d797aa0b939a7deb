"""Surface: datasets on disk, randomly corrupted (manifest fields, Parquet bytes and columns,
encoded images and channels: depth, instance and structure masks), read by ``Dataset.open``
and checked by ``validate``.

Reading may refuse (a :class:`~sgdata.errors.DatasetError`); ``validate`` must report problems
rather than raise; and neither may write anything into the dataset.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import shutil
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pyarrow as pa
import pyarrow.parquet as pq
from hypothesis import strategies as st

from sgdata.dataset.channels import CHANNELS
from sgdata.dataset.reader import Dataset, decode_image
from sgdata.validate import validate_dataset

from ..conftest import CHANNELS_TOML
from .harness import Surface
from .mutations import json_values

MANIFEST = "dataset.json"

# (what, which file or row, which edit, where, a value): drawn blind, resolved on the copy
corruptions = st.lists(
    st.tuples(
        st.sampled_from(["manifest", "bytes", "image", "column"]),
        st.integers(0, 10_000),
        st.sampled_from(
            ["truncate", "flip", "empty", "remove", "retype", "null", "drop", "duplicate"]
        ),
        st.integers(0, 1 << 30),
        json_values,
    ),
    min_size=1,
    max_size=2,
)


def generate_with_cli(root: Path, config_text: str) -> Path:
    """``sgdata generate`` of a config given as text, into ``root/data``: its root."""
    config = root / "config.toml"
    config.parent.mkdir(parents=True, exist_ok=True)
    config.write_text(config_text)
    sgdata = str(Path(sys.executable).parent / "sgdata")
    subprocess.run(
        [sgdata, "generate", str(config), str(root / "data")], check=True, capture_output=True
    )
    return root / "data"


@contextlib.contextmanager
def channels_dataset(root: Path) -> Iterator[Path]:
    """The tests' mini dataset (three bathrooms) with its channels (depth, instance and
    structure masks), generated once for a campaign by the CLI."""
    yield generate_with_cli(root, CHANNELS_TOML)


def _digest(root: Path) -> dict[str, str]:
    return {
        str(p.relative_to(root)): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(root.rglob("*"))
        if p.is_file()
    }


def _corrupt_manifest(path: Path, k: int, edit: str, value: Any) -> None:
    doc = json.loads(path.read_text())
    keys = sorted(doc)
    key = keys[k % len(keys)]
    if edit == "remove":
        del doc[key]
    elif edit in ("retype", "null"):
        doc[key] = None if edit == "null" else value
    else:  # one level down: a field of the entry
        inner = doc[key]
        if isinstance(inner, dict) and inner:
            sub = sorted(inner)[k % len(inner)]
            inner[sub] = value
        elif isinstance(inner, list) and inner:
            inner[k % len(inner)] = value
        else:
            doc[key] = value
    path.write_text(json.dumps(doc))


def _corrupt_bytes(path: Path, at: int, edit: str) -> None:
    data = path.read_bytes()
    at = at % max(len(data), 1)
    if edit == "truncate":
        data = data[:at]
    elif edit == "empty":
        data = b""
    elif edit == "remove":
        path.unlink()
        return
    else:
        data = data[:at] + bytes([data[at] ^ 0xFF]) + data[at + 1 :] if data else data
    path.write_bytes(data)


def _corrupt_table(path: Path, k: int, edit: str, at: int) -> None:
    table = pq.read_table(path)
    name = table.column_names[k % table.num_columns]
    column = table.column(name)
    if edit == "drop":
        table = table.drop_columns([name])
    elif edit == "null":
        table = table.set_column(
            table.schema.get_field_index(name), name, pa.nulls(len(table), column.type)
        )
    elif edit == "duplicate":
        table = pa.concat_tables([table, table.slice(at % max(len(table), 1), 1)])
    else:  # another type: the values as text
        texts = pa.array([str(v) for v in column.to_pylist()])
        table = table.set_column(table.schema.get_field_index(name), name, texts)
    pq.write_table(table, path)


def _corrupt_image(path: Path, row: int, edit: str, at: int) -> None:
    """Damage one encoded cell of an image column: the RGB or a channel, drawn by ``row``."""
    table = pq.read_table(path)
    names = [n for n in ("image", *CHANNELS) if n in table.column_names]
    if not names or not len(table):
        return
    name = names[row % len(names)]
    images = table.column(name).to_pylist()
    k = row % len(images)
    stored = images[k]  # format 2: the Hugging Face Image struct; 1.x: the bytes
    if stored is None:  # a channel this row does not store
        return
    data = (stored.get("bytes") if isinstance(stored, dict) else stored) or b""
    at = at % max(len(data), 1)
    data = {"truncate": data[:at], "empty": b""}.get(
        edit, data[:at] + b"\x00garbage" + data[at + 8 :]
    )
    images[k] = {"bytes": data, "path": None} if isinstance(stored, dict) else data
    index = table.schema.get_field_index(name)
    table = table.set_column(index, name, pa.array(images, table.schema.field(name).type))
    pq.write_table(table, path)


def feed(example: list, work: Path, dataset: Path) -> None:
    root = work / "data"
    shutil.copytree(dataset, root)
    parquets = sorted(root.rglob("*.parquet"))
    files = sorted(p for p in root.rglob("*") if p.is_file())
    for what, k, edit, at, value in example:
        if what == "manifest" and (root / MANIFEST).is_file():
            with contextlib.suppress(ValueError):  # an earlier edit left it unreadable
                _corrupt_manifest(root / MANIFEST, k, edit, value)
        elif what == "bytes":
            path = files[k % len(files)]
            if path.exists():
                _corrupt_bytes(path, at, edit)
        elif what == "column" and parquets[k % len(parquets)].exists():
            with contextlib.suppress(pa.ArrowException):  # an earlier edit left it unreadable
                _corrupt_table(parquets[k % len(parquets)], k, edit, at)
        elif what == "image" and parquets[k % len(parquets)].exists():
            with contextlib.suppress(pa.ArrowException):
                _corrupt_image(parquets[k % len(parquets)], k, edit, at)
    before = _digest(root)
    try:
        opened = Dataset.open(root)
        for split in opened.splits:
            table = opened.observations(split, columns=["image"])
            for data in table.column("image").to_pylist()[:2]:
                decode_image(data)
            opened.triplets(split)
    finally:
        report = validate_dataset(root)  # refusing to open is fine: validate must still report
        assert report is not None
        assert _digest(root) == before, "validate or Dataset.open wrote into the dataset"


SURFACE = Surface(
    name="datasets (Dataset.open, validate)",
    inputs=corruptions,
    feed=feed,
    session=channels_dataset,
)
