"""``seannet eval``: evaluate a run's best checkpoint and write JSON, markdown and heat maps."""

from __future__ import annotations

import json
import math
from dataclasses import asdict
from pathlib import Path
from typing import Any

import numpy as np
from PIL import Image, ImageDraw, ImageFont

from seannet.data.box_noise import BoxNoise
from seannet.data.datasets import ImageTransform, ObservationDataset, TripletDataset
from seannet.data.moved import moved_objects
from seannet.data.opening import DataSource, open_dataset
from seannet.errors import DataError
from seannet.evaluation.box_overlap import SlotBoxes
from seannet.evaluation.embedding_cache import cached_embeddings
from seannet.evaluation.metrics import (
    MAX_OFFSET,
    Embeddings,
    choose_threshold,
    embed_split,
    example_groups,
    offset_statistics,
    pose_pairs,
    similarity_of,
    threshold_quality,
    triplet_metrics,
    triplet_similarities,
)
from seannet.evaluation.retrieval import accuracy_by_moved, map_recall, separation
from seannet.evaluation.scene_term import BOX_KERNEL, SceneTerm
from seannet.markdown import table
from seannet.training.runs import MODEL_KEYS, restore_run
from sgdata.dataset import Dataset
from sgdata.errors import SgdataError
from sgdata.fileio import atomic_write_text, save_png

__all__ = ["draw_heatmap", "eval_file", "evaluate_run"]


def evaluate_run(
    run: Path,
    data: DataSource,
    *,
    split: str = "test",
    out: Path | None = None,
    boxes: str = "",
    noise: BoxNoise | None = None,
) -> dict:
    """Evaluate ``run/best.pt`` on ``split`` of ``data``; writes ``eval_<split><tag>.*`` files.

    ``data`` is an opened dataset (:func:`~seannet.data.opening.open_dataset`) or its root,
    opened once here; everything below is handed the opened dataset.

    Every choice is read off the validation split (epsilon; with ``boxes``, lambda), under
    the same box noise as ``split``; the split evaluated only gives figures.

    Args:
        boxes: a scene term of :data:`~seannet.model.specs.SCENE_TERMS` (``""``: none): score pairs
            ``S + lambda * S_scene``, lambda chosen on val (``+boxes``: the hand-made overlap;
            ``+box-kernel``: the kernel learned on train; :class:`SceneTerm`). Tagged with the
            term's name.
        noise: evaluate with the boxes a labeler or detector would give (:class:`BoxNoise`).
            Tag ``_S<jitter>-P<drop>-Q<spurious>``.

    Raises:
        ValueError: ``boxes`` is not a scene term.
        CheckpointError: no checkpoint, or it was trained on another dataset.
        DataError: the dataset or split is missing; ``boxes`` on a dataset with no val split,
            ``+box-kernel`` on one with no train split.
    """
    scene = SceneTerm.from_spec(boxes)  # a bad name fails before the run is read
    out = out or run
    ds = open_dataset(data)
    # photos: another dataset by design, but the same vocabulary
    restored = restore_run(run, ds, keys=MODEL_KEYS if _all_real(ds, split) else None)
    config, model, device, state = restored.config, restored.model, restored.device, restored.state

    def embedded(name: str) -> Embeddings:
        compute = lambda: embed_split(model, config, ds, name, device, noise=noise)  # noqa: E731
        return cached_embeddings(run, ds, name, noise, compute)

    evaluated = embedded(split)
    transform = ImageTransform.for_model(config.model.image_size, config.model.image_family)
    triplets = TripletDataset(ds, split, transform=transform)
    s_ap, s_an = triplet_similarities(evaluated, triplets)
    val = None
    if "val" in ds.splits:
        val = evaluated if split == "val" else embedded("val")
    name, tag = config.model.name + boxes, _tag(boxes, noise)
    if boxes:
        if val is None:
            raise DataError(
                f"{ds.root}: {boxes} chooses lambda on the val split, and there is none"
            )
        val_triplets = (
            triplets if split == "val" else TripletDataset(ds, "val", transform=transform)
        )
        if scene.learned:
            scene.fit(*_train_boxes(ds, noise))
        v_ap, v_an = triplet_similarities(val, val_triplets)
        scene.choose_weight(v_ap, v_an, *scene.triplet_scores(_boxes(val), val_triplets.obs))
        o_ap, o_an = scene.triplet_scores(_boxes(evaluated), triplets.obs)
        s_ap, s_an = scene.combine(s_ap, o_ap), scene.combine(s_an, o_an)
    metrics = triplet_metrics(triplets, s_ap, s_an)
    moved = moved_objects(ds, split, triplets.obs)
    if val is not None:
        threshold = choose_threshold(val)
        rule = "max balanced accuracy, same pose vs one step (val)"
    else:  # a real dataset holds one split: choosing epsilon on it would grade its own choice
        threshold = {"epsilon": float("nan"), "balanced_accuracy": float("nan")}
        rule = "not chosen: the dataset has no val split"
    quality = threshold_quality(evaluated, threshold["epsilon"])
    stats = offset_statistics(evaluated)
    result: dict[str, Any] = {
        "run": str(run),
        "model": name,
        "split": split,
        "epoch": state["epoch"],
        "noise": asdict(noise) if noise is not None else None,
        **scene.choices,  # the kernel fit on train, lambda on val
        **metrics,
        # epsilon, retrieval and the offset statistics read the embedding alone
        "threshold": {**threshold, "rule": rule},
        "threshold_on_split": quality,
        "retrieval": map_recall(evaluated),
        "by_moved": accuracy_by_moved(s_ap > s_an, moved),
        "separation": separation(*pose_pairs(evaluated)),
        "offset_mean": _plain(stats["mean"]),
        "offset_std": _plain(stats["std"]),
        "offset_count": stats["count"].astype(int).tolist(),
    }
    out.mkdir(parents=True, exist_ok=True)
    if not tag:  # the pictures are the embedding's: drawn once, for the plain evaluation
        result["examples"] = _examples(evaluated, triplets, out, split, name)
        save_png(
            draw_heatmap(stats["mean"], f"{name}: mean S by offset"), out / f"heat_mean_{split}.png"
        )
        save_png(
            draw_heatmap(stats["std"], f"{name}: std S by offset"), out / f"heat_std_{split}.png"
        )
    written = eval_file(out, split, boxes=boxes, noise=noise)
    atomic_write_text(written, json.dumps(result, indent=2))
    atomic_write_text(written.with_suffix(".md"), _markdown(result))
    return result


