"""``seannet navigate``: the paper's Table II for some localizer runs, JSON, markdown, strips.

Every localizer run is tested on the same episodes: each is drawn from
:func:`sgdata.seeds.episode_seed` (test seed, room, case, index) and from the map's structure,
which is the same whatever run embedded it. Maps are built once per run and room into
``<maps>/<run name>/<room>/`` and reused (:func:`seannet.navigation.maps.ensure_map`).
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from PIL import Image, ImageDraw, ImageFont

from seannet.data.datasets import dataset_identity, open_dataset
from seannet.data.live_views import LiveRooms
from seannet.errors import NavigationError
from seannet.navigation.episodes import (
    CASES,
    FAILURES,
    K_MAX,
    EpisodeResult,
    run_episode,
    sample_episode,
)
from seannet.navigation.localizer import load_localizer
from seannet.navigation.maps import ensure_map
from seannet.navigation.navigator import load_navigator, resize
from seannet.training.runs import BEST, check_same_dataset, load_checkpoint
from sgdata.fileio import atomic_write_text, save_png
from sgdata.seeds import episode_seed, rng_for

__all__ = ["run_navigation", "table_rows", "draw_strip"]

STRIP_EPISODES = 2  # per case, in the split's first room, per run
STRIP_PANEL = 112  # pixels
STRIP_MAX_PANELS = 16


def run_navigation(
    runs: list[Path],
    navigator: Path,
    data: Path,
    *,
    split: str = "test",
    episodes: int = 20,
    seed: int = 0,
    k_max: int = K_MAX,
    spacing: int = 2,
    epsilon: float | None = None,
    out: Path | None = None,
    maps: Path | None = None,
    strips: Path | None = None,
    progress: Callable[[str], None] | None = None,
) -> dict[str, Any]:
    """Run the navigation test of every localizer run on the rooms of ``split``.

    Writes ``navigate_<split>.json`` and ``.md`` into ``out`` (default: the navigator run),
    maps under ``maps`` (default: ``out/maps``), strips under ``strips`` when given.

    Raises:
        CheckpointError: a run or the navigator was trained on another dataset.
        NavigationError: no epsilon for a run, a split without rooms, or a room without an
            episode.
    """
    if episodes < 1:
        raise NavigationError(f"--episodes {episodes}: expected >= 1 per case and room")
    out = out or navigator
    maps = maps or out / "maps"
    identity = dataset_identity(data)
    state = load_checkpoint(navigator / BEST)
    check_same_dataset(navigator / BEST, state["dataset"], identity)
    policy = load_navigator(navigator)
    ds = open_dataset(data)
    rooms = list(ds.rooms(split)) if split in ds.splits else []
    if not rooms:
        raise NavigationError(f"{data}: split {split!r} has no room to navigate in")
    say = progress or (lambda _: None)
    results: dict[str, Any] = {
        "split": split,
        "episodes_per_case_and_room": episodes,
        "seed": seed,
        "k_max": k_max,
        "spacing": spacing,
        "navigator": str(navigator),
        "runs": [],
    }
    with LiveRooms(data) as live:
        for run in runs:
            localizer = load_localizer(run, data, epsilon=epsilon)
            records: list[dict[str, Any]] = []
            for r, room_id in enumerate(rooms):
                say(f"{run.name}: map of {room_id}")
                topo = ensure_map(
                    localizer, live, room_id, maps / run.name / room_id, spacing=spacing
                )
                for case in CASES:
                    for index in range(episodes):
                        rng = rng_for(episode_seed(seed, room_id, case, index))
                        episode = sample_episode(topo, live, case, rng, index=index)
                        keep = strips is not None and r == 0 and index < STRIP_EPISODES
                        say(f"{run.name}: {room_id} {case} {index + 1}/{episodes}")
                        result = run_episode(
                            episode, topo, live, localizer, policy, k_max=k_max, keep_frames=keep
                        )
                        records.append(result.to_dict())
                        if keep and strips is not None:
                            name = f"{room_id}_{case}_{index}.png"
                            save_png(
                                draw_strip(result, topo.image(episode.path[-1])),
                                strips / run.name / name,
                            )
            results["runs"].append(
                {
                    "run": str(run),
                    "model": localizer.name,
                    "epsilon": localizer.epsilon,
                    "epsilon_source": localizer.epsilon_source,
                    "table": _rates(records),
                    "episodes": records,
                }
            )
    out.mkdir(parents=True, exist_ok=True)
    atomic_write_text(out / f"navigate_{split}.json", json.dumps(results, indent=2))
    atomic_write_text(out / f"navigate_{split}.md", _markdown(results))
    results["written"] = str(out / f"navigate_{split}.md")
    return results


def _rates(records: list[dict[str, Any]]) -> dict[str, dict[str, float | int]]:
    """Per case: total episodes, success and failure rates (percent)."""
    table: dict[str, dict[str, float | int]] = {}
    for case in CASES:
        part = [r["outcome"] for r in records if r["case"] == case]
        n = len(part)
        table[case] = {"total": n}
        for outcome in ("success", *FAILURES):
            table[case][outcome] = 100.0 * part.count(outcome) / n if n else float("nan")
    return table


def table_rows(results: dict[str, Any]) -> list[list[str]]:
    """Table II rows: model, total N / A, success N / A, then each failure rate N / A."""
    rows = []
    for run in results["runs"]:
        t = run["table"]
        cells = [
            f"{run['model']} ({Path(run['run']).name})",
            f"{t['N']['total']} / {t['A']['total']}",
        ]
        for outcome in ("success", *FAILURES):
            cells.append(f"{t['N'][outcome]:.1f} / {t['A'][outcome]:.1f}")
        rows.append(cells)
    return rows


HEADER = [
    "localizer",
    "total cases N / A",
    "success % N / A",
    "navigation % N / A",
    "localization % N / A",
    "collision % N / A",
]


def _markdown(results: dict[str, Any]) -> str:
    lines = [
        f"# Navigation test on {results['split']} (paper Table II)",
        "",
        f"{results['episodes_per_case_and_room']} episodes per case and room, k_max "
        f"{results['k_max']}, map spacing {results['spacing']}, seed {results['seed']}; "
        "N: neighbour sub-nodes, A: arbitrary sub-nodes.",
        "",
        "| " + " | ".join(HEADER) + " |",
        "|" + "---|" * len(HEADER),
        *("| " + " | ".join(r) + " |" for r in table_rows(results)),
        "",
        "| localizer | epsilon | from |",
        "|---|---|---|",
        *(
            f"| {r['model']} ({Path(r['run']).name}) | {r['epsilon']:.3f} | {r['epsilon_source']} |"
            for r in results["runs"]
        ),
    ]
    return "\n".join(lines) + "\n"


def draw_strip(result: EpisodeResult, goal: np.ndarray) -> Image.Image:
    """An episode as a strip (the paper's Fig. 9): start, each step's view with its action
    and S, then the goal view; the outcome in the title."""
    e = result.episode
    labels = ["start"]
    for _, steps in result.segments:
        labels += [f"{s.action} S={s.similarity:.2f}" for s in steps if not s.collided]
    frames = list(zip(result.frames, labels, strict=False))[: STRIP_MAX_PANELS - 1]
    frames.append((goal, "goal"))
    size, top = STRIP_PANEL, 34
    image = Image.new("RGB", (len(frames) * (size + 4) + 4, size + top + 18), "white")
    draw = ImageDraw.Draw(image)
    font = ImageFont.load_default(size=11)
    title = (
        f"{e.room_id} layout {e.layout} case {e.case} #{e.index}: {result.outcome} "
        f"({len(e.path) - 1} segments)"
    )
    draw.text((4, 4), title, fill="black", font=font)
    for k, (rgb, label) in enumerate(frames):
        x = 4 + k * (size + 4)
        image.paste(Image.fromarray(resize(rgb, size)), (x, top))
        draw.text((x, top + size + 3), label, fill="black", font=font)
    return image
