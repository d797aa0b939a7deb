"""A trained method's directory (``method.json`` + ``method.pt``) holds its ``state_dict``, not a
pickle: a fresh interpreter rebuilds the method with its factory and gets the same vectors; a
trained method without a state is one line at save time; a pickled method is refused in one
line."""

from __future__ import annotations

import io
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import torch
from torch.utils.data import DataLoader

from seannet.data.datasets import ImageTransform, ObservationDataset, collate_views, open_dataset
from seannet.data.opening import dataset_identity
from seannet.errors import MethodError
from seannet.methods import BenchmarkConfig, benchmark_method, load_method
from seannet.methods.localizer import (
    METHOD_FILE,
    STATE_FILE,
    STATE_FORMAT,
    MethodLocalizer,
    open_method,
    save_method,
)
from seannet.methods.views import Budget, SplitData

# a user's trained method in a file no import path reaches: a linear map of tiny images,
# fitted on the train triplets
USER_METHOD = """
import torch
import torch.nn.functional as F


class Projected:
    image_size = 32

    def __init__(self):
        self.weight = None
        self.steps = 0

    def _tiny(self, views):
        return F.adaptive_avg_pool2d(views.images.float() / 255.0, 8).flatten(1)

    def fit(self, train, val, budget):
        torch.manual_seed(budget.seed)
        x = torch.cat([self._tiny(v) for v in train.views()])
        t = torch.from_numpy(train.triplets)
        w = torch.randn(x.shape[1], 16, requires_grad=True)
        optimizer = torch.optim.SGD([w], lr=0.1)
        for _ in range(5):
            a, p, n = (F.normalize(x[t[:, k]] @ w, dim=1) for k in range(3))
            loss = F.relu(0.1 - (a * p).sum(1) + (a * n).sum(1)).mean()
            optimizer.zero_grad()
            loss.backward()
            optimizer.step()
        self.weight, self.steps = w.detach(), 5

    def embed(self, views):
        return self._tiny(views) @ self.weight
{extra}"""
STATE_METHODS = """
    def state_dict(self):
        return {"weight": self.weight, "steps": self.steps}

    def load_state_dict(self, state):
        self.weight, self.steps = state["weight"], state["steps"]
"""
# the fresh interpreter: open a method directory, embed the first test views, save them
OPEN_AND_EMBED = """
import sys
from pathlib import Path
import numpy as np
from seannet.data.datasets import ObservationDataset
from seannet.methods.localizer import open_method

directory, data, out, count = Path(sys.argv[1]), Path(sys.argv[2]), sys.argv[3], int(sys.argv[4])
localizer = open_method(directory, data)
views = ObservationDataset(data, "test", transform=localizer.transform)
vectors = localizer.embed([views[k].view for k in range(count)])
np.savez(out, vectors=vectors, scores=localizer.score(vectors, vectors[::-1].copy()))
"""
VIEWS = 6


def _split(data: Path, name: str, size: int, method: str) -> SplitData:
    """A split as the benchmark hands it to ``fit`` (views in batches, triplet indices)."""
    dataset = open_dataset(data)
    views = ObservationDataset(dataset, name, transform=ImageTransform.for_model(size, "resnet"))
    index = {o: k for k, o in enumerate(views.obs_ids)}
    table = dataset.triplets(name)
    columns = [table.column(c).to_pylist() for c in ("anchor", "positive", "negative")]
    triplets = np.array([[index[o] for o in col] for col in columns], dtype=np.int64).T

    def batches(batch_size: int):  # noqa: ANN202
        loader = DataLoader(views, batch_size=batch_size, collate_fn=collate_views)
        return (batch for batch, _ in loader)

    tiers = table.column("tier").to_numpy().astype(np.int64)
    return SplitData(name, dataset, triplets, tiers, len(views), batches, method)


def _user_method(tmp_path: Path, *, state: bool = True) -> str:
    path = tmp_path / ("projected.py" if state else "stateless.py")
    path.write_text(USER_METHOD.format(extra=STATE_METHODS if state else ""))
    return f"{path}:Projected"


def _fitted(name: str, data: Path) -> object:
    method = load_method(name)[0]()
    method.fit(
        _split(data, "train", 32, name),
        _split(data, "val", 32, name),
        Budget(seed=0, preset="smoke"),
    )
    return method


def _fresh_embed(directory: Path, data: Path, tmp_path: Path) -> dict[str, np.ndarray]:
    """What a fresh interpreter (no test module, no user module imported) embeds with it."""
    out = tmp_path / "fresh.npz"
    done = subprocess.run(
        [sys.executable, "-c", OPEN_AND_EMBED, str(directory), str(data), str(out), str(VIEWS)],
        capture_output=True, text=True, cwd=tmp_path, check=False,
        env={**os.environ, "OMP_NUM_THREADS": "1"},
    )  # fmt: skip
    assert done.returncode == 0, done.stderr[-2000:]
    with np.load(out) as saved:
        return {k: saved[k] for k in saved.files}


def _embed(localizer: MethodLocalizer, data: Path) -> np.ndarray:
    views = ObservationDataset(data, "test", transform=localizer.transform)
    return localizer.embed([views[k].view for k in range(VIEWS)])


