"""``seannet benchmark``: DESIGN §12's protocol for any method, one card per method.

For each method (a name, an import path or a model spec, :func:`load_method`) and each seed
(trained methods: every seed of the config; frozen ones: the first):

1. ``fit(train, val, budget)`` when the method has one (its choices, lr and lambda, on val);
2. every choice of the harness on **val**: epsilon, the threshold that separates same-pose
   from one-step pairs (max balanced accuracy);
3. **test, read once**: triplet accuracy overall, per tier and per room; full-map recall@1/@5
   (queries of the other layouts against the layout-0 map of their room); precision / recall
   of ``S > epsilon``; the **change sweep** (accuracy by moved objects in view, by their share
   of the anchor's object pixels, by their dynamics class); the box-noise sweep for a method
   with ``uses_boxes``; the cost (ms per view embedded, bytes per map entry).
4. with a ``navigation`` test given (``seannet benchmark --navigator RUN``): the paper's
   navigation test with the first seed's method as localizer (its epsilon from val), its
   success and failure rates in the card.
5. with the covisibility oracle given (``seannet benchmark --covisibility``): accuracy on the
   test triplets the views decide (the oracle agrees with the label) beside all of them,
   overall and per tier, the mean over seeds of each triplet's outcome
   (:mod:`seannet.evaluation.covisibility_oracle`; a diagnostic, the oracle is no method).

The first seed's method is kept in the card's directory as a method directory
(:func:`~seannet.methods.localizer.save_method`: ``method.json``, and ``method.pt`` for a
trained one), so ``seannet map`` / ``localize`` / ``navigate`` take the card directory as a
localizer.

Every output a method gives is checked (finite, float, one row per view, one width; a
similarity in [-1, 1]); any failure, an exception inside the method included, is one
:class:`~seannet.errors.MethodError` naming the method and the check, and no card is written.
Cards are JSON + markdown + a sweep plot, stamped with the commit, the data fingerprint and
the command (:mod:`seannet.methods.cards`).
"""

from __future__ import annotations

import time
from collections import defaultdict
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np
import torch
import torch.nn.functional as F
from torch import Tensor
from torch.utils.data import DataLoader

from seannet.data.box_noise import BoxNoise
from seannet.data.datasets import ImageTransform, ObservationDataset, collate_views
from seannet.data.opening import DataSource, open_dataset
from seannet.errors import MethodError
from seannet.evaluation.covisibility_oracle import decidable_by_tier
from seannet.evaluation.intervals import (
    per_room_matrix,
    t_interval,
    two_level_interval,
    wilson_interval,
)
from seannet.evaluation.retrieval import map_queries
from seannet.methods.change import change_of_pairs, sweep
from seannet.methods.checks import (
    checked_image_input,
    checked_similarity,
    checked_vectors,
    embed_views,
    guarded,
)
from seannet.methods.registry import load_method, method_source, method_title
from seannet.methods.views import Budget, SplitData
from seannet.seeds import DEFAULT_SEEDS
from seannet.training.config import DEFAULT_PRESET
from sgdata.dataset import Dataset

__all__ = [
    "BenchmarkConfig",
    "NOISE_LEVELS",
    "benchmark_method",
    "breaking_point",
    "run_seed",
    "summarize",
]

NOISE_LEVELS = (
    BoxNoise(jitter=0.05),
    BoxNoise(jitter=0.15),
    BoxNoise(drop=0.2),
    BoxNoise(spurious=0.2),
    BoxNoise(jitter=0.1, drop=0.1, spurious=0.1),
)
_CHUNK = 4096  # pairs per similarity call


@dataclass(frozen=True)
class BenchmarkConfig:
    """What the benchmark runs; every method of one benchmark gets the same."""

    seeds: tuple[int, ...] = DEFAULT_SEEDS  # trained methods train once per seed; frozen: the first
    preset: str = DEFAULT_PRESET  # the bundled networks' training preset
    batches: int | None = None  # batches per epoch for trained methods (None: the preset's)
    epochs: int | None = None  # epochs for trained methods (None: the preset's)
    lrs: tuple[float, ...] = ()  # learning rates a trained method chooses from on val
    batch_size: int = 32  # views per embed() call
    map_layout: int = 0  # the layout the recall maps are built in
    noise: tuple[BoxNoise, ...] = NOISE_LEVELS  # the box-noise sweep (methods with uses_boxes)

    def __post_init__(self) -> None:
        if not self.seeds:
            raise MethodError("benchmark: name at least one seed")
        if self.batch_size < 1:
            raise MethodError(f"benchmark: batch_size {self.batch_size}; expected >= 1")


