"""The API serves only the photos and its own files, and refuses bad saves with 4xx."""

from __future__ import annotations

import os
import socket
from pathlib import Path

import httpx
import pytest
from fastapi.testclient import TestClient

from sgdata.errors import ConfigError
from sgdata.label.classes import load_class_names
from sgdata.label.server import MAX_BODY, create_app, host_name

from .server_process import label_server

GOOD = {"room_id": "k1", "room_type": "kitchen", "objects": [], "relations": []}


@pytest.fixture
def client(photos_dir: Path, tmp_path: Path) -> TestClient:
    secret = tmp_path / "secret.png"
    secret.write_bytes((photos_dir / "a.png").read_bytes())
    os.symlink(secret, photos_dir / "link.png")  # a symlink out of the photos directory
    app = create_app(photos_dir, tmp_path / "ds")
    return TestClient(app, base_url="http://127.0.0.1")


def _labels_dir(tmp_path: Path) -> dict[str, bytes]:
    root = tmp_path / "ds" / "labels"
    return {p.name: p.read_bytes() for p in root.iterdir()} if root.exists() else {}


def test_lists_photos_and_skips_the_rest(client: TestClient) -> None:
    body = client.get("/api/photos").json()
    assert [p["name"] for p in body["photos"]] == ["a.png", "b.png", "c.jpg"]
    skipped = {s["name"]: s["reason"] for s in body["skipped"]}
    assert set(skipped) == {"broken.png", "link.png", "notes.txt"}
    assert "outside" in skipped["link.png"]
    assert client.get("/photos/a.png").status_code == 200
    assert client.get("/").status_code == 200 and client.get("/static/app.js").status_code == 200


@pytest.mark.parametrize(
    "path",
    [
        "/photos/../secret.png",
        "/photos/%2e%2e%2fsecret.png",
        "/photos/..%2fsecret.png",
        "/photos/%2e%2e/secret.png",
        "/photos//etc/passwd",
        "/photos/%2fetc%2fpasswd",
        "/photos/link.png",
        "/photos/notes.txt",
        "/static/../server.py",
        "/static/%2e%2e%2fserver.py",
        "/static/__init__.py",
        "/api/labels/..%2f..%2fsecret.png",
    ],
)
def test_traversal_is_refused(client: TestClient, path: str) -> None:
    response = client.get(path)
    assert 400 <= response.status_code < 500
    assert b"PNG" not in response.content[:8]


def test_foreign_host_is_refused(client: TestClient) -> None:
    assert client.get("/api/photos", headers={"Host": "evil.example"}).status_code == 400
    assert client.get("/api/photos", headers={"Host": "[::2]:8765"}).status_code == 400
    assert client.get("/api/photos", headers={"Host": "127.0.0.1.evil:80"}).status_code == 400


@pytest.mark.parametrize("host", ["[::1]:8765", "[::1]", "127.0.0.1:8765", "localhost"])
def test_loopback_hosts_are_answered(client: TestClient, host: str) -> None:
    assert client.get("/api/photos", headers={"Host": host}).status_code == 200


def _ipv6_loopback() -> bool:
    try:
        with socket.socket(socket.AF_INET6) as s:
            s.bind(("::1", 0))
        return True
    except OSError:
        return False


@pytest.mark.skipif(not _ipv6_loopback(), reason="this machine has no IPv6 loopback")
def test_a_server_on_ipv6_loopback_answers(photos_dir: Path, tmp_path: Path) -> None:
    with label_server(photos_dir, tmp_path / "ds", host="::1") as (url, _):
        assert url.startswith("http://[::1]:")
        assert httpx.get(url + "/api/photos").status_code == 200
        assert httpx.get(url + "/api/photos", headers={"Host": "evil.example"}).status_code == 400


def test_host_name_reads_bracketed_ipv6() -> None:
    assert host_name("[::1]:8765") == "::1" and host_name("127.0.0.1:80") == "127.0.0.1"
    assert host_name("[::1") == "" and host_name("localhost") == "localhost"