def eval_file(run: Path, split: str, *, boxes: str = "", noise: BoxNoise | None = None) -> Path:
    """Where :func:`evaluate_run` writes its JSON for these options."""
    return run / f"eval_{split}{_tag(boxes, noise)}.json"


def _tag(boxes: str, noise: BoxNoise | None) -> str:
    tag = boxes
    if noise is not None and noise.active:
        tag += f"_{noise.label()}"
    return tag


def _boxes(embeddings: Embeddings) -> SlotBoxes:
    """The boxes the model saw in every view of ``embeddings``, by slot."""
    assert embeddings.slot_boxes is not None  # embed_split always fills it
    return SlotBoxes(embeddings.obs_ids, *embeddings.slot_boxes, embeddings.num_slots)


def _train_boxes(ds: Dataset, noise: BoxNoise | None) -> tuple[SlotBoxes, list]:
    """The train split's boxes (under ``noise``) and triplets, for ``+box-kernel``'s fit."""
    if "train" not in ds.splits:
        raise DataError(f"{ds.root}: {BOX_KERNEL} learns on the train split, and there is none")
    views = ObservationDataset(ds, "train", noise=noise)
    boxes = SlotBoxes(views.obs_ids, *views.slot_boxes(), views.num_slots)
    return boxes, TripletDataset(ds, "train").obs


def _all_real(ds: Dataset, split: str) -> bool:
    """Whether every observation of ``split`` is a real photo (``domain = "real"``)."""
    try:
        domains = ds.observations(split, columns=["domain"]).column("domain").to_pylist()
    except SgdataError:  # a missing split: the loaders below name it
        return False
    return bool(domains) and set(domains) == {"real"}


def _plain(grid: np.ndarray) -> list[list[float | None]]:
    return [[None if math.isnan(v) else round(float(v), 4) for v in row] for row in grid]


def _percent_rows(shares: dict[str, float]) -> list[tuple[str, str]]:
    return [(k, f"{100 * v:.1f} %") for k, v in shares.items()]


