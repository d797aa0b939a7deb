"""The dataset card ``README.md``: YAML front matter that Hugging Face ``datasets`` loads from,
then what the data is, its counts and how to load and cite it.

The front matter is a pure function of the manifest (:func:`card_metadata`, written by
:func:`front_matter`), so ``sgdata validate`` checks it by writing it again; the body adds
histograms read from the observation tables. Both are deterministic: the same dataset gives
the same bytes.
"""

from __future__ import annotations

import json
import re
from collections import Counter
from pathlib import Path, PurePosixPath
from typing import TYPE_CHECKING, Any

import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.parquet as pq

from sgdata import markdown
from sgdata.dataset.paths import CARD, MANIFEST, OBSERVATIONS, TRIPLETS
from sgdata.dataset.schema import observations_schema, primitive_name, triplets_schema
from sgdata.dataset.storage import is_image_field
from sgdata.errors import DatasetError
from sgdata.fileio import atomic_write_text

if TYPE_CHECKING:
    from sgdata.dataset.manifest import Manifest

__all__ = [
    "DATA_LICENSE",
    "card_metadata",
    "card_text",
    "front_matter",
    "hf_features",
    "read_front_matter",
    "write_card",
]

# The licence the card and croissant.json declare: the scenes are procedural and the catalog
# is the project's own, so generated data carries the usual open-data licence. Every dataset
# declares it, photos from `label --export` too (validate checks the card against the
# manifest, so a per-dataset licence needs a manifest key first).
DATA_LICENSE = "cc-by-4.0"
DATA_LICENSE_URL = "https://creativecommons.org/licenses/by/4.0/"
PAPER_URL = "https://arxiv.org/abs/2110.02276"
TASKS = ("image-feature-extraction", "object-detection")
TAGS = ("scene-graph", "indoor", "localization", "synthetic", "sgdata", "croissant")
# The Hugging Face Hub's size_categories tags, by number of views.
_SIZES = (
    (1_000, "n<1K"),
    (10_000, "1K<n<10K"),
    (100_000, "10K<n<100K"),
    (1_000_000, "100K<n<1M"),
    (10_000_000, "1M<n<10M"),
    (100_000_000, "10M<n<100M"),
)
_PLAIN_KEY = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
_FENCE = "---"


# --------------------------------------------------------------------------- features


def _feature_type(t: pa.DataType, field: pa.Field, labels: dict[str, list[str]]) -> dict:
    """The YAML feature entry (without ``name``) of one Arrow type, as ``datasets`` writes it."""
    if field.name in labels and pa.types.is_integer(t):
        names = {str(k): name for k, name in enumerate(labels[field.name])}
        return {"dtype": {"class_label": {"names": names}}}
    if is_image_field(field):
        return {"dtype": "image"}
    if pa.types.is_struct(t):
        return {"struct": [_feature(t.field(i), {}) for i in range(t.num_fields)]}
    if pa.types.is_list(t) or pa.types.is_fixed_size_list(t):
        inner = t.value_type
        if pa.types.is_struct(inner):
            entry: dict[str, Any] = {
                "list": [_feature(inner.field(i), labels) for i in range(inner.num_fields)]
            }
        else:
            entry = {"list": primitive_name(inner)}
        if pa.types.is_fixed_size_list(t):
            entry["length"] = t.list_size
        return entry
    return {"dtype": primitive_name(t)}


def _feature(field: pa.Field, labels: dict[str, list[str]]) -> dict:
    return {"name": field.name, **_feature_type(field.type, field, labels)}


def hf_features(schema: pa.Schema, labels: dict[str, dict[str, list[str]]]) -> list[dict]:
    """``schema`` as the ``features`` list of a card's ``dataset_info``.

    Args:
        labels: column -> {nested field -> class names}: those integer fields become
            ``ClassLabel`` (``objects.class_id`` names the class vocabulary).
    """
    return [_feature(f, labels.get(f.name, {})) for f in schema]


# --------------------------------------------------------------------------- front matter


def _folder(template: str, split: str) -> str:
    """The folder (with its trailing ``/``) of a split's files under ``template``."""
    return str(PurePosixPath(template.format(split=split)).parent) + "/"


def _split_bytes(manifest: Manifest, prefix: str) -> int:
    return sum(f.bytes for f in manifest.files if f.path.startswith(prefix))


