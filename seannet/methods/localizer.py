"""A method as a localizer: what maps, ``seannet localize`` and ``seannet navigate`` call to
embed views and score them, with every output checked (the same checks as the benchmark)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
import torch
import torch.nn.functional as F

from seannet.data.collate import ViewTensors, collate_views
from seannet.data.view_inputs import ImageTransform
from seannet.methods.checks import checked_similarity, checked_vectors, guarded
from seannet.methods.registry import load_method
from seannet.methods.views import Views

__all__ = ["MethodLocalizer"]

BATCH = 16  # views per embed() call


class MethodLocalizer:
    """Views in, checked vectors out; ``score`` is the method's similarity (default cosine).

    Built from a method name (:func:`~seannet.methods.registry.load_method`; a trained method
    must be fit first: pass the fitted object as ``method``). ``epsilon`` is the threshold a
    benchmark card chose on val (``card["summary"]["epsilon"]``), NaN when unknown.
    """

    def __init__(self, name: str, method: Any | None = None, *, epsilon: float = math.nan):
        self.name = name
        self.method = method if method is not None else guarded(name, "its factory",
                                                                load_method(name)[0])  # fmt: skip
        self.epsilon = epsilon
        self._similarity = getattr(self.method, "similarity", None)

    @property
    def transform(self) -> ImageTransform:
        """The image transform the method reads views with (its size and normalisation)."""
        size = int(getattr(self.method, "image_size", 224))
        return ImageTransform.for_model(size, str(getattr(self.method, "network", "resnet")))

    def embed(self, views: Sequence[ViewTensors]) -> np.ndarray:
        """(N, D) float32 vectors of views (made with :attr:`transform`), checked."""
        parts = []
        for start in range(0, len(views), BATCH):
            batch, _ = collate_views(list(views[start : start + BATCH]))
            out = guarded(self.name, "embed", self.method.embed, Views(batch, method=self.name))
            parts.append(checked_vectors(self.name, out, batch.num_views, None))
        if not parts:
            return np.zeros((0, 0), dtype=np.float32)
        vectors = torch.cat(parts)
        if self._similarity is None:
            vectors = F.normalize(vectors.float(), dim=1)  # cosine: unit rows, dot products
        return vectors.numpy().astype(np.float32)

    def score(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """(P,) similarity of the row pairs (a[k], b[k]) of :meth:`embed`'s vectors."""
        ta, tb = (
            torch.from_numpy(np.ascontiguousarray(a)),
            torch.from_numpy(np.ascontiguousarray(b)),
        )
        if self._similarity is None:
            return (ta * tb).sum(1).double().numpy()
        return checked_similarity(self.name, self._similarity, ta, tb).numpy()