@dataclass
class _Embedded:
    """A split's vectors with the pose metadata only the harness sees."""

    vectors: Tensor
    obs_ids: list[str]
    room: np.ndarray
    layout: np.ndarray
    grid_i: np.ndarray
    grid_j: np.ndarray
    heading: np.ndarray
    seconds: float

    def index(self) -> dict[str, int]:
        return {o: k for k, o in enumerate(self.obs_ids)}


class _Harness:
    """One method on one dataset: views in the method's transform, checked outputs."""

    def __init__(self, name: str, method: Any, dataset: Dataset, config: BenchmarkConfig) -> None:
        self.name, self.method, self.dataset, self.config = name, method, dataset, config
        self.width: int | None = None
        self.similarity = getattr(method, "similarity", None)

    def transform(self) -> ImageTransform:
        return ImageTransform.for_model(*checked_image_input(self.name, self.method))

    def loader(self, split: str, noise: BoxNoise | None = None) -> DataLoader:
        views = ObservationDataset(self.dataset, split, transform=self.transform(), noise=noise)
        return DataLoader(views, batch_size=self.config.batch_size, collate_fn=collate_views)

    def embed(self, split: str, noise: BoxNoise | None = None) -> _Embedded:
        parts, meta = [], defaultdict(list)
        seconds = 0.0
        for batch, info in self.loader(split, noise):
            start = time.perf_counter()
            out = embed_views(self.name, self.method, batch)
            seconds += time.perf_counter() - start
            out = checked_vectors(self.name, out, batch.num_views, self.width)
            self.width = out.shape[1]
            parts.append(out)
            meta["obs_id"] += info["obs_id"]
            meta["room"] += info["room_id"]
            for key in ("layout", "grid_i", "grid_j", "heading"):
                meta[key] += info[key].tolist()
        if not parts:
            raise MethodError(f"method {self.name!r}: the {split} split holds no views")
        return _Embedded(
            torch.cat(parts), meta["obs_id"], np.array(meta["room"]),
            *(np.array(meta[k]) for k in ("layout", "grid_i", "grid_j", "heading")), seconds,
        )  # fmt: skip

    def split_data(self, split: str) -> SplitData:
        views = ObservationDataset(self.dataset, split)
        index = {o: k for k, o in enumerate(views.obs_ids)}
        table = self.dataset.triplets(split)
        triplets = np.array(
            [[index[o] for o in row] for row in zip(
                *(table.column(c).to_pylist() for c in ("anchor", "positive", "negative")),
                strict=True)],
            dtype=np.int64,
        ).reshape(-1, 3)  # fmt: skip

        def batches(batch_size: int):  # noqa: ANN202
            loader = DataLoader(
                ObservationDataset(self.dataset, split, transform=self.transform()),
                batch_size=batch_size, collate_fn=collate_views,
            )  # fmt: skip
            return (batch for batch, _ in loader)

        tiers = table.column("tier").to_numpy().astype(np.int64)
        return SplitData(split, self.dataset, triplets, tiers, len(views), batches, self.name)

    def scores(self, vectors: Tensor, first: np.ndarray, second: np.ndarray) -> np.ndarray:
        """(P,) similarity of the row pairs, checked."""
        if len(first) == 0:
            return np.zeros(0)
        if self.similarity is None:
            unit = F.normalize(vectors.float(), dim=1)
            a, b = unit[torch.from_numpy(first)], unit[torch.from_numpy(second)]
            return (a * b).sum(1).double().numpy()
        out = []
        for start in range(0, len(first), _CHUNK):
            a = vectors[torch.from_numpy(first[start : start + _CHUNK])]
            b = vectors[torch.from_numpy(second[start : start + _CHUNK])]
            s = checked_similarity(self.name, self.similarity, a, b)
            out.append(s.numpy())
        return np.concatenate(out)


