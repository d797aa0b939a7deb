"""What keeps a photo from export, as the API reports it: per photo and in the listing."""

from __future__ import annotations

from pathlib import Path

from fastapi.testclient import TestClient

from sgdata.label.server import create_app

TABLE = {"id": 0, "class_name": "DiningTable", "box": [40, 100, 280, 230]}
MUG = {"id": 1, "class_name": "Mug", "box": [120, 60, 170, 105]}


def _client(photos_dir: Path, tmp_path: Path) -> TestClient:
    return TestClient(create_app(photos_dir, tmp_path / "ds"), base_url="http://127.0.0.1")


def _put(client: TestClient, name: str, revision: int, **fields) -> dict:
    body = {"revision": revision, "room_id": "k1", "room_type": "kitchen", **fields}
    response = client.put(f"/api/labels/{name}", json=body)
    assert response.status_code == 200, response.text
    return response.json()


def _listed(client: TestClient) -> dict[str, dict]:
    return {p["name"]: p for p in client.get("/api/photos").json()["photos"]}


def test_ready_means_room_set_every_box_classed_and_nothing_undecided(
    photos_dir: Path, tmp_path: Path
) -> None:
    client = _client(photos_dir, tmp_path)
    fresh = client.get("/api/labels/a.png").json()
    assert fresh["problems"] == ["no room id", "no room type"]
    unclassed = {**MUG, "class_name": ""}
    saved = _put(client, "a.png", 0, objects=[TABLE, unclassed])
    assert saved["problems"] == ["box 1 has no class", "1 undecided proposal(s)"]
    saved = _put(client, "a.png", 1, objects=[TABLE, MUG])
    assert saved["problems"] == ["1 undecided proposal(s)"]
    assert not _listed(client)["a.png"]["ready"]
    saved = _put(
        client, "a.png", 2, objects=[TABLE, MUG], relations=[{"src": 1, "dst": 0, "type": "on"}]
    )
    assert saved["problems"] == []
    listed = _listed(client)
    assert listed["a.png"]["ready"] and not listed["b.png"]["ready"]


def test_new_ids_and_classes_are_checked_across_the_room(photos_dir: Path, tmp_path: Path) -> None:
    client = _client(photos_dir, tmp_path)
    _put(client, "a.png", 0, objects=[TABLE, MUG])
    other = _put(client, "b.png", 0, objects=[{**MUG, "class_name": "Cup"}])
    assert other["room_ids"] == [0, 1]  # the page draws new boxes from id 2 on
    (problem,) = other["problems"]
    assert problem.startswith("box 1 is Cup here but Mug in a.png (same room)")
    assert not _listed(client)["b.png"]["ready"]
    moved = _put(client, "b.png", 1, room_id="k2", objects=[{**MUG, "class_name": "Cup"}])
    assert moved["room_ids"] == [] and moved["problems"] == []