def test_a_users_trained_method_opens_in_a_fresh_interpreter(
    mini_dataset: Path, tmp_path: Path
) -> None:
    name = _user_method(tmp_path)
    method = _fitted(name, mini_dataset)
    directory = tmp_path / "card"
    directory.mkdir()
    save_method(directory, name, method, epsilon=0.5, epsilon_source="test", data=mini_dataset)
    saved = torch.load(directory / STATE_FILE, weights_only=True)  # plain data, no class
    assert saved["format"] == STATE_FORMAT and set(saved["state"]) == {"weight", "steps"}
    fresh = _fresh_embed(directory, mini_dataset, tmp_path)
    expected = _embed(MethodLocalizer(name, method), mini_dataset)
    assert fresh["vectors"].shape == (VIEWS, 16)
    # the same numbers up to float rounding: the fresh interpreter runs torch on one thread,
    # this one on the machine's (a matmul split over threads may round its last bit apart)
    np.testing.assert_allclose(fresh["vectors"], expected, rtol=1e-6, atol=1e-6)


def test_a_benchmarked_network_opens_by_its_card_directory_in_a_fresh_interpreter(
    mini_dataset: Path, tmp_path: Path
) -> None:
    from seannet.methods.bundled import NetworkMethod
    from seannet.model.specs import parse_spec
    from seannet.training.runs import restore_run

    config = BenchmarkConfig(
        seeds=(0,), preset="smoke", batch_size=16, batches=1, epochs=1, noise=()
    )
    card_file = benchmark_method("resnet18+boxes", mini_dataset, tmp_path / "cards", config)
    directory = card_file.parent
    choices = json.loads(card_file.read_text())["runs"][0]["choices"]
    # the reference: the network the fit kept, read back from its run's checkpoint
    reference = NetworkMethod(parse_spec("resnet18+boxes"), preset="smoke")
    reference.model = restore_run(Path(choices["run"]), mini_dataset).model
    expected = _embed(MethodLocalizer("resnet18+boxes", reference), mini_dataset)
    fresh = _fresh_embed(directory, mini_dataset, tmp_path)
    np.testing.assert_allclose(fresh["vectors"], expected, rtol=0, atol=1e-5)
    opened = open_method(directory, mini_dataset)
    assert opened.method.scene.weight == choices["box_weight"]["lambda"]  # lambda from val
    assert opened.method.choices == choices
    np.testing.assert_allclose(
        fresh["scores"], opened.score(fresh["vectors"], fresh["vectors"][::-1].copy()), atol=1e-6
    )
    # the file is the weights and a little plain data, not a pickled object graph
    saved = torch.load(directory / STATE_FILE, weights_only=True)
    assert saved["format"] == STATE_FORMAT and saved["state"]["spec"] == "resnet18+boxes"
    buffer = io.BytesIO()
    torch.save(reference.model.state_dict(), buffer)
    assert (directory / STATE_FILE).stat().st_size <= len(buffer.getvalue()) + 32_768


def test_a_trained_method_without_a_state_is_one_line_at_save_time(
    mini_dataset: Path, tmp_path: Path
) -> None:
    name = _user_method(tmp_path, state=False)
    with pytest.raises(MethodError) as error:
        benchmark_method(name, mini_dataset, tmp_path / "cards", BenchmarkConfig(seeds=(0,)))
    message = str(error.value)
    assert name in message and "state_dict / load_state_dict" in message and "\n" not in message
    assert not list((tmp_path / "cards").rglob("card.*"))
    assert not list((tmp_path / "cards").rglob(STATE_FILE))


class _Holds:
    """A trained method whose state holds a module, not its weights."""

    def __init__(self) -> None:
        self.head = torch.nn.Linear(2, 2)

    def fit(self, train: object, val: object, budget: object) -> None:
        pass

    def embed(self, views: object) -> torch.Tensor:
        return torch.ones(1, 2)

    def state_dict(self) -> dict:
        return {"steps": 3, "parts": [{"head": self.head}]}

    def load_state_dict(self, state: dict) -> None:
        pass


def test_a_state_of_more_than_plain_data_is_refused_naming_where(
    mini_dataset: Path, tmp_path: Path
) -> None:
    with pytest.raises(MethodError) as error:
        save_method(tmp_path, "holds", _Holds(), epsilon=0.5, epsilon_source="t", data=mini_dataset)
    message = str(error.value)
    assert "'holds'" in message and "state['parts'][0]['head'] is a Linear" in message
    assert not (tmp_path / STATE_FILE).exists() and not (tmp_path / METHOD_FILE).exists()


def test_a_pickled_method_or_a_damaged_state_is_refused_in_one_line(
    mini_dataset: Path, tmp_path: Path
) -> None:
    from seannet.methods.reference import BoxKernelMethod

    torch.save(BoxKernelMethod(), tmp_path / STATE_FILE)  # the object itself, not its state
    record = {"method": 1, "name": "boxes-kernel", "trained": True, "epsilon": 0.4,
              "epsilon_source": "val", "dataset": dataset_identity(mini_dataset)}  # fmt: skip
    (tmp_path / METHOD_FILE).write_text(json.dumps(record))
    for damaged in (None, b"not a state"):
        if damaged is not None:
            (tmp_path / STATE_FILE).write_bytes(damaged)
        with pytest.raises(MethodError, match="benchmark it again") as error:
            open_method(tmp_path, mini_dataset)
        assert "\n" not in str(error.value)
