"""Reference methods, registered by name: a user's method meets real competition.

- ``tiny-image``: the view downsampled to 16 x 16 pixels, mean removed (Torralba et al.'s
  "tiny images"; no learning, the floor any method should clear).
- ``lite0-gem``: frozen ImageNet EfficientNet-Lite0, its stride-32 map GeM-pooled (p = 3;
  Radenović et al., https://arxiv.org/abs/1711.02512): a VPR-style descriptor with no training
  (the ``lite`` extra).
- ``lite0-gem-head``: the same descriptor with a linear head (1280 -> 256) trained on the
  train triplets with the triplet loss (the classical VPR recipe; lr chosen on val).
- ``boxes-overlap``: the visible objects' boxes slot by slot, scored by their mean IoU.
- ``boxes-kernel``: the same boxes, scored by a slot kernel learned on the train triplets.
"""

from __future__ import annotations

import torch
import torch.nn.functional as F
from torch import Tensor, nn

from seannet.evaluation.box_kernel import BoxKernel
from seannet.methods.boxes import box_scores, box_vectors, fit_kernel
from seannet.methods.registry import register_method
from seannet.methods.views import Budget, SplitData, Views
from seannet.model.loss import TripletLoss
from seannet.weights import LITE0, LITE0_WEIGHTS

__all__ = ["BoxKernelMethod", "BoxOverlap", "Lite0GeM", "Lite0GeMHead", "TinyImage"]


@register_method("tiny-image")
class TinyImage:
    """The view as 16 x 16 x 3 pixels, mean removed, compared by cosine."""

    image_size = 64  # read small: the 16 x 16 pool does not need more
    side = 16

    def embed(self, views: Views) -> Tensor:
        x = F.adaptive_avg_pool2d(views.images.float() / 255.0, self.side).flatten(1)
        return x - x.mean(dim=1, keepdim=True)


@register_method("lite0-gem")
class Lite0GeM:
    """Frozen ImageNet EfficientNet-Lite0, GeM pooling of its last map (1280-d)."""

    network = LITE0
    image_size = 224
    p = 3.0  # GeM's power: 1 is average pooling, infinity max pooling

    def __init__(self) -> None:
        from seannet.model.backbones import efficientnet_lite0_c4

        split = efficientnet_lite0_c4(pretrained=LITE0_WEIGHTS)
        self.trunk = nn.Sequential(split.backbone, split.head[0]).eval()

    @torch.no_grad()
    def embed(self, views: Views) -> Tensor:
        features = self.trunk(views.normalised).clamp_min(1e-6)
        return features.pow(self.p).mean(dim=(2, 3)).pow(1.0 / self.p)


@register_method("lite0-gem-head")
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

    def _pooled(self, split: SplitData) -> Tensor:
        return F.normalize(torch.cat([Lite0GeM.embed(self, v) for v in split.views()]), dim=1)

    def _accuracy(self, head: nn.Module, features: Tensor, triplets: Tensor) -> float:
        with torch.no_grad():
            a, p, n = (F.normalize(head(features[triplets[:, k]]), dim=1) for k in range(3))
            return float(((a * p).sum(1) > (a * n).sum(1)).float().mean())

    def fit(self, train: SplitData, val: SplitData, budget: Budget) -> None:
        train_x, val_x = self._pooled(train), self._pooled(val)
        train_t, val_t = torch.from_numpy(train.triplets), torch.from_numpy(val.triplets)
        loss_fn = TripletLoss(margin=0.1)
        by_lr, best = {}, None
        for lr in budget.lrs or (0.01, 0.1):
            order = torch.Generator().manual_seed(budget.seed)
            torch.manual_seed(budget.seed)
            head = nn.Linear(train_x.shape[1], self.dim)
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

    @torch.no_grad()
    def embed(self, views: Views) -> Tensor:
        return F.normalize(self.head(F.normalize(super().embed(views), dim=1)), dim=1)


@register_method("boxes-overlap")
class BoxOverlap:
    """Boxes only: each slot's box (image-relative), scored by the mean IoU over the slots
    present in either view (:mod:`seannet.evaluation.box_overlap`)."""

    uses_boxes = True
    image_size = 64  # the pixels are not read; the boxes are scaled with them
    kernel: BoxKernel | None = None

    def embed(self, views: Views) -> Tensor:
        return box_vectors(views.slot_boxes())

    def similarity(self, a: Tensor, b: Tensor) -> Tensor:
        return box_scores(a, b, self.kernel)


@register_method("boxes-kernel")
class BoxKernelMethod(BoxOverlap):
    """Boxes only, scored by a per-slot weighted IoU learned on the train triplets
    (:mod:`seannet.evaluation.box_kernel`)."""

    trainable = True

    def fit(self, train: SplitData, val: SplitData, budget: Budget) -> None:
        torch.manual_seed(budget.seed)
        vectors = torch.cat([self.embed(v) for v in train.views()])
        self.kernel, _ = fit_kernel(vectors, train.triplets)