def card_metadata(manifest: Manifest) -> dict[str, Any]:
    """The card's YAML front matter: licence, tasks, configs with their splits' files, and per
    config the features and split sizes (what ``load_dataset(ROOT, config)`` reads)."""
    listed = {f.path for f in manifest.files}
    obs_splits = list(manifest.splits)
    tri_splits = [s for s in obs_splits if TRIPLETS.format(split=s) in listed]
    obs_glob = OBSERVATIONS.replace("{room_id}", "*")
    labels = {
        "objects": {"class_id": [c.name for c in manifest.classes]},
        "relations": {"type": list(manifest.relation_types)},
    }
    total = sum(manifest.counts.observations.values())
    size = next((label for bound, label in _SIZES if total < bound), "100M<n<1B")
    return {
        "license": DATA_LICENSE,
        "pretty_name": manifest.name,
        "task_categories": list(TASKS),
        "tags": list(TAGS),
        "size_categories": [size],
        "configs": [
            {
                "config_name": "observations",
                "default": True,
                "data_files": [{"split": s, "path": obs_glob.format(split=s)} for s in obs_splits],
            },
            {
                "config_name": "triplets",
                "data_files": [{"split": s, "path": TRIPLETS.format(split=s)} for s in tri_splits],
            },
        ],
        "dataset_info": [
            {
                "config_name": "observations",
                "features": hf_features(observations_schema(), labels),
                "splits": [
                    {
                        "name": s,
                        "num_bytes": _split_bytes(manifest, _folder(obs_glob, s)),
                        "num_examples": manifest.counts.observations[s],
                    }
                    for s in obs_splits
                ],
            },
            {
                "config_name": "triplets",
                "features": hf_features(triplets_schema(), {}),
                "splits": [
                    {
                        "name": s,
                        "num_bytes": _split_bytes(manifest, TRIPLETS.format(split=s)),
                        "num_examples": manifest.counts.triplets[s],
                    }
                    for s in tri_splits
                ],
            },
        ],
    }


