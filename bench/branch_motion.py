"""How far each part of SeanNet moves in training, relative to its size (issue: an inert graph
branch moved by 0 to 4e-5 while the backbone moved by 1.6e-2).

    python bench/branch_motion.py DATA [--preset cpu] [--batches 8] [--lr-scale 1]

Trains SeanNet for a few batches from its seeded initial weights and prints, per part, the
relative change ||w - w0|| / ||w0||, and the part of the fused embedding's view-to-view
variation that comes from each branch (the spread of LayerNorm(image) and LayerNorm(graph)
through the fusion's two weight blocks).
"""

from __future__ import annotations

import argparse
from itertools import islice
from pathlib import Path

import torch
from torch.utils.data import DataLoader

from seannet.data.datasets import ImageTransform, TripletDataset, collate_triplets
from seannet.model.loss import TripletLoss
from seannet.seeds import init_seed
from seannet.training.config import DEFAULT_PRESET, preset
from seannet.training.loop import train_one_epoch, triplet_step
from seannet.training.runs import build_for_dataset
from seannet.training.train import param_groups

PARTS = {
    "backbone (C4)": "backbone.",
    "head (5th stage)": "head.",
    "object fcn": "objects.",
    "GCN on": "gcn.pathways.0.",
    "GCN in": "gcn.pathways.1.",
    "GCN proximity": "gcn.pathways.2.",
    "GCN fc": "gcn.fc.",
    "fusion": "fusion.",
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("data", type=Path)
    parser.add_argument("--preset", default=DEFAULT_PRESET)
    parser.add_argument("--batches", type=int, default=8)
    parser.add_argument("--lr-scale", type=float, default=None)
    args = parser.parse_args()
    config = preset(args.preset)
    if args.lr_scale is not None:
        config = config.replace(new_layers_lr_scale=args.lr_scale)
    torch.manual_seed(init_seed(config.seed))
    model = build_for_dataset(config, args.data)
    start = {k: v.detach().clone() for k, v in model.named_parameters()}
    optimizer = torch.optim.SGD(param_groups(model, config), lr=config.lr, momentum=config.momentum)
    loss_fn = TripletLoss(margin=config.margin)
    data = TripletDataset(
        args.data, "train", transform=ImageTransform(size=config.model.image_size)
    )
    loader = DataLoader(
        data, batch_size=config.batch_size, shuffle=True, collate_fn=collate_triplets
    )
    step = triplet_step(model, loss_fn, torch.device("cpu"))  # the step every run trains by
    train_one_epoch(model, islice(loader, args.batches), step, optimizer)
    print(f"{'part':<18} {'relative change':>16}")
    for part, prefix in PARTS.items():
        now = dict(model.named_parameters())
        keys = [k for k in start if k.startswith(prefix)]
        before = torch.cat([start[k].flatten() for k in keys])
        after = torch.cat([now[k].detach().flatten() for k in keys])
        print(f"{part:<18} {float((after - before).norm() / before.norm()):>16.2e}")
    model.eval()
    a, _, _, _ = next(iter(DataLoader(data, batch_size=16, collate_fn=collate_triplets)))
    a = a.prepare()  # float images and a dense adjacency, as SeanNet.embed sees them
    with torch.no_grad():
        c4 = model.backbone(a.images)
        c5 = model.head[0](c4)
        image = model.image_norm(model.head[1:](c5))
        x = model.object_features(c4, a, c5)
        graph = model.graph_norm(model.gcn(model.node_features(x, a), a.adjacency))
        w = model.fusion.weight
        from_image = (image @ w[:, : image.shape[1]].T).std(dim=0).mean()
        from_graph = (graph @ w[:, image.shape[1] :].T).std(dim=0).mean()
    share = float(from_graph / (from_image + from_graph))
    print(
        f"fused variation from image {float(from_image):.3f}, from graph "
        f"{float(from_graph):.3f} (graph share {100 * share:.1f} %)"
    )


if __name__ == "__main__":
    main()