def _pose_pairs(e: _Embedded) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(first, second, steps) of same-room, same-heading view pairs at most one step apart."""
    first, second, steps = [], [], []
    for room in sorted(set(e.room)):
        for heading in sorted(set(e.heading[e.room == room])):
            k = np.nonzero((e.room == room) & (e.heading == heading))[0]
            a, b = np.triu_indices(len(k), 1)
            a, b = k[a], k[b]
            step = np.abs(e.grid_i[a] - e.grid_i[b]) + np.abs(e.grid_j[a] - e.grid_j[b])
            keep = (step <= 1) & ((step == 1) | (e.layout[a] != e.layout[b]))
            first.append(a[keep])
            second.append(b[keep])
            steps.append(step[keep])
    cat = lambda parts: np.concatenate(parts) if parts else np.zeros(0, np.int64)  # noqa: E731
    return cat(first), cat(second), cat(steps)


def _choose_epsilon(same: np.ndarray, step: np.ndarray) -> dict[str, float]:
    """Epsilon maximising balanced accuracy of same-pose vs one-step pairs (val)."""
    if not len(same) or not len(step):
        return {"epsilon": float("nan"), "balanced_accuracy": float("nan")}
    candidates = np.unique(np.concatenate([same, step]))
    balanced = [0.5 * ((same > c).mean() + (step <= c).mean()) for c in candidates]
    best = int(np.argmax(balanced))
    return {"epsilon": float(candidates[best]), "balanced_accuracy": float(balanced[best])}


def _recall(h: _Harness, e: _Embedded, map_layout: int) -> dict[str, Any]:
    """recall@1 / @5 of the same pose among the room's map-layout views (other layouts ask),
    and each query's hit@1 with its (query, true map view) pair, for the change sweep."""
    ranks, pairs = [], []
    for room in sorted(set(e.room)):
        map_idx, q, truth = map_queries(e, room, map_layout)
        if not len(q):
            continue
        first, second = np.repeat(q, len(map_idx)), np.tile(map_idx, len(q))
        sim = h.scores(e.vectors, first, second).reshape(len(q), len(map_idx))
        true_score = sim[np.arange(len(q)), truth]
        ranks.append((sim >= true_score[:, None]).sum(axis=1) - 1)  # ties count against
        pairs += [(e.obs_ids[k], e.obs_ids[map_idx[t]]) for k, t in zip(q, truth, strict=True)]
    rank = np.concatenate(ranks) if ranks else np.zeros(0, np.int64)
    return {
        # keyed "1" and "5", as JSON keeps them: a result read back is the result written
        "recall": {str(k): float((rank < k).mean()) if len(rank) else float("nan") for k in (1, 5)},
        "queries": int(len(rank)),
        "_hits": rank < 1,
        "_pairs": pairs,
    }


def _triplets(h: _Harness, e: _Embedded, split: str) -> tuple[np.ndarray, dict[str, Any]]:
    """Per-triplet correctness on ``split`` and the accuracy overall / per tier / per room."""
    table = h.dataset.triplets(split)
    index = e.index()
    cols = [table.column(c).to_pylist() for c in ("anchor", "positive", "negative")]
    a, p, n = (np.array([index[o] for o in col], dtype=np.int64) for col in cols)
    correct = h.scores(e.vectors, a, p) > h.scores(e.vectors, a, n)
    rooms = np.array(table.column("room_id").to_pylist())
    tiers = table.column("tier").to_numpy()
    result = {
        "triplets": int(len(correct)),
        "accuracy": float(correct.mean()) if len(correct) else float("nan"),
        "per_tier": {str(int(t)): float(correct[tiers == t].mean()) for t in sorted(set(tiers))},
        "per_tier_triplets": {str(int(t)): int((tiers == t).sum()) for t in sorted(set(tiers))},
        "per_room": {str(r): float(correct[rooms == r].mean()) for r in sorted(set(rooms))},
        "room_triplets": {str(r): int((rooms == r).sum()) for r in sorted(set(rooms))},
    }
    pairs = list(zip(cols[0], cols[1], strict=True))
    return correct, {**result, "_pairs": pairs}


