"""The scene term of a model spec (``MODEL+boxes``, ``MODEL+box-kernel``): a box score added to
the network's similarity, one home for ``seannet eval`` and the method benchmark.

``S_scene(a, b)`` is the hand-made overlap of the views' boxes, slot by slot
(:mod:`seannet.evaluation.box_overlap`, ``+boxes``), or the slot kernel fit on the train
triplets (:mod:`seannet.evaluation.box_kernel`, ``+box-kernel``). A pair scores
``S + lambda * S_scene``, lambda the value of
:data:`~seannet.evaluation.box_overlap.BOX_WEIGHTS` that ranks the most val triplets right
(:func:`~seannet.evaluation.box_overlap.choose_box_weight`). A method's similarity divides the
same sum by ``1 + lambda`` (``combine(..., unit=True)``): in [-1, 1] like a cosine, where the
benchmark's checks and epsilon expect it, and in the same order, so accuracy is the same.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, TypeVar

import numpy as np

from seannet.evaluation.box_kernel import BoxKernel, SlotPairs, fit_box_kernel, slot_pairs
from seannet.evaluation.box_overlap import SlotBoxes, choose_box_weight
from seannet.model.specs import SCENE_TERMS

__all__ = ["BOX_KERNEL", "SceneTerm"]

BOX_KERNEL = "+box-kernel"  # the term that learns (its kernel) on the train triplets
Triplets = Sequence[tuple[str, str, str]]  # (anchor, positive, negative) ids of SlotBoxes
_Scores = TypeVar("_Scores")  # np.ndarray or torch.Tensor: combine keeps the caller's type


@dataclass
class SceneTerm:
    """One scene term and what was chosen for it: the kernel (``+box-kernel``, on train) and
    lambda (on val). The empty term scores nothing and combines to ``S`` itself.

    Attributes:
        term: a key of :data:`~seannet.model.specs.SCENE_TERMS`, or ``""``.
        kernel: the slot kernel after :meth:`fit` (``+box-kernel``), else None.
        weight: lambda after :meth:`choose_weight` (0 until then: ``S`` alone).
        choices: the plain-data record for a JSON file: ``box_kernel`` (train triplets and
            accuracy, after :meth:`fit`) and ``box_weight`` (lambda and each lambda's val
            accuracy, after :meth:`choose_weight`).
    """

    term: str = ""
    kernel: BoxKernel | None = None
    weight: float = 0.0
    choices: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.term and self.term not in SCENE_TERMS:
            raise ValueError(
                f"scene term {self.term!r}: expected one of {', '.join(SCENE_TERMS)} or ''"
            )

    @classmethod
    def from_spec(cls, term: str) -> SceneTerm:
        """The unfitted term named ``term`` (``""``, ``+boxes`` or ``+box-kernel``).

        Raises:
            ValueError: ``term`` is not a scene term.
        """
        return cls(term)

    @property
    def learned(self) -> bool:
        """Whether :meth:`fit` learns something (the kernel of ``+box-kernel``)."""
        return self.term == BOX_KERNEL

    def fit(self, boxes: SlotBoxes, triplets: Triplets) -> None:
        """``+box-kernel``: fit the kernel on the train triplets' boxes (the same boxes give the
        same kernel); the other terms learn nothing."""
        if not self.learned:
            return
        positive, negative = _pairs(boxes, triplets)
        self.kernel, accuracy = fit_box_kernel(positive, negative, boxes.boxes.shape[1])
        self.choices["box_kernel"] = {"train_triplets": positive.pairs, "train_accuracy": accuracy}

    def scores(self, boxes: SlotBoxes, first: Sequence[str], second: Sequence[str]) -> np.ndarray:
        """``S_scene`` of each pair (first[k], second[k]) of ``boxes``' ids: (P,) float64 in
        [0, 1]; zeros for the empty term.

        Raises:
            ValueError: ``+box-kernel`` before :meth:`fit`.
        """
        if not self.term:
            return np.zeros(len(first))
        if not self.learned:
            return boxes.overlap(first, second)
        if self.kernel is None:
            raise ValueError(f"{self.term}: fit the kernel on the train triplets first")
        return self.kernel.score(slot_pairs(boxes, first, second))

    def triplet_scores(self, boxes: SlotBoxes, triplets: Triplets) -> tuple[np.ndarray, np.ndarray]:
        """(S_scene(A, P), S_scene(A, N)) of each triplet of ``boxes``' ids."""
        anchors, positives, negatives = zip(*triplets, strict=True) if triplets else ((), (), ())
        return self.scores(boxes, anchors, positives), self.scores(boxes, anchors, negatives)

    def choose_weight(
        self, s_ap: np.ndarray, s_an: np.ndarray, box_ap: np.ndarray, box_an: np.ndarray
    ) -> tuple[float, dict[str, float]]:
        """Choose lambda on the val triplets' similarities ``S`` and scene scores (the value
        ranking the most right with ``S + lambda * S_scene``; ties: the smaller), keep it, and
        return it with each lambda's val accuracy."""
        weight, by_weight = choose_box_weight(s_ap, s_an, box_ap, box_an)
        self.weight = weight
        self.choices["box_weight"] = {"lambda": weight, "val_accuracy_by_lambda": by_weight}
        return weight, by_weight

    def combine(self, s: _Scores, box: _Scores, *, unit: bool = False) -> _Scores:
        """``S + lambda * S_scene`` (what lambda was chosen by, and what ``seannet eval``
        reports); ``unit``: divided by ``1 + lambda``, in [-1, 1] for a cosine ``S`` (a method's
        similarity), in the same order."""
        combined = s + self.weight * box
        return combined / (1.0 + self.weight) if unit else combined

    def state_dict(self) -> dict[str, Any]:
        """The term and its choices as tensors and plain data (a method's saved state)."""
        kernel = None
        if self.kernel is not None:
            kernel = {k: v.detach().cpu() for k, v in self.kernel.state_dict().items()}
        return {
            "term": self.term,
            "weight": float(self.weight),
            "kernel": kernel,
            "choices": self.choices,
        }

    @classmethod
    def from_state(cls, state: dict[str, Any]) -> SceneTerm:
        """The term :meth:`state_dict` describes."""
        kernel = None
        if state["kernel"] is not None:
            kernel = BoxKernel(len(state["kernel"]["slot_weight"]))
            kernel.load_state_dict(state["kernel"])
            kernel.eval()
        return cls(state["term"], kernel, float(state["weight"]), dict(state["choices"]))


def _pairs(boxes: SlotBoxes, triplets: Triplets) -> tuple[SlotPairs, SlotPairs]:
    anchors, positives, negatives = zip(*triplets, strict=True) if triplets else ((), (), ())
    return slot_pairs(boxes, anchors, positives), slot_pairs(boxes, anchors, negatives)
