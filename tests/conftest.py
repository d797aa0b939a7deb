"""Shared test fixtures: a tiny hand-built room with its render geometry, one renderer, the
mini dataset, tiny seannet runs (a localizer, a navigation run), built once per run and shared
by every xdist worker (tests/artefacts.py), one spawned worker per navigation module, process
probes, the lock that lets a `quiet` test time an idle machine, the run's TMPDIR, and a
session-end check that no process of the run survives."""

from __future__ import annotations

import contextlib
import fcntl
import json
import os
import shutil
import sys
import tempfile
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

# Before any EGL context: Mesa's llvmpipe and triton (loaded by torch._dynamo, which
# torchvision's models import) each bring an LLVM, and loading triton after Mesa segfaults.
# `import seannet` does this first in its own processes; the test session mixes both.
import torch._dynamo  # noqa: F401  isort: skip
import torch
import trimesh

from sgdata.usd.meshes import MeshData, ObjectGeometry, SceneGeometry
from sgdata.world.scene import Dynamics, Opening, Placement, Room, SceneObject

from .artefacts import changed_artefacts, run_folder, shared_artefact

# The camera pose from which the tiny room's interesting objects are all in view.
TINY_VIEW = (2.5, 0.5, np.pi / 2)  # x, y, theta: standing near the south wall, looking north


@dataclass(frozen=True)
class TinyRoom:
    """The tiny room: its model, its render geometry, and names for its instances."""

    room: Room
    geometry: SceneGeometry
    ids: dict[str, int]


def _mesh(parts: list[trimesh.Trimesh], color: tuple[float, float, float]) -> MeshData:
    m = trimesh.util.concatenate(parts)
    return MeshData(
        vertices=np.asarray(m.vertices, dtype=np.float64),
        faces=np.asarray(m.faces, dtype=np.int32),
        face_colors=np.tile(np.asarray(color, dtype=np.float32), (len(m.faces), 1)),
    )


def _box(
    extents: tuple[float, float, float], center: tuple[float, float, float]
) -> trimesh.Trimesh:
    b = trimesh.creation.box(extents=extents)
    b.apply_translation(center)
    return b


def _block(size: tuple[float, float, float]) -> list[trimesh.Trimesh]:
    """A solid box in the local frame (origin at the bottom centre)."""
    return [_box(size, (0.0, 0.0, size[2] / 2))]


def _table(size: tuple[float, float, float]) -> list[trimesh.Trimesh]:
    w, d, h = size
    top = _box((w, d, 0.04), (0, 0, h - 0.02))
    legs = [
        _box((0.05, 0.05, h - 0.04), (sx * (w / 2 - 0.025), sy * (d / 2 - 0.025), (h - 0.04) / 2))
        for sx in (-1, 1)
        for sy in (-1, 1)
    ]
    return [top, *legs]


def _shelving(size: tuple[float, float, float]) -> list[trimesh.Trimesh]:
    """An open-front frame: two sides, bottom, top and back (the board is its own object)."""
    w, d, h, t = *size, 0.02
    return [
        _box((t, d, h), (-w / 2 + t / 2, 0, h / 2)),
        _box((t, d, h), (w / 2 - t / 2, 0, h / 2)),
        _box((w, d, t), (0, 0, t / 2)),
        _box((w, d, t), (0, 0, h - t / 2)),
        _box((w, t, h), (0, d / 2 - t / 2, h / 2)),
    ]


def _mug(size: tuple[float, float, float]) -> list[trimesh.Trimesh]:
    c = trimesh.creation.cylinder(radius=size[0] / 2, height=size[2], sections=16)
    c.apply_translation((0, 0, size[2] / 2))
    return [c]


