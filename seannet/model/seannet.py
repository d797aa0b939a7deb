"""SeanNet, the scene-embedding network (paper §IV)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
import torch
from torch import Tensor, nn
from torch.nn import functional as F
from torchvision.ops import roi_align

from seannet.data.batch import NUM_RELATIONS, SceneBatch
from seannet.errors import ModelError
from seannet.model.backbones import efficientnet_lite0_c4, resnet_c4
from seannet.model.config import VISUAL_FEATURES, ModelConfig
from seannet.model.layers import MultiPathwayGCN, ObjectEmbedding, SlotLayout
from seannet.model.layers.object_embedding import OBJECT_INPUTS
from sgdata.annotate.slots import NUM_SLOTS

__all__ = ["BRANCHES", "SeanNet"]

BRANCHES = ("both", "image", "graph")
_DEFAULT = ModelConfig()  # the architecture knobs' defaults have one home


class SeanNet(nn.Module):
    r"""SeanNet: an image and its scene graph → one scene embedding.

    From "SeanNet: Semantic Understanding Network for Localization Under Object Dynamics"
    (https://arxiv.org/abs/2110.02276), §IV, with the input contract of DESIGN §8:

    1. **Image branch.** A ResNet split at C4: backbone :math:`I \mapsto C_4` (1024 × 14 × 14
       for ResNet-50 at 224²), head (5th stage + pool) :math:`C_4 \mapsto v_I` (2048).
    2. **Object embeddings.** Each box is RoI-aligned on *its own view's* :math:`C_4`
       (``box_view`` is the RoI batch index; the authors' code pooled every box from the
       first image) to ``roi_size`` × ``roi_size``, and passed through the *same* head
       (shared weights) → :math:`x_v`; with :math:`x_b` (box PE) and :math:`x_w` (word
       vector): :math:`x_i = \mathrm{fcn}([x_v; x_b; x_w])` (512).
    3. **Scene-graph branch.** :math:`x_i` are scattered into :math:`X^{(0)}` (B × M × 512)
       at (view, slot), zero rows for empty slots, and a :class:`MultiPathwayGCN` on the
       on / in / proximity adjacencies gives :math:`g` (2048).
    4. **Fusion.** :math:`f = W_f [\mathrm{LN}(v_I); \mathrm{LN}(g)] + b_f` (2048). The
       paper's Fig. 2 merges the two 2048-d vectors into one without saying how; we normalise
       each branch (LayerNorm) so neither drowns the other — without it a trained checkpoint's
       view-to-view variation came 4.1 from the image and 0.023 from the graph — then
       concatenate and apply one linear layer. No activation after it: the embedding takes
       either sign, so cosine similarity uses the whole sphere rather than one orthant.
    5. **Layout pathway** (not in the paper; ``layout_grid`` > 0, the default): the
       :class:`~seannet.model.layers.SlotLayout` vector of the scene graph's boxes, slot by slot
       (B × M·grid², count-sketched to B × ``layout_sketch``), joins the embedding as a
       second unit vector:
       :math:`[f / \|f\|;\; \lambda\, \ell / \|\ell\|]` with a learned
       :math:`\lambda` (initially 1), so the cosine similarity of two views is
       :math:`(S_f + \lambda^2 S_\ell) / (1 + \lambda^2)`. Without it the graph branch adds
       nothing measurable to the image (``docs/results.md``): the GCN pathways never learn how
       far the same objects' boxes moved, which is what ranks the triplets.

    ``visual_features`` picks how :math:`x_v` is computed: ``"c4_head"`` as the paper (RoIAlign
    on C4, then the head on every crop: ~55 % of a CPU step), or ``"c5"`` (RoIAlign on the
    head's 5th-stage map, computed once per image for the image branch anyway, then averaged:
    the same features at the box, without a head pass per object). ``branches`` and
    ``object_inputs`` switch parts off for ablations (``"image"``: no scene graph at all;
    ``"graph"``: no image vector in the fusion); ``layout_grid=0`` leaves the paper's branch.

    Dropout (0.2) is used in the GCN only, as in the paper (§V-B).

    Args:
        word_vectors: :math:`(C, D_w)` class word vectors, row c for class id c (catalog
            order); fixed, not trained.
        depth: ResNet depth, 18, 34 or 50 (default 50). C4/head widths: 256/512 for 18/34,
            1024/2048 for 50.
        num_slots: M, GCN node slots (default 256).
        roi_size: RoIAlign output size (default 14, as the paper; 7 halves a CPU preset's cost).
        box_dim_per_coord: PE channels per box corner coordinate (default 64).
        object_dims: object fcn widths (default (1024, 512)).
        gcn_dims: pathway widths after the object width (default (256, 64, 8)).
        graph_hidden_dim: hidden width of the GCN's fcn (default 4096).
        embed_dim: width of the graph and scene embeddings (default 2048).
        dropout: GCN dropout (default 0.2).
        pretrained: a local torchvision ResNet state_dict for the backbone and head.
        pretrained_sha256: its expected SHA-256 (default: torchvision's known weights).
        visual_features: ``"c4_head"`` (default, as the paper) or ``"c5"``, see above.
        branches: ``"both"`` (default), ``"image"`` or ``"graph"``.
        object_inputs: the parts of :math:`x_i` (default ``("visual", "box", "word")``).
        backbone: ``"resnet"`` (default, of ``depth``) or ``"efficientnet_lite0"`` (split at
            stride 16 like C4; ``pretrained="imagenet-lite0"`` loads its ImageNet weights
            from the optional ``lite`` extra).
        layout_grid: cells per side of the layout pathway (default 32; 0: no layout pathway).
        layout_weights: :math:`(C,)` its starting class weights (default 1 each).
        layout_sketch: its count-sketch width (default 16,384; 0: M · layout_grid² wide).

    Shapes:
        - **batch**: a :class:`~seannet.data.batch.SceneBatch` with B views, K boxes, M slots
        - **output**: :math:`(B, \text{out\_dim})`: ``embed_dim``, plus the layout pathway's
          ``layout_sketch`` (or M · layout_grid² unsketched)
    """

    def __init__(
        self,
        word_vectors: Tensor | np.ndarray,
        *,
        depth: int = _DEFAULT.depth,
        num_slots: int = NUM_SLOTS,
        roi_size: int = _DEFAULT.roi_size,
        box_dim_per_coord: int = 64,
        object_dims: Sequence[int] = (1024, 512),
        gcn_dims: Sequence[int] = (256, 64, 8),
        graph_hidden_dim: int = 4096,
        embed_dim: int = _DEFAULT.embed_dim,
        dropout: float = _DEFAULT.dropout,
        pretrained: Path | None = None,
        pretrained_sha256: str | None = None,
        visual_features: str = _DEFAULT.visual_features,
        branches: str = "both",
        object_inputs: Sequence[str] = OBJECT_INPUTS,
        backbone: str = _DEFAULT.backbone,
        layout_grid: int = _DEFAULT.layout_grid,
        layout_weights: Tensor | None = None,
        layout_sketch: int = _DEFAULT.layout_sketch,
    ) -> None:
        super().__init__()
        if layout_grid < 0:
            raise ModelError(f"layout_grid={layout_grid}; expected 0 (off) or a positive integer")
        if visual_features not in VISUAL_FEATURES:
            raise ModelError(
                f"visual_features={visual_features!r}; expected one of {VISUAL_FEATURES}"
            )
        if branches not in BRANCHES:
            raise ModelError(f"branches={branches!r}; expected one of {BRANCHES}")
        if roi_size <= 0:
            raise ModelError(f"roi_size={roi_size}; expected a positive integer")
        if embed_dim <= 0:
            raise ModelError(f"embed_dim={embed_dim}; expected a positive integer")
        if backbone == "efficientnet_lite0":
            split = efficientnet_lite0_c4(pretrained=pretrained, sha256=pretrained_sha256)
        elif backbone == "resnet":
            split = resnet_c4(depth, pretrained=pretrained, sha256=pretrained_sha256)
        else:
            raise ModelError(f"backbone={backbone!r}; expected 'resnet' or 'efficientnet_lite0'")
        self.depth = depth
        self.num_slots = num_slots
        self.roi_size = roi_size
        self.embed_dim = embed_dim
        self.visual_features = visual_features
        self.branches = branches
        self.c4_stride = split.stride
        self.backbone = split.backbone
        self.head = split.head  # shared by the image branch and every object
        self.objects = ObjectEmbedding(
            torch.as_tensor(word_vectors, dtype=torch.float32),
            split.head_dim,
            box_dim_per_coord=box_dim_per_coord,
            hidden_dims=object_dims,
            inputs=object_inputs,
        )
        self.gcn = MultiPathwayGCN(
            num_slots,
            (self.objects.out_dim, *gcn_dims),
            num_relations=NUM_RELATIONS,
            hidden_dim=graph_hidden_dim,
            out_dim=embed_dim,
            dropout=dropout,
        )
        self.image_norm = nn.LayerNorm(split.head_dim)
        self.graph_norm = nn.LayerNorm(embed_dim)
        widths = {"both": split.head_dim + embed_dim, "image": split.head_dim, "graph": embed_dim}
        self.fusion = nn.Linear(widths[branches], embed_dim)
        self.layout: SlotLayout | None = None
        self.out_dim = embed_dim
        if layout_grid and branches != "image":
            self.layout = SlotLayout(
                num_slots,
                self.num_classes,
                grid=layout_grid,
                initial_weights=layout_weights,
                sketch_dim=layout_sketch,
            )
            self.layout_weight = nn.Parameter(torch.ones(()))  # lambda
            self.out_dim += self.layout.out_dim

    @property
    def num_classes(self) -> int:
        return self.objects.num_classes

    def object_features(self, c4: Tensor, batch: SceneBatch, c5: Tensor | None = None) -> Tensor:
        """:math:`x_i` of every box, RoI-aligned on its own view's feature map. (K, 512).

        ``c5`` is the 5th-stage map of ``c4`` when the caller has it (computed otherwise)."""
        if "visual" not in self.objects.inputs:
            visual = c4.new_zeros(batch.boxes.shape[0], 0)
        elif self.visual_features == "c4_head":
            visual = self.head(self._roi(c4, batch, self.roi_size, self.c4_stride))
        else:  # the 5th-stage map is half C4's resolution: half the RoI grid
            c5 = self.head[0](c4) if c5 is None else c5
            size = max(1, self.roi_size // 2)
            visual = self._roi(c5, batch, size, 2 * self.c4_stride).mean(dim=(2, 3))
        return self.objects(visual, batch.boxes, batch.class_ids)

    @staticmethod
    def _roi(features: Tensor, batch: SceneBatch, size: int, stride: int) -> Tensor:
        rois = torch.cat(
            (batch.box_view.to(features.dtype).unsqueeze(1), batch.boxes.to(features.dtype)), 1
        )
        # aligned=True: box coordinates are continuous pixel edges (u2 exclusive = right edge
        # of the last pixel), so the half-pixel shift maps them onto sample centres exactly
        return roi_align(
            features,
            rois,
            output_size=size,
            spatial_scale=1.0 / stride,
            sampling_ratio=-1,
            aligned=True,
        )

    def node_features(self, x: Tensor, batch: SceneBatch) -> Tensor:
        """Scatter object embeddings to :math:`X^{(0)}` (B, M, F) at (view, slot)."""
        x0 = x.new_zeros(batch.num_views, self.num_slots, x.shape[1])
        return x0.index_put((batch.box_view, batch.slots), x)

    def embed(self, batch: SceneBatch) -> Tensor:
        """Scene embeddings (B, embed_dim) of a batch.

        A compact batch (the loaders') is prepared first (:meth:`SceneBatch.prepare`: images
        normalised; a sparse adjacency stays sparse, the GCN reads its edges) where it is, so
        on the model's device after ``batch.to(device)``.

        Raises:
            DataError: the batch's indices are out of range or two boxes share a node.
            ModelError: the batch's M differs from the model's.
        """
        if batch.num_slots != self.num_slots:
            raise ModelError(
                f"batch has M = {batch.num_slots} slots, the model {self.num_slots}; build the "
                f"model with num_slots={batch.num_slots} or fix the dataset's slot table"
            )
        batch = batch.prepare(dense_adjacency=False)
        batch.validate(num_classes=self.num_classes)
        c4 = self.backbone(batch.images)
        c5 = self.head[0](c4)  # the 5th stage, shared by the image vector and x_v
        parts = []
        if self.branches != "graph":
            parts.append(self.image_norm(self.head[1:](c5)))
        if self.branches != "image":
            if batch.boxes.shape[0]:
                x = self.object_features(c4, batch, c5)
            else:
                x = c4.new_zeros(0, self.objects.out_dim)
            graph = self.gcn.forward_nodes(
                x,
                batch.box_view,
                batch.slots,
                batch.adjacency.to(c4.dtype),
                num_views=batch.num_views,
            )
            parts.append(self.graph_norm(graph))
        fused = self.fusion(torch.cat(parts, dim=1))
        if self.layout is None:
            return fused
        height, width = batch.images.shape[-2:]
        layout = self.layout(
            batch.boxes,
            batch.box_view,
            batch.slots,
            batch.class_ids,
            num_views=batch.num_views,
            height=height,
            width=width,
        )
        return torch.cat(
            (F.normalize(fused, dim=1), self.layout_weight * F.normalize(layout, dim=1)), dim=1
        )

    def forward(self, batch: SceneBatch) -> Tensor:
        return self.embed(batch)
