"""Surface: a detector run handed to ``sgdata label --detector``, broken as users and detector
packages break it, through :func:`sgdata.label.box_proposer.open_proposer` and the proposer it
returns, called on a photo as the label server calls it.

The run's ``detector.json`` is missing, not JSON, not an object, or names its opener wrongly
(no colon, two, a module or a function that does not exist). The opener raises or returns
something that cannot be called. The detector raises, or returns None, a number, a generator
that raises half-way, or rows that are not boxes: dicts, boxes of three or five values, of
strings, None, NaN, infinities, huge or reversed corners, scores that are NaN, strings or out of
[0, 1], class names that are unknown, None or lists. Each ends in one ``ConfigError`` line, or in
the boxes an oracle written here expects: the finite, known, scored ones, clipped to the photo,
best first.
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path
from typing import Any

from hypothesis import strategies as st

from sgdata.errors import ConfigError

from .harness import Surface

KNOWN = ("Chair", "Mug", "Toaster")
MODULE = "fuzzed_detector"  # the detector package every example's run names
H, W, MIN_SCORE = 40, 60, 0.5

RECORDS = (*["valid"] * 12, "missing", "not json", "list", "no proposer", "proposer int",
           "no colon", "two colons", "no module", "no function")  # fmt: skip
OPENERS = (*["valid"] * 12, "raises", "not callable")
RESULTS = (*["list"] * 10, "tuple", "generator", "raises", "raises late", "none", "int")
COORDS = (*["valid"] * 12, "nan", "inf", "-inf", "huge", "negative", "reversed", "string",
          "none", "three", "five", "ints", "numpy", "int overflow")  # fmt: skip
SCORES = (*["valid"] * 10, "nan", "inf", "negative", "above one", "string", "none", "int",
          "int overflow")  # fmt: skip
CLASSES = (*["known"] * 10, "unknown", "none", "list", "int")

rows = st.fixed_dictionaries(
    {
        "row": st.sampled_from((*["box"] * 12, "dict", "tuple")),
        "coords": st.sampled_from(COORDS),
        "corners": st.tuples(*[st.floats(-20, 80, allow_nan=False)] * 4),
        "score": st.sampled_from(SCORES),
        "value": st.floats(0, 1),
        "class": st.sampled_from(CLASSES),
        "known": st.sampled_from(KNOWN),
    }
)
runs = st.fixed_dictionaries(
    {
        "record": st.sampled_from(RECORDS),
        "opener": st.sampled_from(OPENERS),
        "result": st.sampled_from(RESULTS),
        "rows": st.lists(rows, max_size=6),
    }
)

# The detector package the runs name: it reads its behaviour from the run's fuzz.json.
DETECTOR = """
import json, math
from pathlib import Path
import numpy as np
from sgdata.label.box_proposer import ProposedBox

def _coords(r):
    c = r["coords"]
    u1, v1, u2, v2 = r["corners"]
    return {"valid": (u1, v1, u2, v2), "nan": (math.nan, v1, u2, v2),
            "inf": (u1, v1, math.inf, v2), "-inf": (-math.inf, v1, u2, v2),
            "huge": (u1, v1, 1e300, v2), "negative": (-1e6, -1e6, u2, v2),
            "reversed": (u2, v2, u1, v1), "string": ("1", v1, u2, v2),
            "none": None, "three": (u1, v1, u2), "five": (u1, v1, u2, v2, 1.0),
            "ints": tuple(int(x) for x in (u1, v1, u2, v2)),
            "numpy": np.array([u1, v1, u2, v2], np.float32),
            "int overflow": (u1, v1, 10**400, v2)}[c]

def _score(r):
    return {"valid": r["value"], "nan": math.nan, "inf": math.inf, "negative": -0.5,
            "above one": 1.5, "string": "0.9", "none": None, "int": 1,
            "int overflow": 10**400}[r["score"]]

def _class(r):
    return {"known": r["known"], "unknown": "Giraffe", "none": None, "list": ["Mug"],
            "int": 3}[r["class"]]

def _row(r):
    if r["row"] == "dict":
        return {"class_name": _class(r), "box": _coords(r), "score": _score(r)}
    if r["row"] == "tuple":
        return (_class(r), _coords(r), _score(r))
    return ProposedBox(_class(r), _coords(r), _score(r))