def build_tiny_room() -> TinyRoom:
    """A 5 x 4 m room: a mug on a table, a book on a board inside a shelving unit, two chairs
    side by side, and a crate hidden behind the north wall."""
    width, depth, height = 5.0, 4.0, 2.6
    specs = [
        # name, instance, class, dynamics, size, placement, support, attached_to, colour, shape
        ("table", 1, "DiningTable", Dynamics.LOW, (1.0, 0.6, 0.75), (1.3, 2.8, 0.0), None, None,
         (0.45, 0.25, 0.1), _table),
        ("mug", 2, "Mug", Dynamics.HIGH, (0.12, 0.12, 0.14), (1.3, 2.7, 0.75), 1, None,
         (0.8, 0.1, 0.1), _mug),
        ("unit", 3, "ShelvingUnit", Dynamics.LOW, (0.8, 0.4, 1.2), (4.0, 3.0, 0.0), None, None,
         (0.5, 0.5, 0.55), _shelving),
        ("board", 5, "Shelf", Dynamics.STATIC, (0.76, 0.36, 0.02), (4.0, 2.99, 0.55), None, 3,
         (0.6, 0.45, 0.3), _block),
        ("book", 4, "Book", Dynamics.HIGH, (0.3, 0.22, 0.08), (4.0, 2.95, 0.57), 5, None,
         (0.1, 0.2, 0.8), _block),
        ("chair_a", 6, "Chair", Dynamics.HIGH, (0.45, 0.45, 0.9), (2.5, 2.0, 0.0), None, None,
         (0.1, 0.5, 0.2), _block),
        ("chair_b", 7, "Chair", Dynamics.HIGH, (0.45, 0.45, 0.9), (3.0, 2.0, 0.0), None, None,
         (0.9, 0.7, 0.1), _block),
        ("crate", 8, "Box", Dynamics.HIGH, (0.5, 0.5, 0.5), (2.5, 4.5, 0.0), None, None,
         (0.9, 0.2, 0.9), _block),
    ]  # fmt: skip
    objects, geoms, ids = [], [], {}
    for name, inst, cls, dyn, size, (x, y, z), sup, att, color, shape in specs:
        obj = SceneObject(
            instance=inst,
            class_name=cls,
            dynamics=dyn,
            size=size,
            placement=Placement(x, y, z),
            color=color,
            support=sup,
            attached_to=att,
        )
        objects.append(obj)
        geoms.append(ObjectGeometry(inst, cls, _mesh(shape(size), color), obj.placement.matrix()))
        ids[name] = inst
    t = 0.1
    structure = (
        _mesh([_box((width, depth, t), (width / 2, depth / 2, -t / 2))], (0.55, 0.5, 0.45)),
        _mesh([_box((width, depth, t), (width / 2, depth / 2, height + t / 2))], (0.9, 0.9, 0.9)),
        _mesh(
            [
                _box((width + 2 * t, t, height), (width / 2, -t / 2, height / 2)),
                _box((width + 2 * t, t, height), (width / 2, depth + t / 2, height / 2)),
                _box((t, depth, height), (-t / 2, depth / 2, height / 2)),
                _box((t, depth, height), (width + t / 2, depth / 2, height / 2)),
            ],
            (0.8, 0.78, 0.7),
        ),
    )
    room = Room(
        room_id="tiny_000",
        room_type="living_room",
        width=width,
        depth=depth,
        height=height,
        seed=0,
        door=Opening("south", center=1.0, width=0.9, bottom=0.0, top=2.0),
        objects=tuple(objects),
    )
    return TinyRoom(room, SceneGeometry(structure=structure, objects=tuple(geoms)), ids)


@pytest.fixture(scope="session")
def tiny_room() -> TinyRoom:
    """The tiny room (see :func:`build_tiny_room`)."""
    return build_tiny_room()


@pytest.fixture(scope="session")
def renderer() -> Iterator[object]:
    """One EGL renderer for the whole session (building contexts is slow)."""
    from sgdata.render.renderer import Renderer

    r = Renderer()
    yield r
    r.close()


@pytest.fixture
def tiny_renderer(renderer: object, tiny_room: TinyRoom) -> object:
    """The session renderer holding the tiny room's default layout."""
    renderer.update_poses(tiny_room.geometry)  # type: ignore[attr-defined]
    return renderer


@pytest.fixture(scope="session")
def tiny_view() -> tuple[float, float, float]:
    """(x, y, theta) from which every interesting object of the tiny room is in view."""
    return TINY_VIEW


# One small real dataset for every test that reads one: three bathrooms (train, val, test),
# two layouts each, 96 px views, 20 / 10 / 10 triplets. About 20 s to generate, once.
MINI_TOML = """\
[dataset]
name = "mini"
version = "0.0.1"
seed = 5
[rooms]
types = ["bathroom"]
train = 1
val = 1
test = 1
[layouts]
count = 2
[camera]
width = 96
height = 96
[triplets]
train = 20
val = 10
test = 10
"""
MINI_TRIPLETS = {"train": 20, "val": 10, "test": 10}


@pytest.fixture(scope="session")
def mini_triplets() -> dict[str, int]:
    """Triplets per split of the mini dataset."""
    return dict(MINI_TRIPLETS)


@pytest.fixture(scope="session")
def mini_config_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("mini_config") / "mini.toml"
    path.write_text(MINI_TOML)
    return path


