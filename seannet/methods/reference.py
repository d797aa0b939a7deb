"""Reference methods, registered by name: a user's method meets real competition.

- ``tiny-image``: the view downsampled to 16 x 16 pixels, mean removed (Torralba et al.'s
  "tiny images"; no learning, the floor any method should clear).
- ``lite0-gem``: frozen ImageNet EfficientNet-Lite0, its stride-32 map GeM-pooled (p = 3;
  Radenović et al., https://arxiv.org/abs/1711.02512): a VPR-style descriptor with no training
  (the ``lite`` extra).
- ``lite0-gem-head``: the same descriptor with a linear head (1280 -> 256) trained on the
  train triplets with the triplet loss (the classical VPR recipe; lr chosen on val).
- ``lite0-netvlad``: the frozen Lite0 map (1280 channels) reduced to 64 by a 1 x 1 conv and
  pooled by NetVLAD (Arandjelović et al., https://arxiv.org/abs/1511.07247) with 16 clusters
  (1,024-d), both trained on the train triplets the same way.
- ``boxes-overlap``: the visible objects' boxes slot by slot, scored by their mean IoU.
- ``boxes-kernel``: the same boxes, scored by a slot kernel learned on the train triplets.
"""

from __future__ import annotations

import torch
import torch.nn.functional as F
from torch import Tensor, nn

from seannet.evaluation.scene_term import BOX_KERNEL, SceneTerm
from seannet.methods.boxes import box_scores, box_vectors, row_triplets, vector_boxes
from seannet.methods.views import Budget, SplitData, Views
from seannet.model.loss import TripletLoss
from seannet.weights import IMAGE_SIZE, LITE0, LITE0_WEIGHTS

__all__ = [
    "BoxKernelMethod",
    "BoxOverlap",
    "Lite0GeM",
    "Lite0GeMHead",
    "Lite0NetVLAD",
    "NetVLAD",
    "TinyImage",
]


class TinyImage:
    """The view as 16 x 16 x 3 pixels, mean removed, compared by cosine."""

    image_size = 64  # read small: the 16 x 16 pool does not need more
    side = 16

    def embed(self, views: Views) -> Tensor:
        x = F.adaptive_avg_pool2d(views.images.float() / 255.0, self.side).flatten(1)
        return x - x.mean(dim=1, keepdim=True)


class Lite0GeM:
    """Frozen ImageNet EfficientNet-Lite0, GeM pooling of its last map (1280-d)."""

    network = LITE0
    image_size = IMAGE_SIZE
    p = 3.0  # GeM's power: 1 is average pooling, infinity max pooling

    def __init__(self) -> None:
        from seannet.model.backbones import efficientnet_lite0_c4

        split = efficientnet_lite0_c4(pretrained=LITE0_WEIGHTS)
        self.trunk = nn.Sequential(split.backbone, split.head[0]).eval()

    @torch.no_grad()
    def features(self, views: Views) -> Tensor:
        """(N, 1280, h, w) the frozen stride-32 map."""
        return self.trunk(views.normalised)

    @torch.no_grad()
    def embed(self, views: Views) -> Tensor:
        features = self.features(views).clamp_min(1e-6)
        return features.pow(self.p).mean(dim=(2, 3)).pow(1.0 / self.p)


class Lite0GeMHead(Lite0GeM):
    """Frozen Lite0 + GeM, then a linear head trained on the train triplets (triplet loss,
    margin 0.1, SGD with momentum; the lr of ``budget.lrs`` best on val, default 0.01 / 0.1)."""

    trainable = True
    dim = 256  # the head's output width
    epochs = 30  # over the train triplets, unless the budget says otherwise
    batch = 64  # triplets per step

    def __init__(self) -> None:
        super().__init__()
        self.head: nn.Module = nn.Identity()
        self.choices: dict[str, object] = {}
        self.inputs = 0  # the frozen features' channels, the head's input

    # The frozen inputs of the last dataset's splits, shared by every seed of a benchmark:
    # they depend on the dataset and the ImageNet trunk only, not on the seed.
    _frozen: dict[tuple[str, ...], Tensor] = {}

    def _frozen_inputs(self, split: SplitData) -> Tensor:
        """:meth:`_pooled` of ``split``, computed once per dataset (its manifest's sha256)."""
        dataset = (type(self).__name__, str(split.dataset.root.resolve()),
                   split.dataset.manifest_sha256)  # fmt: skip
        key = (*dataset, split.name)
        if key not in Lite0GeMHead._frozen:
            if any(k[:3] != dataset for k in Lite0GeMHead._frozen):
                Lite0GeMHead._frozen.clear()  # keep one dataset's inputs: they can be GBs
            Lite0GeMHead._frozen[key] = self._pooled(split)
        return Lite0GeMHead._frozen[key]

    def _pooled(self, split: SplitData) -> Tensor:
        """The frozen inputs of the head, every view of ``split`` in order."""
        return F.normalize(torch.cat([Lite0GeM.embed(self, v) for v in split.views()]), dim=1)

    def _new_head(self, inputs: Tensor) -> nn.Module:
        return nn.Linear(inputs.shape[1], self.dim)

    def _accuracy(self, head: nn.Module, features: Tensor, triplets: Tensor) -> float:
        with torch.no_grad():
            a, p, n = (F.normalize(head(features[triplets[:, k]]), dim=1) for k in range(3))
            return float(((a * p).sum(1) > (a * n).sum(1)).float().mean())

    def fit(self, train: SplitData, val: SplitData, budget: Budget) -> None:
        train_x, val_x = self._frozen_inputs(train), self._frozen_inputs(val)
        train_t, val_t = torch.from_numpy(train.triplets), torch.from_numpy(val.triplets)
        self.inputs = int(train_x.shape[1])
        loss_fn = TripletLoss(margin=0.1)
        by_lr, best = {}, None
        for lr in budget.lrs or (0.01, 0.1):
            order = torch.Generator().manual_seed(budget.seed)
            torch.manual_seed(budget.seed)
            head = self._new_head(train_x)
            optimizer = torch.optim.SGD(head.parameters(), lr=lr, momentum=0.9)
            for _ in range(budget.epochs or self.epochs):
                for rows in torch.randperm(len(train_t), generator=order).split(self.batch):
                    a, p, n = (head(train_x[train_t[rows, k]]) for k in range(3))
                    loss = loss_fn(a, p, n)
                    optimizer.zero_grad()
                    loss.backward()
                    optimizer.step()
            by_lr[f"{lr:g}"] = self._accuracy(head, val_x, val_t)
            if best is None or (by_lr[f"{lr:g}"], -lr) > best[:2]:
                best = (by_lr[f"{lr:g}"], -lr, head)
        assert best is not None
        self.head = best[2].eval()
        self.choices = {"lr": -best[1], "val_accuracy_by_lr": by_lr}

    def state_dict(self) -> dict:
        """The trained head's weights and the choices on val (the trunk is ImageNet's)."""
        head = {k: v.detach().cpu() for k, v in self.head.state_dict().items()}
        return {"inputs": self.inputs, "head": head, "choices": self.choices}

    def load_state_dict(self, state: dict) -> None:
        self.inputs = int(state["inputs"])
        self.head = self._new_head(torch.zeros(1, self.inputs))
        self.head.load_state_dict(state["head"])
        self.head.eval()
        self.choices = dict(state["choices"])

    @torch.no_grad()
    def embed(self, views: Views) -> Tensor:
        return F.normalize(self.head(F.normalize(super().embed(views), dim=1)), dim=1)


