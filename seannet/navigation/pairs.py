"""The navigator's (current, goal) pairs: drawn per room, rendered once, cached on disk.

Pairs are drawn per room from seeded streams (:func:`seannet.seeds.navigator_pairs_seed`) over
every layout of the room (:func:`seannet.navigation.navigator.draw_pair`) and rendered live
(:class:`seannet.data.live_views.LiveRooms`) at the dataset's camera, then resized to the
navigator's input as the localizers' images are. A cache directory holds one ``.npz`` per room
under ``<cache>/<split>-<key digest>/``, where the key is everything the pixels depend on (the
dataset, the split, the seed, the image size, the goal range, the count); each file is written
atomically, so a killed render resumes at its next room, and every epoch and every later run
with the same key reads the pixels instead of rendering them.
"""

from __future__ import annotations

import hashlib
import io
import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from seannet.data.live_views import LiveRooms
from seannet.errors import DataError
from seannet.navigation.motion import local_offset
from seannet.navigation.navigator import NavigatorConfig, draw_pair, resize
from seannet.seeds import navigator_pairs_seed
from sgdata.fileio import atomic_write_bytes, atomic_write_text
from sgdata.seeds import rng_for

__all__ = ["PairSet", "pairs_key", "render_pairs"]

PAIRS_FORMAT = 2  # bump when a cached file's arrays change
_FIELDS = ("current", "goal", "labels", "poses", "rooms")


@dataclass
class PairSet:
    """Rendered pairs and where each came from."""

    current: np.ndarray  # (N, S, S, 3) uint8
    goal: np.ndarray  # (N, S, S, 3) uint8
    labels: np.ndarray  # (N,) int64, an index of NAVIGATOR_ACTIONS
    poses: np.ndarray  # (N, 8) int64: layout, current (i, j, h), goal layout, goal (i, j, h)
    rooms: np.ndarray  # (N,) str

    def __len__(self) -> int:
        return len(self.labels)

    def arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(current, goal, labels): what a batch is made of."""
        return self.current, self.goal, self.labels

    def distances(self) -> np.ndarray:
        """(N,) cells from current to goal (|forward| + |side|)."""
        return np.array(
            [sum(map(abs, local_offset(tuple(p[1:4]), tuple(p[5:7])))) for p in self.poses],
            dtype=np.int64,
        )


def pairs_key(config: NavigatorConfig, split: str, count: int, identity: dict[str, Any]) -> dict:
    """Everything the pixels of a split's pairs depend on."""
    return {
        "format": PAIRS_FORMAT,
        "dataset": identity,
        "split": split,
        "count": count,
        "seed": config.seed,
        "image_size": config.image_size,
        "max_side": config.max_side,
        "max_forward": config.max_forward,
        "cross_layout": config.cross_layout,
    }


def render_pairs(
    live: LiveRooms,
    split: str,
    count: int,
    config: NavigatorConfig,
    *,
    cache: Path | None = None,
    identity: dict[str, Any] | None = None,
) -> PairSet:
    """``count`` pairs over the rooms of ``split``, from ``cache`` where it holds them.

    Args:
        cache: the cache root (None: render, keep nothing).
        identity: the dataset's identity (part of the cache key; required with ``cache``).

    Raises:
        DataError: the split has no room, or no room allows a pair.
    """
    rooms = list(live.dataset.rooms(split)) if split in live.dataset.splits else []
    if not rooms:
        raise DataError(f"{live.data}: split {split!r} has no room to draw navigator pairs from")
    per_room = math.ceil(count / len(rooms))
    directory = None
    if cache is not None:
        key = pairs_key(config, split, count, identity or {})
        text = json.dumps(key, sort_keys=True)
        directory = cache / f"{split}-{hashlib.sha256(text.encode()).hexdigest()[:16]}"
        if not (directory / "key.json").is_file():
            atomic_write_text(directory / "key.json", json.dumps(key, indent=1))
    parts = []
    for room_id in rooms:
        path = directory / f"{room_id}.npz" if directory is not None else None
        part = _load(path) if path is not None else None
        if part is None:
            part = _render_room(live, split, room_id, per_room, config)
            if path is not None:
                _save(part, path)
        parts.append(part)
    if not sum(len(p) for p in parts):
        raise DataError(f"{live.data}: no reachable pair in the rooms of split {split!r}")
    joined = [np.concatenate([getattr(p, name) for p in parts])[:count] for name in _FIELDS]
    return PairSet(*joined)


def _render_room(
    live: LiveRooms, split: str, room_id: str, count: int, config: NavigatorConfig
) -> PairSet:
    """``count`` draws in one room (fewer where draws fail), rendered layout by layout."""
    rng = rng_for(navigator_pairs_seed(config.seed, split, room_id))
    layouts = live.layouts(room_id)
    wanted = [layouts[int(k)] for k in rng.integers(len(layouts), size=count)]
    masks = {}
    for layout in layouts:
        live.load(room_id, layout)
        masks[layout] = live.grid.reachable.copy()
    draws = []  # (layout, current, goal layout, goal, label)
    for layout in sorted(set(wanted)):
        for _ in range(wanted.count(layout)):
            pair = draw_pair(
                masks[layout], rng, max_side=config.max_side, max_forward=config.max_forward
            )
            if pair is None:
                continue
            a, b, label = pair
            goal_layout = layout
            # drawn only when asked, so the pairs without it stay what they were
            if config.cross_layout > 0 and len(layouts) > 1 and rng.random() < config.cross_layout:
                other = [k for k in layouts if k != layout][int(rng.integers(len(layouts) - 1))]
                if masks[other][b[0], b[1]]:  # not inside an object that moved there
                    goal_layout = other
            draws.append((layout, a, goal_layout, b, label))
    s = config.image_size
    current = np.zeros((len(draws), s, s, 3), dtype=np.uint8)
    goal = np.zeros_like(current)
    views = [(d[0], n, d[1], current) for n, d in enumerate(draws)]
    views += [(d[2], n, d[3], goal) for n, d in enumerate(draws)]
    for layout, n, pose, into in sorted(views, key=lambda v: (v[0], v[3] is goal, v[1])):
        live.load(room_id, layout)
        into[n] = resize(live.image(*pose), s)
    return PairSet(
        current=current,
        goal=goal,
        labels=np.array([d[4] for d in draws], dtype=np.int64),
        poses=np.array([(d[0], *d[1], d[2], *d[3]) for d in draws], dtype=np.int64).reshape(-1, 8),
        rooms=np.array([room_id] * len(draws), dtype=str),
    )


def _save(part: PairSet, path: Path) -> None:
    buffer = io.BytesIO()
    np.savez(buffer, **{name: getattr(part, name) for name in _FIELDS})
    atomic_write_bytes(path, buffer.getvalue())


def _load(path: Path) -> PairSet | None:
    """A cached room's pairs; None when missing or unreadable (then rendered again)."""
    try:
        with np.load(path, allow_pickle=False) as npz:
            return PairSet(*(npz[name] for name in _FIELDS))
    except (OSError, ValueError, KeyError):
        return None