def generated_dataset(tmp_path_factory: pytest.TempPathFactory, name: str, toml: str) -> Path:
    """The dataset a config (TOML text) generates, with 2 workers, as the shared artefact
    ``name``: generated once per test run."""

    def build(root: Path) -> None:
        from sgdata.pipeline.config import load_config
        from sgdata.pipeline.generate import generate_dataset

        config_file = root.parent / f"{name}.toml"
        config_file.write_text(toml)
        generate_dataset(load_config(config_file), root, workers=2)

    return shared_artefact(tmp_path_factory, name, build)


@pytest.fixture(scope="session")
def mini_dataset(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Root of the generated mini dataset (real USD, Parquet and PNG), built once per run."""
    return generated_dataset(tmp_path_factory, "mini_dataset", MINI_TOML)


# The mini dataset with the optional channels on (depth and instance masks): the channel
# checks, the COCO / YOLO exports and the loader's channel tensors read it.
CHANNELS_TOML = MINI_TOML + "[outputs]\ndepth = true\ninstances = true\n"


@pytest.fixture(scope="session")
def channels_dataset(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Root of the mini dataset generated with ``[outputs] depth`` and ``instances`` on."""
    return generated_dataset(tmp_path_factory, "channels_dataset", CHANNELS_TOML)


# --------------------------------------------------------------------------- seannet runs
# Trained in seconds on the mini dataset, shared by the seannet tests and the tests of the
# bench scripts (tests/bench/) that read them. seannet is imported in the fixtures, so a
# session of sgdata tests never loads it.


def tiny_localizer_config():  # noqa: ANN201  (seannet.training.config.TrainConfig)
    """A localizer run in seconds: the ResNet-18 baseline at 64 px, one batch of two triplets."""
    from seannet.training.config import TrainConfig

    return TrainConfig().replace(
        model="resnet18",
        image_size=64,
        embed_dim=64,
        epochs=1,
        batch_size=2,
        max_train_batches=1,
        num_workers=0,
    )


@pytest.fixture
def tiny_seannet():  # noqa: ANN201  (seannet.training.config.TrainConfig)
    """SeanNet in seconds: the cpu preset's (GCN fc 512 wide) on ResNet-18 at 64 px, an 8 x 8
    layout pathway, one batch of four triplets."""
    from seannet.training.config import TrainConfig

    return TrainConfig().replace(
        model="seannet-fc512",
        depth=18,
        image_size=64,
        roi_size=4,
        visual_features="c5",
        embed_dim=64,
        layout_grid=8,
        layout_sketch=0,
        epochs=1,
        batch_size=4,
        max_train_batches=1,
        num_workers=0,
    )


@pytest.fixture(scope="session")
def localizer_run(tmp_path_factory: pytest.TempPathFactory, mini_dataset: Path) -> Path:
    """A run directory (best.pt) trained on the mini dataset; no eval file, so no epsilon."""

    def build(run: Path) -> None:
        from seannet.training.train import train

        train(tiny_localizer_config(), mini_dataset, run)

    return shared_artefact(tmp_path_factory, "localizer_run", build)


@pytest.fixture(scope="session")
def detector_run(tmp_path_factory: pytest.TempPathFactory, channels_dataset: Path) -> Path:
    """A detector run (FCOS on Lite0, 96 px, two epochs) trained on the channels dataset's
    COCO export by ``seannet detector train``: the detection tests copy it (their evals
    write into it), the labeling tool proposes its boxes."""

    def build(run: Path) -> None:
        from tests.cli_runner import run_cli

        done = run_cli(
            "seannet", "detector", "train", "--data", channels_dataset, "--out", run,
            "--epochs", "2", "--size", "96", "--val-views", "0",
        )  # fmt: skip
        assert done.returncode == 0, done.stderr

    return shared_artefact(tmp_path_factory, "detector_run", build)


@pytest.fixture(scope="module")
def detector_copy(tmp_path_factory: pytest.TempPathFactory, detector_run: Path) -> Path:
    """The shared detector run copied for a module whose commands write into the run (scores,
    the detected graphs' cache and threshold)."""
    run = tmp_path_factory.mktemp("detector") / "run"
    shutil.copytree(detector_run, run)
    return run


@pytest.fixture(scope="module")
def one_pool() -> Iterator[None]:
    """One spawned worker for every one-worker run of the module's tests (maps, episodes), as
    a command of several phases keeps one (:func:`sgdata.pipeline.executors.executor_session`):
    a fresh worker spends some 5 s importing torch and seannet before its first task."""
    from sgdata.pipeline.executors import executor_session

    with executor_session(workers=1):
        yield


def tiny_navigation() -> dict:
    """What the tiny navigation run used: the kill-and-resume test runs it again with these."""
    from seannet.navigation.config import NavigationTestConfig

    return {"config": NavigationTestConfig(episodes=2, replan=True), "epsilon": 0.95}


@pytest.fixture(scope="session")
def navigation_run(
    tmp_path_factory: pytest.TempPathFactory, localizer_run: Path, mini_dataset: Path
) -> SimpleNamespace:
    """A navigator trained in seconds, and ``seannet navigate`` of the tiny localizer with
    it on the mini dataset's test room (two workers, paper rule and --replan, strips)."""

    def build(root: Path) -> None:
        from seannet.navigation.benchmark import run_navigation
        from seannet.navigation.navigator import NavigatorConfig
        from seannet.navigation.navigator_training import train_navigator

        config = NavigatorConfig(
            image_size=64, hidden=16, epochs=1, batch_size=8, train_pairs=8, val_pairs=4
        )
        train_navigator(config, mini_dataset, root / "nav")
        run_navigation(
            [localizer_run],
            root / "nav",
            mini_dataset,
            workers=2,
            out=root / "out",
            strips=root / "strips",
            **tiny_navigation(),
        )

    from seannet.navigation.benchmark import results_path

    root = shared_artefact(tmp_path_factory, "navigation_run", build)
    written = results_path(root / "out", tiny_navigation()["config"].split)
    return SimpleNamespace(
        navigator=root / "nav", out=root / "out", strips=root / "strips",
        history=json.loads((root / "nav" / "history.json").read_text()),
        results={**json.loads(written.read_text()), "written": str(written.with_suffix(".md"))},
        options=tiny_navigation(),
    )  # fmt: skip


# --------------------------------------------------------------------------- processes


def _stat(pid: int) -> tuple[int, int, int, int] | None:
    """(ppid, pgid, sid, start time in clock ticks) of a live process, None if gone."""
    try:
        text = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return None
    fields = text.rsplit(")", 1)[1].split()
    if fields[0] == "Z":  # a zombie has exited; only its parent's wait is missing
        return None
    return int(fields[1]), int(fields[2]), int(fields[3]), int(fields[19])


def _cmdline(pid: int) -> str:
    try:
        return (
            Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
        )
    except OSError:
        return ""


def live_pids() -> list[int]:
    return [int(p) for p in os.listdir("/proc") if p.isdigit()]


def in_group(pgid: int) -> list[int]:
    """Live processes of process group ``pgid``."""
    return [p for p in live_pids() if (s := _stat(p)) is not None and s[1] == pgid]


def in_session(sid: int) -> list[int]:
    """Live processes of session ``sid`` (a run started with ``start_new_session``)."""
    return [p for p in live_pids() if (s := _stat(p)) is not None and s[2] == sid]


def ancestors(pid: int) -> set[int]:
    found = set()
    while pid > 1 and (s := _stat(pid)) is not None:
        found.add(pid)
        pid = s[0]
    return found


def strays_since(start_ticks: int, *, exclude: set[int]) -> list[str]:
    """Live processes of this project's environment (their command line names this venv)
    started since ``start_ticks``, other than ``exclude``: what a run left behind."""
    out = []
    for pid in live_pids():
        s = _stat(pid)
        if pid in exclude or s is None or s[3] < start_ticks:
            continue
        command = _cmdline(pid)
        if sys.prefix in command:
            out.append(f"{pid}: {command[:120]}")
    return out


def start_ticks(pid: int) -> int:
    s = _stat(pid)
    assert s is not None
    return s[3]


def wait_until_gone(find, seconds: float = 10.0) -> list:  # noqa: ANN001
    """Poll ``find()`` until it returns nothing or ``seconds`` pass; the last result."""
    deadline = time.monotonic() + seconds
    while (left := find()) and time.monotonic() < deadline:
        time.sleep(0.1)
    return left


@pytest.fixture(scope="session")
def procs() -> SimpleNamespace:
    """The /proc probes above, for tests that kill real runs."""
    return SimpleNamespace(
        in_group=in_group,
        in_session=in_session,
        strays_since=strays_since,
        start_ticks=start_ticks,
        wait_until_gone=wait_until_gone,
        ancestors=ancestors,
    )


# --------------------------------------------------------------------------- xdist workers


@pytest.hookimpl(trylast=True)  # after pytest's own, which makes the run's temp folder
def pytest_configure(config: pytest.Config) -> None:
    """Temporary files of the run, and of every process it starts, go under the run's temp
    folder (``TMPDIR``): a command the tests kill with SIGKILL cannot remove its own (its
    pool's task notes), and Ray keeps its sessions under ``$TMPDIR/ray``; the suite leaves
    nothing outside pytest's temp folder.

    Under xdist, each worker's torch (and the processes its tests start) gets its share of
    the cores: torch's OpenMP threads spin while they wait, so two workers of two threads each
    on two cores burn half their time without progress."""
    temp = run_folder(config._tmp_path_factory) / "tmp"  # type: ignore[attr-defined]
    temp.mkdir(exist_ok=True)
    os.environ["TMPDIR"] = str(temp)
    tempfile.tempdir = None  # read TMPDIR again
    workers = getattr(config, "workerinput", {}).get("workercount")
    if workers:
        share = str(max(1, (os.cpu_count() or 1) // int(workers)))
        os.environ["OMP_NUM_THREADS"] = share
        torch.set_num_threads(int(share))


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Tests marked `quiet` first (their wait for the other workers is shortest before those
    are deep in long tests), the rest in file order: the slow protocol tests of tests/bench/
    then share one worker's part, which keeps the run's disk peak at 2.7-2.9 GB (started
    together on every worker they wrote 4.5 GB of checkpoints, for no gain in time). Tests
    marked `gpu` skip, with their reason, where torch sees no GPU."""
    if not torch.cuda.is_available():
        for item in items:
            if item.get_closest_marker("gpu"):
                item.add_marker(pytest.mark.skip(reason="needs a GPU: torch sees none"))
    items.sort(key=lambda item: item.get_closest_marker("quiet") is None)


# --------------------------------------------------------------------------- a quiet machine
# A test marked `quiet` needs the machine to itself: it times the machine (a budget's
# calibration against busy loops, whose quiet side must be quiet), or it starts a local Ray,
# whose start-up beside busy workers takes up to 8 times as long. Under xdist it runs while
# the other workers wait. Every other test holds a shared lock while it runs (set-up and
# teardown included); a quiet one takes it exclusively. The gate keeps new shared holders out
# while a quiet test waits, so it is not starved.


@contextlib.contextmanager
def _machine_share(item: pytest.Item) -> Iterator[None]:
    if not os.environ.get("PYTEST_XDIST_WORKER"):
        yield
        return
    folder = run_folder(item.config._tmp_path_factory)  # type: ignore[attr-defined]
    quiet = item.get_closest_marker("quiet") is not None
    with open(folder / "quiet.gate", "a") as gate, open(folder / "quiet.lock", "a") as lock:
        fcntl.flock(gate, fcntl.LOCK_EX)
        try:
            fcntl.flock(lock, fcntl.LOCK_EX if quiet else fcntl.LOCK_SH)
        finally:
            if not quiet:
                fcntl.flock(gate, fcntl.LOCK_UN)
        try:
            yield
        finally:
            fcntl.flock(lock, fcntl.LOCK_UN)
            fcntl.flock(gate, fcntl.LOCK_UN)


@pytest.hookimpl(wrapper=True)
def pytest_runtest_protocol(item: pytest.Item, nextitem: pytest.Item | None) -> Iterator[None]:
    with _machine_share(item):
        return (yield)


@pytest.fixture(scope="session", autouse=True)
def shared_artefacts_stay_unchanged() -> Iterator[None]:
    """Fail the run when a test changed a shared artefact (tests/artefacts.py) in place."""
    yield
    changed = changed_artefacts()
    assert not changed, f"a test changed shared artefacts; copy one before changing it: {changed}"


@pytest.hookimpl(wrapper=True)
def pytest_sessionfinish(session: pytest.Session, exitstatus: int) -> Iterator[None]:
    """Fail the run when a process it started outlives it (a pool worker, a resource
    tracker, a Ray process): `make test` must leave nothing behind. Under xdist the controller
    checks, once every other hook (xdist's, which stops the workers) has run."""
    from multiprocessing import resource_tracker

    result = yield
    if hasattr(session.config, "workerinput"):  # an xdist worker: its controller checks
        return result
    # This process's own resource tracker ends with it by design (its pipe closes); stop it
    # now so that what remains is what would really outlive the run.
    resource_tracker._resource_tracker._stop()
    me = os.getpid()
    left = wait_until_gone(
        lambda: strays_since(start_ticks(me), exclude=ancestors(me)), seconds=15.0
    )
    if left:
        print("\nprocesses started by the test run are still alive:\n  " + "\n  ".join(left))
        session.exitstatus = pytest.ExitCode.TESTS_FAILED
    return result