class NetVLAD(nn.Module):
    """NetVLAD pooling (Arandjelović et al. 2016) after a 1 x 1 channel reduction: soft
    assignment of each location to ``clusters`` centroids, residuals summed per cluster,
    intra-normalised, flattened and L2-normalised (``clusters`` x ``reduced`` wide)."""

    def __init__(self, channels: int, clusters: int = 16, reduced: int = 64) -> None:
        super().__init__()
        self.reduce = nn.Conv2d(channels, reduced, kernel_size=1)
        self.assign = nn.Conv2d(reduced, clusters, kernel_size=1)
        self.centroids = nn.Parameter(0.1 * torch.randn(clusters, reduced))

    def forward(self, maps: Tensor) -> Tensor:
        x = F.normalize(self.reduce(maps), dim=1)
        weights = F.softmax(self.assign(x), dim=1).flatten(2)  # (N, K, L)
        x = x.flatten(2)  # (N, D, L)
        residual = torch.einsum("nkl,ndl->nkd", weights, x)
        residual = residual - weights.sum(2).unsqueeze(2) * self.centroids.unsqueeze(0)
        return F.normalize(F.normalize(residual, dim=2).flatten(1), dim=1)


class Lite0NetVLAD(Lite0GeMHead):
    """Frozen Lite0, then NetVLAD (64 channels, 16 clusters: 1,024-d) trained on the train
    triplets like ``lite0-gem-head``'s head (triplet loss, the lr of ``budget.lrs`` best on val).
    The frozen maps of the train and val views are kept in memory while it trains."""

    clusters = 16
    reduced = 64

    def _pooled(self, split: SplitData) -> Tensor:
        return torch.cat([self.features(v) for v in split.views()])

    def _new_head(self, inputs: Tensor) -> nn.Module:
        return NetVLAD(inputs.shape[1], self.clusters, self.reduced)

    @torch.no_grad()
    def embed(self, views: Views) -> Tensor:
        return self.head(self.features(views))


class BoxOverlap:
    """Boxes only: each slot's box (image-relative), scored by the mean IoU over the slots
    present in either view (the scene term ``+boxes`` alone:
    :class:`~seannet.evaluation.scene_term.SceneTerm`)."""

    uses_boxes = True
    image_size = 64  # the pixels are not read; the boxes are scaled with them
    term = "+boxes"

    def __init__(self) -> None:
        self.scene = SceneTerm.from_spec(self.term)

    def embed(self, views: Views) -> Tensor:
        return box_vectors(views.slot_boxes())

    def similarity(self, a: Tensor, b: Tensor) -> Tensor:
        return box_scores(a, b, self.scene).float()  # float32, as the cards were computed


class BoxKernelMethod(BoxOverlap):
    """Boxes only, scored by a per-slot weighted IoU learned on the train triplets
    (the scene term ``+box-kernel`` alone: :mod:`seannet.evaluation.box_kernel`)."""

    trainable = True
    term = BOX_KERNEL

    def fit(self, train: SplitData, val: SplitData, budget: Budget) -> None:
        torch.manual_seed(budget.seed)
        vectors = torch.cat([self.embed(v) for v in train.views()])
        self.scene = SceneTerm.from_spec(self.term)
        self.scene.fit(vector_boxes(vectors), row_triplets(train.triplets))

    def state_dict(self) -> dict:
        """The fitted kernel as tensors and plain data (a card directory's ``method.pt``)."""
        return {"scene": self.scene.state_dict()}

    def load_state_dict(self, state: dict) -> None:
        self.scene = SceneTerm.from_state(state["scene"])