@pytest.mark.parametrize(
    ("body", "status"),
    [
        (b"{not json", 400),
        (b'{"room_id": "k1", "colour": "red"}', 422),  # unknown field
        (b'{"objects": [{"id": 0, "class_name": "Mug", "box": [1, 1, 5, 5], "x": 1}]}', 422),
        (b'{"objects": [{"id": 0, "class_name": "Mug", "box": [1, 1, 500, 5]}]}', 422),
        (b'{"objects": [{"id": 0, "class_name": "Unicorn", "box": [1, 1, 5, 5]}]}', 422),
        (b'{"room_id": "../etc"}', 422),
        (b'{"relations": [{"src": 0, "dst": 1, "type": "on"}]}', 422),
        (b"[]", 422),
        (b"{" + b" " * (MAX_BODY + 1) + b"}", 413),
        (b"[" * 200_000 + b"]" * 200_000, 400),  # nested too deep for the parser: not a 500
        (b'{"objects": [{"id": 0, "class_name": "Saucer", "box": [1, 1, 5, 5]}]}', 422),
    ],
)
def test_bad_saves_are_refused_and_change_nothing(
    client: TestClient, tmp_path: Path, body: bytes, status: int
) -> None:
    assert client.put("/api/labels/a.png", json=GOOD).status_code == 200
    before = _labels_dir(tmp_path)
    headers = {"Content-Type": "application/json"}
    response = client.put("/api/labels/a.png", content=body, headers=headers)
    assert response.status_code == status
    assert _labels_dir(tmp_path) == before


def test_unknown_class_names_the_closest_and_how_to_map(client: TestClient) -> None:
    body = {**GOOD, "objects": [{"id": 0, "class_name": "Saucr", "box": [1, 1, 5, 5]}]}
    (detail,) = client.put("/api/labels/a.png", json=body).json()["detail"]
    assert detail.startswith("unknown class 'Saucr'; closest: ") and "--classes" in detail
    message = client.get("/api/classes/unknown", params={"name": "Mugg"}).json()["message"]
    assert "closest: Mug" in message and '"Mugg" = "Mug"' in message


def test_favicon_is_served(client: TestClient) -> None:
    for path in ("/favicon.ico", "/static/favicon.svg"):
        response = client.get(path)
        assert response.status_code == 200 and response.content.startswith(b"<svg")


def test_other_content_types_and_unknown_photos_are_refused(client: TestClient) -> None:
    text = {"Content-Type": "text/plain"}
    assert client.put("/api/labels/a.png", content=b"{}", headers=text).status_code == 415
    assert client.put("/api/labels/zzz.png", json=GOOD).status_code == 404


def test_stale_revision_is_a_conflict(client: TestClient) -> None:
    first = client.put("/api/labels/b.png", json=GOOD).json()
    assert first["labels"]["revision"] == 1
    other_tab = client.put("/api/labels/b.png", json={**GOOD, "room_id": "k2"})  # revision 0
    assert other_tab.status_code == 409 and other_tab.json()["revision"] == 1
    assert client.get("/api/labels/b.png").json()["labels"]["room_id"] == "k1"


def test_bad_inputs_are_one_line_config_errors(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="does not exist"):
        create_app(tmp_path / "nowhere", tmp_path / "ds")
    bad = tmp_path / "map.toml"
    bad.write_text('mug = "Unicorn"\n')
    with pytest.raises(ConfigError, match="not a catalog class"):
        load_class_names(bad)
    bad.write_text("mug = \n")
    with pytest.raises(ConfigError, match="not valid TOML"):
        load_class_names(bad)
    good = tmp_path / "good.toml"
    good.write_text('"coffee mug" = "Mug"\n')
    names = load_class_names(good)
    assert names.resolve("coffee mug") == "Mug" and names.resolve("Mug") == "Mug"