def run_seed(
    name: str, factory: Callable[[], Any], data: DataSource, config: BenchmarkConfig, seed: int,
    work: Path, say: Callable[[str], None],
) -> tuple[dict[str, Any], Any]:  # fmt: skip
    """The protocol for one seed on ``data`` (an opened dataset, or its root: opened here):
    its results, and the (fitted) method. Its val triplet accuracy (``val_accuracy``) is what
    a choice between runs reads; test is read here once."""
    torch.manual_seed(seed)
    method = guarded(name, "its factory", factory)
    if not callable(getattr(method, "embed", None)):
        raise MethodError(f"method {name!r}: has no embed(views) (check: interface)")
    h = _Harness(name, method, open_dataset(data), config)
    fit = getattr(method, "fit", None)
    fitting = time.perf_counter()
    if fit is not None:
        say(f"{name}: fit, seed {seed}")
        budget = Budget(seed=seed, preset=config.preset, batches=config.batches,
                        epochs=config.epochs, lrs=config.lrs, work=work)  # fmt: skip
        guarded(name, "fit", fit, h.split_data("train"), h.split_data("val"), budget)
    fit_s = time.perf_counter() - fitting
    say(f"{name}: val (epsilon), seed {seed}")
    val = h.embed("val")
    first, second, steps = _pose_pairs(val)
    s = h.scores(val.vectors, first, second)
    threshold = _choose_epsilon(s[steps == 0], s[steps == 1])
    val_correct, _ = _triplets(h, val, "val")
    say(f"{name}: test, seed {seed}")
    test = h.embed("test")
    correct, metrics = _triplets(h, test, "test")
    pairs = metrics.pop("_pairs")
    first, second, steps = _pose_pairs(test)
    s = h.scores(test.vectors, first, second)
    eps = threshold["epsilon"]
    same, step = s[steps == 0], s[steps == 1]
    positives = float((same > eps).sum() + (step > eps).sum())
    retrieval = _recall(h, test, config.map_layout)
    hits, recall_pairs = retrieval.pop("_hits"), retrieval.pop("_pairs")
    result: dict[str, Any] = {
        "seed": seed,
        "trained": fit is not None,
        "val_accuracy": float(val_correct.mean()) if len(val_correct) else float("nan"),
        **metrics,
        # each test triplet right (1) or wrong (0), in the split's row order: any later
        # breakdown (by direction, by covisibility) is read from it without training again
        "test_correct": "".join("1" if c else "0" for c in correct),
        "threshold": {**threshold, "rule": "max balanced accuracy, same pose vs one step (val)"},
        "threshold_on_test": {
            "precision": float((same > eps).sum()) / positives if positives else float("nan"),
            "recall": float((same > eps).mean()) if len(same) else float("nan"),
        },
        "retrieval": retrieval,
        "change": sweep(correct, change_of_pairs(h.dataset, "test", pairs)),
        # recall@1 of each query against how much moved between it and its true map view
        "change_recall": sweep(hits, change_of_pairs(h.dataset, "test", recall_pairs)),
        "cost": {
            "ms_per_view": 1000.0 * test.seconds / len(test.obs_ids),
            "bytes_per_map_entry": int(test.vectors.shape[1] * test.vectors.element_size()),
            "dim": int(test.vectors.shape[1]),
            "torch_threads": torch.get_num_threads(),
            "fit_s": fit_s,
        },
        "choices": dict(getattr(method, "choices", {}) or {}),
    }
    if getattr(method, "uses_boxes", False):
        result["box_noise"] = []
        for noise in config.noise:
            say(f"{name}: test under box noise {noise.label()}, seed {seed}")
            noisy = h.embed("test", noise)
            right, _ = _triplets(h, noisy, "test")
            # the map's views are read with the same graphs as the queries: a robot's map
            # was built by the same detector
            recall = _recall(h, noisy, config.map_layout)["recall"]
            result["box_noise"].append({**asdict(noise), "label": noise.label(),
                                        "accuracy": float(right.mean()),
                                        "recall1": recall["1"]})  # fmt: skip
    return result, method


def breaking_point(by_bin: dict[str, dict[str, float]]) -> str | None:
    """The first bin where accuracy falls below halfway from its first bin's accuracy to
    chance (0.5): where the method breaks; None if it never does."""
    bins = [(k, v["accuracy"]) for k, v in by_bin.items() if not np.isnan(v["accuracy"])]
    if not bins:
        return None
    line = 0.5 * (bins[0][1] + 0.5)
    return next((k for k, acc in bins[1:] if acc < line), None)


def _mean_bins(
    runs: list[dict[str, Any]], measure: str, key: str = "change"
) -> dict[str, dict[str, float]]:
    first = runs[0][key][measure]
    return {
        b: {
            "triplets": first[b]["triplets"],
            "accuracy": float(np.mean([r[key][measure][b]["accuracy"] for r in runs])),
        }
        for b in first
    }


def _floored(interval: dict[str, Any], triplets: int) -> dict[str, Any]:
    """``interval`` never narrower than the binomial (Wilson) one of its mean over
    ``triplets``: few rooms can make the room bootstrap's spread look smaller than the count
    allows (two rooms of 10 triplets gave [68.5, 71.5])."""
    w = wilson_interval(round(interval["mean"] * triplets), triplets)
    if w["low"] >= interval["low"] and w["high"] <= interval["high"]:
        return interval
    return {**interval, "low": min(interval["low"], w["low"]),
            "high": max(interval["high"], w["high"]), "floored_by": "binomial"}  # fmt: skip


