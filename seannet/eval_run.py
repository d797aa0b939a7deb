"""``seannet eval``: evaluate a run's best checkpoint and write JSON, markdown and heat maps."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
from PIL import Image, ImageDraw, ImageFont

from sgdata.fileio import atomic_write_text
from sgdata.preview import save_png

from .checkpoint import check_same_dataset, load_checkpoint
from .config import TrainConfig
from .data import ImageTransform, TripletDataset, dataset_identity
from .evaluate import (
    MAX_OFFSET,
    choose_threshold,
    embed_split,
    offset_statistics,
    threshold_quality,
    triplet_metrics,
)
from .train import BEST, build_for_dataset, device_for_run

__all__ = ["evaluate_run", "draw_heatmap"]


def evaluate_run(run: Path, data: Path, *, split: str = "test", out: Path | None = None) -> dict:
    """Evaluate ``run/best.pt`` on ``split`` of ``data``; writes ``eval_<split>.*`` files.

    Raises:
        CheckpointError: no checkpoint, or it was trained on another dataset.
        DataError: the dataset or split is missing.
    """
    out = out or run
    path = run / BEST
    state = load_checkpoint(path)
    check_same_dataset(path, state["dataset"], dataset_identity(data))
    config = TrainConfig(**state["config"])
    device = device_for_run()
    model = build_for_dataset(config, data).to(device)
    model.load_state_dict(state["model"])
    val = embed_split(model, config, data, "val", device)
    evaluated = embed_split(model, config, data, split, device)
    transform = ImageTransform(size=config.image_size)
    metrics = triplet_metrics(evaluated, TripletDataset(data, split, transform=transform))
    threshold = choose_threshold(val)
    quality = threshold_quality(evaluated, threshold["epsilon"])
    stats = offset_statistics(evaluated)
    result: dict[str, Any] = {
        "run": str(run),
        "model": config.model,
        "split": split,
        "epoch": state["epoch"],
        **metrics,
        "threshold": {**threshold, "rule": "max balanced accuracy, same pose vs one step (val)"},
        "threshold_on_split": quality,
        "offset_mean": _plain(stats["mean"]),
        "offset_std": _plain(stats["std"]),
        "offset_count": stats["count"].astype(int).tolist(),
    }
    out.mkdir(parents=True, exist_ok=True)
    atomic_write_text(out / f"eval_{split}.json", json.dumps(result, indent=2))
    atomic_write_text(out / f"eval_{split}.md", _markdown(result))
    save_png(
        draw_heatmap(stats["mean"], f"{config.model}: mean S by offset"),
        out / f"heat_mean_{split}.png",
    )
    save_png(
        draw_heatmap(stats["std"], f"{config.model}: std S by offset"),
        out / f"heat_std_{split}.png",
    )
    return result


def _plain(grid: np.ndarray) -> list[list[float | None]]:
    return [[None if math.isnan(v) else round(float(v), 4) for v in row] for row in grid]


def _markdown(result: dict) -> str:
    lines = [
        f"# {result['model']} on {result['split']} (epoch {result['epoch']})",
        "",
        f"- triplet accuracy: **{100 * result['accuracy']:.2f} %** "
        f"over {result['triplets']} triplets",
        f"- mean S(A,P) - S(A,N): {result['mean_gap']:.3f}",
        f"- threshold epsilon (val): {result['threshold']['epsilon']:.3f}; "
        f"precision {result['threshold_on_split']['precision']:.3f}, "
        f"recall {result['threshold_on_split']['recall']:.3f} on {result['split']}",
        "",
        "| tier | accuracy |",
        "|---|---|",
        *(f"| {k} | {100 * v:.1f} % |" for k, v in result["per_tier"].items()),
        "",
        "| room | accuracy |",
        "|---|---|",
        *(f"| {k} | {100 * v:.1f} % |" for k, v in result["per_room"].items()),
    ]
    return "\n".join(lines) + "\n"


def draw_heatmap(grid: np.ndarray, title: str, *, cell: int = 44) -> Image.Image:
    """A (2k+1)^2 grid of values as coloured cells with numbers; rows delta i, columns delta j."""
    size = grid.shape[0]
    margin = 40
    image = Image.new("RGB", (margin + size * cell + 10, margin + size * cell + 24), "white")
    draw = ImageDraw.Draw(image)
    font = ImageFont.load_default(size=11)
    draw.text((margin, 4), title, fill="black", font=font)
    finite = grid[np.isfinite(grid)]
    lo, hi = (float(finite.min()), float(finite.max())) if len(finite) else (0.0, 1.0)
    for r in range(size):
        for c in range(size):
            x, y = margin + c * cell, 20 + margin + r * cell - 20
            value = grid[r, c]
            if math.isfinite(value):
                t = (value - lo) / (hi - lo) if hi > lo else 1.0
                color = (int(255 * t), int(80 + 100 * (1 - abs(2 * t - 1))), int(255 * (1 - t)))
                draw.rectangle([x, y, x + cell - 1, y + cell - 1], fill=color)
                draw.text(
                    (x + cell / 2, y + cell / 2),
                    f"{value:.2f}",
                    fill="white",
                    font=font,
                    anchor="mm",
                )
            else:
                draw.rectangle([x, y, x + cell - 1, y + cell - 1], fill=(235, 235, 235))
        draw.text(
            (margin - 6, 20 + margin + r * cell - 20 + cell / 2),
            f"{r - MAX_OFFSET:+d}",
            fill="black",
            font=font,
            anchor="rm",
        )
    for c in range(size):
        draw.text(
            (margin + c * cell + cell / 2, margin + size * cell + 8),
            f"{c - MAX_OFFSET:+d}",
            fill="black",
            font=font,
            anchor="mm",
        )
    return image