def _markdown(result: dict) -> str:
    retrieval, nan = result["retrieval"], float("nan")
    lines = [
        f"# {result['model']} on {result['split']} (epoch {result['epoch']})",
        "",
        f"- triplet accuracy: **{100 * result['accuracy']:.2f} %** "
        f"over {result['triplets']} triplets",
        f"- mean S(A,P) - S(A,N): {result['mean_gap']:.3f}",
        f"- threshold epsilon (val): {result['threshold']['epsilon']:.3f}; "
        f"precision {result['threshold_on_split']['precision']:.3f}, "
        f"recall {result['threshold_on_split']['recall']:.3f} on {result['split']}",
        f"- recall@1 / @5 of the same pose in the layout-0 map: "
        f"{100 * retrieval['recall'][1]:.1f} / {100 * retrieval['recall'][5]:.1f} % over "
        f"{retrieval['queries']} queries in {retrieval['rooms']} rooms",
        f"- same pose vs one step: S {result['separation'].get('same_pose_mean', nan):.3f} vs "
        f"{result['separation'].get('one_step_mean', nan):.3f}, "
        f"d' = {result['separation']['d_prime']:.2f}",
        "",
        *table(
            ("moved objects in view", "triplets", "accuracy"),
            (
                (k, v["triplets"], f"{100 * v['accuracy']:.1f} %")
                for k, v in result["by_moved"].items()
            ),
        ),
        "",
        *table(("tier", "accuracy"), _percent_rows(result["per_tier"])),
        "",
        *table(("room", "accuracy"), _percent_rows(result["per_room"])),
    ]
    return "\n".join(lines) + "\n"


def draw_heatmap(grid: np.ndarray, title: str) -> Image.Image:
    """Similarity by grid offset: rows delta i, columns delta j, both -4 .. +4."""
    labels = [f"{k - MAX_OFFSET:+d}" for k in range(grid.shape[0])]
    return draw_matrix(grid, labels, labels, title)


def draw_matrix(
    grid: np.ndarray, rows: list[str], columns: list[str], title: str, *, cell: int = 44
) -> Image.Image:
    """A matrix of values as coloured, numbered cells (NaN cells grey), with labels."""
    margin = 40
    height, width = grid.shape
    image = Image.new("RGB", (margin + width * cell + 10, margin + height * cell + 24), "white")
    draw = ImageDraw.Draw(image)
    font = ImageFont.load_default(size=11)
    draw.text((4, 4), title, fill="black", font=font)
    finite = grid[np.isfinite(grid)]
    lo, hi = (float(finite.min()), float(finite.max())) if len(finite) else (0.0, 1.0)
    for r in range(height):
        y = margin + r * cell
        draw.text((margin - 6, y + cell / 2), rows[r], fill="black", font=font, anchor="rm")
        for c in range(width):
            x = margin + c * cell
            value = grid[r, c]
            if not math.isfinite(value):
                draw.rectangle([x, y, x + cell - 1, y + cell - 1], fill=(235, 235, 235))
                continue
            t = (value - lo) / (hi - lo) if hi > lo else 1.0
            color = (int(255 * t), int(80 + 100 * (1 - abs(2 * t - 1))), int(255 * (1 - t)))
            draw.rectangle([x, y, x + cell - 1, y + cell - 1], fill=color)
            draw.text(
                (x + cell / 2, y + cell / 2), f"{value:.3f}", fill="white", font=font, anchor="mm"
            )
    for c in range(width):
        draw.text(
            (margin + c * cell + cell / 2, margin + height * cell + 8),
            columns[c],
            fill="black",
            font=font,
            anchor="mm",
        )
    return image


def _examples(evaluated, triplets: TripletDataset, out: Path, split: str, model: str) -> list:  # noqa: ANN001
    """Pairwise similarity of a few tier-0 triplets with their extra positives (paper Fig. 7)."""
    examples = []
    pictures = []
    for group in example_groups(evaluated, triplets):
        labels = ["A", *(f"P{k}" for k in range(1, len(group) - 1)), "N"]
        matrix = similarity_of(evaluated, group)
        examples.append({"ids": group, "labels": labels, "similarity": matrix.round(4).tolist()})
        pictures.append(draw_matrix(matrix, labels, labels, f"{model}: {group[0]}"))
    if pictures:
        sheet = Image.new(
            "RGB", (sum(p.width for p in pictures), max(p.height for p in pictures)), "white"
        )
        x = 0
        for picture in pictures:
            sheet.paste(picture, (x, 0))
            x += picture.width
        save_png(sheet, out / f"examples_{split}.png")
    return examples
