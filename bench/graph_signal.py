"""How much of a triplet's answer the scene graph's boxes hold, with no learning at all.

    python bench/graph_signal.py DATA [--split test] [--run RUN_DIR]

For each triplet, a hand-made graph similarity of two views: the mean, over the objects of
the chosen dynamics present in either view, of the IoU of the same object's boxes (0 where it
is in one view only). Prints its triplet accuracy per tier for static, static + low and all
objects. With ``--run``, also that run's image similarity (its ``best.pt``) and the sum
``S_image + lambda * S_graph`` with lambda chosen on the validation split: how much the boxes
add to what the network learned (docs/results.md: the reason for SeanNet's layout pathway).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import torch

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import seannet  # noqa: E402,F401  (imports torch's compiler stack first: see tests/conftest.py)
from seannet.evaluation.metrics import embed_split  # noqa: E402
from seannet.training.config import TrainConfig  # noqa: E402
from seannet.training.runs import (  # noqa: E402
    build_for_dataset,
    device_for_run,
    load_checkpoint,  # noqa: E402
)

KEEP = {"static": {"static"}, "static+low": {"static", "low"}, "all": {"static", "low", "high"}}
LAMBDAS = (0.1, 0.2, 0.5, 1.0, 2.0, 5.0)

Boxes = dict[int, tuple[np.ndarray, str]]  # slot -> (box, dynamics)


def read_views(data: Path, split: str) -> dict[str, Boxes]:
    views: dict[str, Boxes] = {}
    for shard in sorted((data / "observations" / split).glob("*.parquet")):
        for row in pq.read_table(shard, columns=["obs_id", "objects"]).to_pylist():
            views[row["obs_id"]] = {
                o["slot"]: (np.asarray(o["box2d"], float), o["dynamics"]) for o in row["objects"]
            }
    return views


def iou(a: np.ndarray, b: np.ndarray) -> float:
    w = max(0.0, min(a[2], b[2]) - max(a[0], b[0]))
    h = max(0.0, min(a[3], b[3]) - max(a[1], b[1]))
    union = (a[2] - a[0]) * (a[3] - a[1]) + (b[2] - b[0]) * (b[3] - b[1]) - w * h
    return w * h / union if union > 0 else 0.0


def graph_similarity(a: Boxes, b: Boxes, keep: set[str]) -> float:
    sa = {s for s, (_, d) in a.items() if d in keep}
    sb = {s for s, (_, d) in b.items() if d in keep}
    both = sa | sb
    return sum(iou(a[s][0], b[s][0]) for s in sa & sb) / len(both) if both else 0.0


def accuracy(pos: np.ndarray, neg: np.ndarray, tiers: np.ndarray) -> str:
    # ties count half: a similarity that cannot tell two views apart is a coin flip
    right = (pos > neg) + 0.5 * (pos == neg)
    per_tier = " ".join(f"{100 * right[tiers == t].mean():5.1f}" for t in range(5))
    return f"{100 * right.mean():5.1f}   tiers 0-4: {per_tier}"


def image_similarity(run: Path, data: Path, split: str, trip: list[dict]) -> tuple:
    state = load_checkpoint(run / "best.pt")
    config = TrainConfig.from_dict(state["config"])
    device = device_for_run()
    model = build_for_dataset(config, data).to(device)
    model.load_state_dict(state["model"])
    with torch.no_grad():
        emb = embed_split(model, config, data, split, device)
    row = {o: i for i, o in enumerate(emb.obs_ids)}
    v = emb.vectors
    pos = np.array([v[row[t["anchor"]]] @ v[row[t["positive"]]] for t in trip])
    neg = np.array([v[row[t["anchor"]]] @ v[row[t["negative"]]] for t in trip])
    return pos, neg


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("data", type=Path)
    parser.add_argument("--split", default="test")
    parser.add_argument("--run", type=Path, help="a run directory: add its image similarity")
    args = parser.parse_args()
    splits = {"val": None, args.split: None} if args.run else {args.split: None}
    for split in splits:
        views = read_views(args.data, split)
        trip = pq.read_table(args.data / "triplets" / f"{split}.parquet").to_pylist()
        tiers = np.array([t["tier"] for t in trip])
        graph = {}
        for name, keep in KEEP.items():
            pos = np.array(
                [graph_similarity(views[t["anchor"]], views[t["positive"]], keep) for t in trip]
            )
            neg = np.array(
                [graph_similarity(views[t["anchor"]], views[t["negative"]], keep) for t in trip]
            )
            graph[name] = (pos, neg)
        splits[split] = (
            graph,
            tiers,
            image_similarity(args.run, args.data, split, trip) if args.run else None,
        )
    graph, tiers, image = splits[args.split]
    print(f"{args.data} {args.split}: {len(tiers)} triplets, triplet accuracy %")
    for name, (pos, neg) in graph.items():
        print(f"  boxes, {name:10s} {accuracy(pos, neg, tiers)}")
    if image is None:
        return
    print(f"  image similarity   {accuracy(*image, tiers)}")
    val_graph, _, val_image = splits["val"]
    for name in KEEP:
        lam = max(LAMBDAS, key=lambda x: _right(val_image, val_graph[name], x))
        pos = image[0] + lam * graph[name][0]
        neg = image[1] + lam * graph[name][1]
        print(f"  image + {lam:g} x boxes ({name}, lambda on val) {accuracy(pos, neg, tiers)}")


def _right(image: tuple, graph: tuple, lam: float) -> float:
    return float(np.mean(image[0] + lam * graph[0] > image[1] + lam * graph[1]))


if __name__ == "__main__":
    main()