def summarize(runs: list[dict[str, Any]]) -> dict[str, Any]:
    """Over seeds: t-intervals, the two-level (rooms x seeds) interval of accuracy, the
    sweep's means and the breaking point."""
    rooms = sorted(runs[0]["per_room"])
    weight = np.array([runs[0]["room_triplets"][r] for r in rooms], dtype=np.float64)
    change = {m: _mean_bins(runs, m) for m in runs[0]["change"]}
    change_recall = {m: _mean_bins(runs, m, "change_recall") for m in runs[0]["change_recall"]}
    summary: dict[str, Any] = {
        "seeds": len(runs),
        "accuracy": t_interval([r["accuracy"] for r in runs]),
        "accuracy_rooms_seeds": _floored(
            two_level_interval(per_room_matrix(runs, rooms), weight), runs[0]["triplets"]
        ),
        "recall1": t_interval([r["retrieval"]["recall"]["1"] for r in runs]),
        "recall5": t_interval([r["retrieval"]["recall"]["5"] for r in runs]),
        "epsilon": float(np.mean([r["threshold"]["epsilon"] for r in runs])),
        "per_tier": {
            t: float(np.mean([r["per_tier"][t] for r in runs])) for t in runs[0]["per_tier"]
        },  # fmt: skip
        "per_tier_triplets": runs[0].get("per_tier_triplets", {}),
        "rooms": len(rooms),
        "change": change,
        "change_recall": change_recall,
        "breaks_at": {m: breaking_point(v) for m, v in change.items() if m != "moved_dynamics"},
        "ms_per_view": float(np.mean([r["cost"]["ms_per_view"] for r in runs])),
        "bytes_per_map_entry": runs[0]["cost"]["bytes_per_map_entry"],
        "triplets": runs[0]["triplets"],
        "queries": runs[0]["retrieval"]["queries"],
    }
    if "box_noise" in runs[0]:
        summary["box_noise"] = [
            {
                **level,
                **{
                    m: float(np.mean([r["box_noise"][k][m] for r in runs]))
                    for m in ("accuracy", "recall1")
                    if m in level
                },
            }  # fmt: skip
            for k, level in enumerate(runs[0]["box_noise"])
        ]
    return summary


def benchmark_method(
    name: str,
    data: DataSource,
    out: Path,
    config: BenchmarkConfig = BenchmarkConfig(),
    *,
    announce: Callable[[str], None] | None = None,
    navigation: Callable[[Path], dict[str, Any]] | None = None,
    covisibility: dict[str, Any] | None = None,
) -> Path:
    """Run the protocol for one method on ``data`` (an opened dataset, or its root: opened
    once here, for every seed, the saved method and the card) and write its card under
    ``out``; the card's JSON path.

    Args:
        navigation: the navigation test of a method directory (the first seed's method, saved
            in the card's directory), returning its summary for the card; the navigation stage
            provides it (:func:`seannet.navigation.method_navigation.navigation_test`).
        covisibility: the covisibility oracle on ``data``'s test split
            (:func:`seannet.evaluation.covisibility_oracle.oracle`): the card says the
            method's accuracy on the triplets the views decide.

    Raises:
        MethodError: the method cannot be loaded or broke a check (no card is written).
    """
    from seannet.methods.cards import card_dir, write_card
    from seannet.methods.localizer import save_method

    say = announce or (lambda _text: None)
    factory, _ = load_method(name)
    dataset = open_dataset(data)
    if covisibility is not None:
        test = dataset.triplets("test").num_rows
        if covisibility.get("split") != "test" or covisibility.get("triplets") != test:
            raise MethodError(
                f"method {name!r}: the covisibility oracle given is not of this dataset's test "
                f"split ({covisibility.get('triplets')} triplets of {covisibility.get('split')!r}"
                f"; test has {test})"
            )
    work = out / "runs"
    first, method = run_seed(name, factory, dataset, config, config.seeds[0], work, say)
    runs = [first]
    trained = first["trained"]  # a method with fit() trains once per seed
    if trained:
        runs += [
            run_seed(name, factory, dataset, config, s, work, say)[0] for s in config.seeds[1:]
        ]
    summary = summarize(runs)
    if covisibility is not None:
        outcomes = np.array([[c == "1" for c in r["test_correct"]] for r in runs])
        summary["covisibility"] = decidable_by_tier(covisibility, outcomes)
    directory = card_dir(out, name)
    directory.mkdir(parents=True, exist_ok=True)
    save_method(directory, name, method, epsilon=first["threshold"]["epsilon"],
                epsilon_source=f"val (benchmark, seed {first['seed']})", data=dataset)  # fmt: skip
    if navigation is not None:
        say(f"{name}: navigation test, seed {first['seed']}")
        summary["navigation"] = navigation(directory)
    return write_card(directory, name, dataset, config, runs, summary, trained=trained,
                      title=method_title(name, method), source=method_source(name))  # fmt: skip
