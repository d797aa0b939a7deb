"""Surface: request bodies of the label server's save (``PUT /api/labels/<photo>``), through its
public HTTP interface: a real ``sgdata label`` process on a free port.

Bodies are mutations of a valid save: JSON nested deep, large, of the wrong types, with
repeated or negative ids and stale or huge revisions, or not JSON at all. The contract here
is HTTP's: a 4xx with a JSON ``detail`` or a 200, never a 5xx, and the photo's labels still
readable afterwards.
"""

from __future__ import annotations

import contextlib
import json
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import httpx
from hypothesis import strategies as st

from ..sgdata.label.conftest import make_photo
from ..sgdata.label.server_process import label_server
from .harness import Surface
from .mutations import NASTY_TEXT, mutated

BODY = {
    "revision": 0,
    "room_id": "kitchen_1",
    "room_type": "kitchen",
    "pose": {"layout": 0, "i": 2, "j": -1, "heading": 3},
    "objects": [
        {"id": 1, "class_name": "DiningTable", "box": [10, 40, 200, 180]},
        {"id": 2, "class_name": "Mug", "box": [50, 20, 80, 60]},
    ],
    "relations": [{"src": 2, "dst": 1, "type": "on"}],
}
OK = {200, 400, 404, 409, 413, 415, 422}  # what a save may answer


def _nested(depth: int) -> bytes:
    """A save whose ``objects`` is a list nested ``depth`` deep (written as text: Python's own
    JSON encoder stops near 1,000 levels)."""
    return b'{"revision": 0, "objects": ' + b"[" * depth + b"]" * depth + b"}"


bodies = st.tuples(
    st.sampled_from(["a.png", "a.png", "a.png", "nope.png", "a%2Epng", "..%2Fa.png"]),
    st.one_of(
        mutated(BODY, most=3),
        st.integers(1, 5000).map(_nested),
        st.sampled_from([b"", b"{", b"\xff\xfe", b"[" * 100_000, b'{"revision": 1e999}']),
        st.sampled_from(NASTY_TEXT).map(lambda t: t.encode("utf-8", "surrogatepass")),
        st.integers(1, 3).map(lambda k: {**BODY, "room_id": "x" * (400_000 * k)}),
    ),
    st.sampled_from(["application/json", "application/json", "text/plain"]),
)


@contextlib.contextmanager
def server(root: Path) -> Iterator[httpx.Client]:
    """A running label server over one photo, and a client of it."""
    photos = root / "photos"
    photos.mkdir(parents=True)
    make_photo(photos / "a.png")  # 320 x 240
    # a fresh connection per request: a server may close one after refusing a body unread
    fresh = httpx.Limits(max_keepalive_connections=0)
    with (
        label_server(photos, root / "out") as (url, _),
        httpx.Client(base_url=url, limits=fresh) as client,
    ):
        yield client


def _depth(data: bytes) -> int:
    """How deep brackets nest in a body (strings ignored: an estimate for the message)."""
    depth = deepest = 0
    for byte in data.replace(b"{", b"[").replace(b"}", b"]"):
        depth += (byte == 0x5B) - (byte == 0x5D)
        deepest = max(deepest, depth)
    return deepest


def feed(example: tuple[str, Any, str], work: Path, client: httpx.Client) -> None:
    name, body, content_type = example
    data = body if isinstance(body, bytes) else json.dumps(body).encode()
    answer = client.put(
        f"/api/labels/{name}", content=data, headers={"content-type": content_type}, timeout=120
    )
    depth = _depth(data) if data.count(b"[") > 500 else 0
    deep = f" (JSON nested {depth} deep)" if depth > 500 else ""
    assert answer.status_code in OK, f"HTTP {answer.status_code}{deep}: {answer.text[:200]}"
    if answer.status_code != 200:
        assert "detail" in answer.json(), (
            f"HTTP {answer.status_code} without a JSON detail: {answer.text[:200]}"
        )
    after = client.get("/api/labels/a.png", timeout=120)
    assert after.status_code == 200, f"labels unreadable after a save: HTTP {after.status_code}"


SURFACE = Surface(
    name="label server request bodies",
    inputs=bodies,
    feed=feed,
    session=server,
)