def open_detector(run):
    spec = json.loads((Path(run) / "fuzz.json").read_text())
    if spec["opener"] == "raises":
        raise RuntimeError("weights do not match the architecture")
    if spec["opener"] == "not callable":
        return 42

    def detect(pixels):
        found = [_row(r) for r in spec["rows"]]
        kind = spec["result"]
        if kind == "raises":
            raise ValueError("CUDA out of memory")
        if kind == "raises late":
            def rows():
                yield from found
                raise KeyError("late")
            return rows()
        return {"list": found, "tuple": tuple(found), "generator": iter(found),
                "none": None, "int": 7}[kind]

    return detect
"""


def _record_text(kind: str) -> str:
    target = {"no colon": MODULE, "two colons": f"{MODULE}:a:b", "no module": "nowhere:open",
              "no function": f"{MODULE}:gone"}.get(kind, f"{MODULE}:open_detector")  # fmt: skip
    if kind == "not json":
        return '{"proposer": '
    if kind == "list":
        return json.dumps([target])
    if kind == "no proposer":
        return json.dumps({"detector": target})
    if kind == "proposer int":
        return json.dumps({"proposer": 3})
    return json.dumps({"proposer": target})


def _expected(example: dict[str, Any]) -> list[tuple[str, tuple[int, ...], float]] | None:
    """The boxes the proposer must return, best first; None where it must refuse."""
    import numpy as np

    if example["record"] != "valid" or example["opener"] != "valid":
        return None
    if example["result"] in ("raises", "raises late", "none", "int"):
        return None
    kept = []
    for r in example["rows"]:
        if r["row"] != "box" or r["coords"] in ("string", "none", "three", "five"):
            return None  # not a box: the detector is broken, not slipping
        if r["class"] in ("none", "list", "int") or r["score"] in ("string", "none"):
            return None
        score = {"valid": r["value"], "nan": math.nan, "inf": math.inf, "negative": -0.5,
                 "above one": 1.5, "int": 1, "int overflow": math.inf}[r["score"]]  # fmt: skip
        u1, v1, u2, v2 = r["corners"]
        corners = {"nan": None, "inf": None, "-inf": None, "huge": (u1, v1, 1e300, v2),
                   "int overflow": None,
                   "negative": (-1e6, -1e6, u2, v2), "reversed": (u2, v2, u1, v1),
                   "ints": tuple(float(int(x)) for x in (u1, v1, u2, v2))}  # fmt: skip
        box = corners.get(r["coords"], (u1, v1, u2, v2))
        if r["coords"] == "numpy":
            box = tuple(float(x) for x in np.float32((u1, v1, u2, v2)))
        if box is None or not math.isfinite(score) or score < MIN_SCORE or r["class"] != "known":
            continue  # a slip: left out
        a, b, c, d = (round(x) for x in box)
        a, c = max(0, min(a, W)), max(0, min(c, W))
        b, d = max(0, min(b, H)), max(0, min(d, H))
        if c - a >= 2 and d - b >= 2:
            kept.append((r["known"], (a, b, c, d), float(score)))
    return sorted(kept, key=lambda k: -k[2])


def feed(example: dict[str, Any], work: Path, session: None) -> None:
    import numpy as np

    from sgdata.label.box_proposer import open_proposer

    package = work / "package"
    package.mkdir()
    (package / f"{MODULE}.py").write_text(DETECTOR)
    run = work / "run"
    run.mkdir()
    if example["record"] != "missing":
        (run / "detector.json").write_text(_record_text(example["record"]))
    (run / "fuzz.json").write_text(json.dumps(example))
    expected = _expected(example)
    sys.path.insert(0, str(package))
    sys.modules.pop(MODULE, None)  # each example's own copy of the package
    try:
        proposer = open_proposer(run, min_score=MIN_SCORE, known=KNOWN)
        found = proposer(np.zeros((H, W, 3), np.uint8))
    except ConfigError as exc:
        assert expected is None, f"a valid run refused: {str(exc)[:200]}"
        raise
    finally:
        sys.path.remove(str(package))
        sys.modules.pop(MODULE, None)
    assert expected is not None, "a broken run gave boxes: " + repr(example)[:300]
    got = [(b.class_name, tuple(b.box), b.score) for b in found]
    assert got == expected, f"boxes {got} != expected {expected}"


SURFACE = Surface(name="detector runs for sgdata label --detector", inputs=runs, feed=feed)