def _scalar(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    return json.dumps(str(value), ensure_ascii=False)  # a YAML double-quoted scalar


def _key(key: str) -> str:
    return key if _PLAIN_KEY.match(key) else json.dumps(key)


def _yaml(value: Any, indent: int) -> list[str]:
    """Block YAML of dicts, lists and scalars (the subset the front matter uses)."""
    pad = " " * indent
    lines: list[str] = []
    if isinstance(value, dict):
        for k, v in value.items():
            if isinstance(v, dict | list) and v:
                lines.append(f"{pad}{_key(k)}:")
                lines.extend(_yaml(v, indent + 2))
            else:
                lines.append(f"{pad}{_key(k)}: {_scalar(v) if v != [] else '[]'}")
        return lines
    for item in value:
        inner = _yaml(item, indent + 2) if isinstance(item, dict | list) else [_scalar(item)]
        if isinstance(item, dict | list):
            lines.append(f"{pad}- {inner[0].lstrip()}")
            lines.extend(inner[1:])
        else:
            lines.append(f"{pad}- {inner[0]}")
    return lines


def front_matter(manifest: Manifest) -> str:
    """The card's front matter block, fences included (its first lines, byte for byte)."""
    return "\n".join([_FENCE, *_yaml(card_metadata(manifest), 0), _FENCE]) + "\n"


def read_front_matter(path: Path) -> str:
    """The front matter block of the card at ``path``, fences included.

    Raises:
        DatasetError: no file, or it does not start with a ``---`` fenced block.
    """
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise DatasetError(f"{path}: cannot read the dataset card ({exc})") from None
    lines = text.split("\n")
    if lines[0] != _FENCE or _FENCE not in lines[1:]:
        raise DatasetError(f"{path}: no YAML front matter (a block fenced by '---' lines)")
    end = lines.index(_FENCE, 1)
    return "\n".join(lines[: end + 1]) + "\n"


# --------------------------------------------------------------------------- body


def _histograms(root: Path, manifest: Manifest) -> tuple[Counter, Counter]:
    """(views per room type, visible objects per class) over every split."""
    room_types: Counter = Counter()
    classes: Counter = Counter()
    for split, rooms in manifest.splits.items():
        for room in rooms:
            path = root / OBSERVATIONS.format(split=split, room_id=room)
            try:
                table = pq.read_table(path, columns=["room_type", "objects"])
            except (pa.ArrowException, OSError) as exc:
                raise DatasetError(f"{path}: cannot read room_type, objects ({exc})") from None
            room_types.update(table.column("room_type").to_pylist())
            names = pc.struct_field(pc.list_flatten(table.column("objects")), "class_name")
            classes.update(names.to_pylist())
    return room_types, classes


def _body(root: Path, manifest: Manifest) -> list[str]:
    m = manifest
    room_types, classes = _histograms(root, m)
    counts = [
        [s, len(m.splits[s]), m.counts.observations[s], m.counts.triplets[s], *m.counts.tiers[s]]
        for s in m.splits
    ]
    first = next(iter(m.splits), "train")
    config = json.dumps(m.config, indent=2, sort_keys=True, ensure_ascii=False)
    return [
        f"# {m.name} {m.version}",
        "",
        "Scene-graph views of indoor rooms whose objects move between layouts: each row of",
        "`observations` is one rendered (or photographed) view with its camera pose, the image,",
        "the visible objects (class, GCN slot, 2D and 3D boxes) and their on / in / proximity /",
        "disjoint relations; each row of `triplets` names an anchor, a positive and a negative",
        "view of one room (the cascaded triplets of SeanNet, paper Table I).",
        "",
        f"Written by {m.generator.name} {m.generator.version}, on-disk format "
        f"{m.format} {m.format_version}, seed {m.seed}. `{MANIFEST}` is the manifest (config,",
        "class vocabulary, every file with its sha256); `croissant.json` describes the same",
        "files as MLCommons Croissant metadata. Field meanings: the sgdata docs, docs/dataset.md.",
        "",
        "## Counts",
        "",
        *markdown.table(
            [
                "split",
                "rooms",
                "views",
                "triplets",
                "tier 0",
                "tier 1",
                "tier 2",
                "tier 3",
                "tier 4",
            ],
            counts,
        ),
        "",
        *markdown.table(["room type", "views"], [[k, room_types[k]] for k in sorted(room_types)]),
        "",
        "Visible objects per class (over every view):",
        "",
        *markdown.table(["class", "objects"], [[k, n] for k, n in sorted(classes.items())]),
        "",
        "`sgdata report ROOT` draws previews and annotated views of this dataset.",
        "",
        "## Loading",
        "",
        "```python",
        "from datasets import load_dataset",
        "",
        'views = load_dataset("ROOT", "observations")  # image: a PIL image; objects: dicts',
        'triplets = load_dataset("ROOT", "triplets")',
        "```",
        "",
        "```python",
        "import pyarrow.dataset as pads",
        "",
        f'obs = pads.dataset("ROOT/observations/{first}", format="parquet").to_table()',
        'png = obs.column("image")[0]["bytes"].as_py()  # the encoded PNG/JPEG',
        "```",
        "",
        "```sql",
        f"SELECT o.class_name, count(*) FROM (SELECT unnest(objects) AS o FROM "
        f"'ROOT/observations/{first}/*.parquet') GROUP BY 1;",
        "```",
        "",
        "```python",
        "from seannet.data import TripletDataset",
        "",
        f'triplets = TripletDataset("ROOT", "{first}")  # tensors for training SeanNet',
        "```",
        "",
        "## Generation config",
        "",
        "<details><summary>the resolved config</summary>",
        "",
        "```json",
        config,
        "```",
        "",
        "</details>",
        "",
        "## Licence and citation",
        "",
        f"The data: [CC BY 4.0]({DATA_LICENSE_URL}). The model and the triplet scheme come from",
        f"SeanNet ([arXiv:2110.02276]({PAPER_URL})):",
        "",
        "```bibtex",
        "@misc{li2021seannet,",
        "  title = {SeanNet: Semantic Understanding Network for Localization Under Object"
        " Dynamics},",
        "  author = {Li, Xiao and others},",
        "  year = {2021},",
        "  eprint = {2110.02276},",
        "  archivePrefix = {arXiv},",
        "}",
        "```",
    ]


def card_text(root: Path, manifest: Manifest) -> str:
    """The whole card of the dataset at ``root``: front matter, then the body."""
    return front_matter(manifest) + "\n" + "\n".join(_body(Path(root), manifest)) + "\n"


def write_card(root: Path, manifest: Manifest) -> Path:
    """Write ``root/README.md`` atomically."""
    path = Path(root) / CARD
    atomic_write_text(path, card_text(root, manifest))
    return path
