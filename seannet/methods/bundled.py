"""The bundled networks as methods: a model spec (``seannet``, ``resnet18+boxes``,
``seannet@lite0+imagenet``, ...) trained with the project's trainer, through the same
interface as any user's method."""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np
import torch
import torch.nn.functional as F
from torch import Tensor

from seannet.evaluation.compare import model_spec
from seannet.evaluation.scene_term import SceneTerm
from seannet.methods.boxes import box_scores, box_vectors, row_triplets, vector_boxes
from seannet.methods.views import Budget, SplitData, Views
from seannet.model.specs import ResolvedSpec
from seannet.training.config import DEFAULT_PRESET
from seannet.training.config import preset as load_preset
from seannet.training.runs import LAST, restore_run
from seannet.training.train import train
from sgdata.dataset import Dataset

__all__ = ["NetworkMethod", "embed_split_views", "pair_scores"]


def embed_split_views(method: object, split: SplitData, batch_size: int = 32) -> Tensor:
    """(N, D) the method's vectors of every view of ``split``, in order."""
    parts = [method.embed(v).detach().cpu() for v in split.views(batch_size)]  # type: ignore[attr-defined]
    return torch.cat(parts) if parts else torch.zeros(0)


def pair_scores(method: object, vectors: Tensor, triplets: np.ndarray) -> tuple[Tensor, Tensor]:
    """(S(A, P), S(A, N)) of triplets with the method's similarity (default cosine)."""
    a, p, n = (vectors[torch.from_numpy(triplets[:, k])] for k in range(3))
    score = getattr(method, "similarity", None)
    if score is None:
        a, p, n = (F.normalize(x.float(), dim=1) for x in (a, p, n))
        return (a * p).sum(1), (a * n).sum(1)
    return score(a, p), score(a, n)


class NetworkMethod:
    """A bundled network named by a model spec, trained by :func:`seannet.training.train` in
    ``fit`` (the lr chosen on val among ``budget.lrs``; ``+boxes`` / ``+box-kernel``: the
    :class:`~seannet.evaluation.scene_term.SceneTerm` ``seannet eval`` uses, its kernel fit on
    train and lambda chosen on val). Its vectors are the unit embedding, followed for a scene
    term by every slot's box (the map holds them too: they count in its bytes per entry)."""

    trainable = True

    def __init__(self, spec: ResolvedSpec, *, preset: str = DEFAULT_PRESET) -> None:
        if not isinstance(spec, ResolvedSpec):  # parsed once, where the name came in
            raise TypeError(
                f"NetworkMethod takes a ResolvedSpec (seannet.model.specs.parse_spec), got "
                f"{type(spec).__name__}"
            )
        self.parsed = spec
        self.name = spec.spec
        self.uses_boxes = spec.uses_boxes
        self._configure(preset)
        self.model: torch.nn.Module | None = None
        self.device = torch.device("cpu")
        self.scene = SceneTerm.from_spec(self.parsed.scene)
        self.choices: dict[str, object] = {}
        self._dim = 0

    def _configure(self, preset: str, **changes: object) -> None:
        self.config = model_spec(self.parsed, load_preset(preset).replace(**changes)).config
        self.image_size = self.config.model.image_size
        self.network = self.config.model.image_family

    def fit(self, train_split: SplitData, val: SplitData, budget: Budget) -> None:
        """Train at each lr of the budget (default: the preset's), keep the best on val."""
        changes: dict[str, object] = {"seed": budget.seed}
        if budget.epochs:
            changes["epochs"] = budget.epochs
        if budget.batches:
            changes["max_train_batches"] = budget.batches
        self._configure(budget.preset, **changes)
        spec = model_spec(self.parsed, self.config)
        work = budget.work or Path(tempfile.mkdtemp(prefix="seannet-method-"))
        self.scene = SceneTerm.from_spec(self.parsed.scene)  # the lr is chosen on S alone
        by_lr: dict[str, float] = {}
        best: tuple[float, float, Path] | None = None
        for lr in budget.lrs or (self.config.lr,):
            run = work / spec.trained / f"lr{lr:g}" / f"seed{budget.seed}"
            config = self.config.replace(lr=lr)
            train(config, train_split.dataset, run, resume=(run / LAST).exists(),
                  pretrained=spec.pretrained)  # fmt: skip
            self._restore(run, train_split.dataset)
            vectors = embed_split_views(self, val)
            s_ap, s_an = pair_scores(self, vectors, val.triplets)
            by_lr[f"{lr:g}"] = float((s_ap > s_an).float().mean())
            if best is None or (by_lr[f"{lr:g}"], -lr) > best[:2]:
                best = (by_lr[f"{lr:g}"], -lr, run)
        assert best is not None
        self._restore(best[2], train_split.dataset)
        self.choices = {"lr": -best[1], "val_accuracy_by_lr": by_lr, "run": str(best[2])}
        if self.scene.term:
            self.fit_scene(train_split, val)
            self.choices.update(self.scene.choices)

    def _restore(self, run: Path, dataset: Dataset) -> None:
        restored = restore_run(run, dataset)
        self.model, self.device = restored.model, restored.device

    def fit_scene(self, train: SplitData, val: SplitData) -> None:
        """The scene term's choices for the network as it stands: ``+box-kernel``'s kernel on
        the train triplets' boxes, then lambda on the val triplets (``seannet eval``'s rule)."""
        self.scene = SceneTerm.from_spec(self.parsed.scene)
        if self.scene.learned:
            boxes = torch.cat([box_vectors(v.slot_boxes()) for v in train.views()])
            self.scene.fit(vector_boxes(boxes), row_triplets(train.triplets))
        vectors = embed_split_views(self, val)
        a, p, n = (vectors[torch.from_numpy(val.triplets[:, k]), : self._dim] for k in range(3))
        s_ap, s_an = (a * p).sum(1).double().numpy(), (a * n).sum(1).double().numpy()
        boxes = vector_boxes(vectors[:, self._dim :])
        self.scene.choose_weight(
            s_ap, s_an, *self.scene.triplet_scores(boxes, row_triplets(val.triplets))
        )

    @torch.no_grad()
    def embed(self, views: Views) -> Tensor:
        if self.model is None:
            raise RuntimeError(f"{self.name}: fit() first (a bundled network is trained)")
        unit = F.normalize(self.model.embed(views.batch.to(self.device)), dim=1).cpu()
        self._dim = unit.shape[1]  # where the boxes start (SeanNet's vector: fused + layout)
        if not self.parsed.scene:
            return unit
        return torch.cat([unit, box_vectors(views.slot_boxes())], dim=1)

    def similarity(self, a: Tensor, b: Tensor) -> Tensor:
        d = self._dim
        s = (a[:, :d] * b[:, :d]).sum(1)
        if not self.scene.weight:  # no scene term, or lambda 0 (or not chosen yet): S alone
            return s
        boxes = box_scores(a[:, d:], b[:, d:], self.scene)
        return self.scene.combine(s.double(), boxes, unit=True)  # stays in [-1, 1]

    def state_dict(self) -> dict:
        """The fitted network as tensors and plain data (what ``method.pt`` keeps): its config,
        the sizes its model was built with, the model's weights, the scene term (lambda, the
        kernel's weights, its choices) and the choices made on val."""
        if self.model is None:
            raise RuntimeError(f"{self.name}: fit() first (a bundled network is trained)")
        model = self.model.state_dict()
        words = model.get("objects.word_vectors")  # SeanNet's classes; the baselines have none
        return {
            "spec": self.name,
            "config": self.config.to_dict(),
            "num_slots": getattr(self.model, "num_slots", None),
            "classes": None if words is None else int(words.shape[0]),
            "model": {k: v.detach().cpu() for k, v in model.items()},
            "scene": self.scene.state_dict(),
            "choices": self.choices,
            "dim": self._dim,
        }

    def load_state_dict(self, state: dict) -> None:
        """Rebuild the fitted network :meth:`state_dict` describes, in any interpreter."""
        from seannet.model.factory import build_model
        from seannet.model.wordvectors import WordVectorTable
        from seannet.training.config import TrainConfig
        from seannet.training.runs import device_for_run

        if state.get("spec") != self.name:
            raise ValueError(f"a state of {state.get('spec')!r}, not of {self.name!r}")
        self.config = TrainConfig.from_dict(state["config"])
        self.image_size = self.config.model.image_size
        self.network = self.config.model.image_family
        sizes: dict = {}
        if state["num_slots"] is not None:
            sizes["num_slots"] = int(state["num_slots"])
        if state["classes"] is not None:  # SeanNet: its word vectors come with its weights
            names = tuple(f"class{k}" for k in range(state["classes"]))
            words = state["model"]["objects.word_vectors"].numpy()
            sizes["word_vectors"] = WordVectorTable(names, words, "method state", "")
            sizes["class_names"] = list(names)
        model = build_model(self.config.model, **sizes)
        model.load_state_dict(state["model"])
        self.device = device_for_run()
        self.model = model.to(self.device).eval()
        self.scene = SceneTerm.from_state(state["scene"])
        self.choices = dict(state["choices"])
        self._dim = int(state["dim"])
