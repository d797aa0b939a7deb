"""sgdata generate end to end: determinism, composition, resumability, refusals."""

from __future__ import annotations

import hashlib
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import duckdb
import polars as pl
import pyarrow.parquet as pq
import pytest

from sgdata.dataset import Dataset
from sgdata.errors import ConfigError, DatasetError
from sgdata.pipeline.config import load_config
from sgdata.pipeline.generate import LEDGER, generate_dataset
from sgdata.pipeline.room_tasks import COMMAND, OUTSIDE, stage_order
from sgdata.stage_clock import StageClock
from sgdata.world.triplets import tier_counts


def digest_tree(root: Path) -> dict[str, str]:
    """sha256 of every file a dataset consists of (the ledger excluded)."""
    return {
        p.relative_to(root).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(root.rglob("*"))
        if p.is_file() and LEDGER not in p.parts
    }


def test_neither_worker_count_nor_profiling_changes_bytes(
    tmp_path: Path, mini_dataset: Path, mini_config_file: Path
) -> None:
    other, clock = tmp_path / "one", StageClock()
    generate_dataset(load_config(mini_config_file), other, workers=1, clock=clock)
    assert digest_tree(other) == digest_tree(mini_dataset)
    # every room task timed itself in its worker and sent its clock back
    rows = {(r["phase"], r["stage"]): r for r in clock.rows(stage_order())}
    rooms = sum(len(r) for r in Dataset.open(other).manifest.splits.values())
    assert rows[("scenes", "ledger")]["calls"] == rows[("views", "ledger")]["calls"] == rooms
    views = sum(pq.read_metadata(p).num_rows for p in (other / "observations").rglob("*.parquet"))
    assert rows[("views", "render")]["calls"] == views
    assert list(rows) == [k for k in rows if k[1] in stage_order()[k[0]]]  # known, in order
    # the command's own steps, each once, the task phases' wall among them; with one worker
    # a task phase's worker time (its tasks' stages and the time outside them) is its wall
    steps = {s: r for (p, s), r in rows.items() if p == COMMAND}
    assert set(steps) == {"inputs", "scenes", "triplets", "views", "manifest", "other"}
    assert all(r["calls"] == 1 for r in steps.values())
    for phase in ("scenes", "views"):
        worker = sum(r["seconds"] for (p, _), r in rows.items() if p == phase)
        assert rows[(phase, OUTSIDE)]["seconds"] >= 0
        assert worker == pytest.approx(steps[phase]["seconds"], rel=0.05, abs=0.05)


def test_composition_and_offsets(mini_triplets: dict[str, int], mini_dataset: Path) -> None:
    dataset = Dataset.open(mini_dataset)
    for split, total in mini_triplets.items():
        triplets = dataset.triplets(split).to_pylist()
        tiers = [sum(t["tier"] == k for t in triplets) for k in range(5)]
        assert tiers == tier_counts(total)
        obs = {r["obs_id"]: r for r in dataset.observations(split).to_pylist()}
        for t in triplets:
            a, p, n = obs[t["anchor"]], obs[t["positive"]], obs[t["negative"]]
            assert a["room_id"] == p["room_id"] == n["room_id"] == t["room_id"]
            assert a["split"] == p["split"] == n["split"] == split
            for other, offset in ((p, t["positive_offset"]), (n, t["negative_offset"])):
                alpha = other["grid_i"] - a["grid_i"]
                beta = other["grid_j"] - a["grid_j"]
                gamma = (other["heading"] - a["heading"]) % 4
                assert (alpha, beta, gamma) == (offset[0], offset[1], offset[2] % 4)
            if t["tier"] == 0:
                assert p["layout"] != a["layout"]


def test_standard_tools_read_it(mini_triplets: dict[str, int], mini_dataset: Path) -> None:
    shard = next((mini_dataset / "observations" / "train").glob("*.parquet"))
    table = pq.read_table(shard)
    assert table.num_rows > 0
    frame = pl.read_parquet(shard)
    assert frame.height == table.num_rows
    count = duckdb.sql(
        f"SELECT count(*) FROM read_parquet('{shard}') AS o, unnest(o.objects) AS u(obj)"
    ).fetchall()[0][0]
    assert count == sum(len(objs) for objs in table.column("objects").to_pylist())
    tiers = duckdb.sql(
        f"SELECT tier, count(*) FROM '{mini_dataset / 'triplets' / 'train.parquet'}' GROUP BY tier"
    ).fetchall()
    assert sum(n for _, n in tiers) == mini_triplets["train"]


def test_refuses_to_overwrite(mini_dataset: Path, mini_config_file: Path, tmp_path: Path) -> None:
    config = load_config(mini_config_file)
    with pytest.raises(ConfigError, match="holds a finished dataset; pass --force"):
        generate_dataset(config, mini_dataset)
    a_file = tmp_path / "file"
    a_file.write_text("x")
    with pytest.raises(ConfigError, match="is a file"):
        generate_dataset(config, a_file)


def test_write_error_then_resume(
    tmp_path: Path, mini_dataset: Path, mini_config_file: Path
) -> None:
    config = load_config(mini_config_file)
    root = tmp_path / "broken"
    (root / "observations").mkdir(parents=True)
    (root / "observations" / "test").write_text("a file where a directory must go")
    with pytest.raises(DatasetError, match="cannot write"):
        generate_dataset(config, root)
    assert not (root / "dataset.json").exists()
    with pytest.raises(ConfigError, match="unfinished generation; pass --resume"):
        generate_dataset(config, root)
    (root / "observations" / "test").unlink()
    generate_dataset(config, root, resume=True)
    assert digest_tree(root) == digest_tree(mini_dataset)


def test_resume_with_another_config_is_refused(tmp_path: Path, mini_config_file: Path) -> None:
    root = tmp_path / "d"
    (root / LEDGER).mkdir(parents=True)
    (root / LEDGER / "config.json").write_text("{}")
    with pytest.raises(ConfigError, match="another config"):
        generate_dataset(load_config(mini_config_file), root, resume=True)


@pytest.mark.slow  # generate killed mid-run with each executor, then resumed to the same bytes
@pytest.mark.parametrize(
    "executor",
    # ray: a local Ray instance started, killed with the run and started again for the resume;
    # quiet, as Ray's start-up beside two busy workers takes 2-8 times as long
    ["local", pytest.param("ray", marks=pytest.mark.quiet)],
)
def test_sigkill_mid_run_then_resume(
    tmp_path: Path,
    mini_dataset: Path,
    mini_config_file: Path,
    procs,
    executor: str,  # noqa: ANN001
) -> None:
    """A real `sgdata generate` process killed with SIGKILL after its first finished room
    takes every process of the run with it (workers, resource tracker, Ray); resumed, it
    gives the same dataset as an uninterrupted run."""
    root = tmp_path / "killed"
    command = [
        sys.executable,
        "-m",
        "sgdata_cli.sgdata_app",
        "generate",
        str(mini_config_file),
        str(root),
        "--workers",
        "2",
    ]
    process = subprocess.Popen(
        [*command, "--executor", executor],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        start_new_session=True,  # its own process group: everything it starts is findable
    )
    deadline = time.monotonic() + 240
    while not list((root / LEDGER).glob("views-*.json")):
        assert process.poll() is None, process.stderr.read().decode() if process.stderr else ""
        assert time.monotonic() < deadline, "no room finished in time"
        time.sleep(0.05)
    os.kill(process.pid, signal.SIGKILL)
    process.wait()
    # the run's session holds everything it started (its pool workers, the resource tracker,
    # Ray's processes), wherever they were re-parented
    assert procs.wait_until_gone(lambda: procs.in_session(process.pid)) == []
    assert not (root / "dataset.json").exists()
    resumed = subprocess.run([*command, "--resume"], capture_output=True, text=True, timeout=600)
    assert resumed.returncode == 0, resumed.stderr
    assert digest_tree(root) == digest_tree(mini_dataset)


def test_a_worker_dead_of_a_signal_is_one_line_then_resume(
    tmp_path: Path, mini_dataset: Path, mini_config_file: Path, procs
) -> None:
    """A pool worker killed with SIGSEGV (what a crash in the GL driver looks like) ends the
    run in one line naming the worker, the signal and its room; --resume finishes it with
    the same bytes. One worker, so that it is rendering the second room when it is killed."""
    root = tmp_path / "crashed"
    command = [sys.executable, "-m", "sgdata_cli.sgdata_app", "generate"]
    command += [str(mini_config_file), str(root), "--workers", "1"]
    process = subprocess.Popen(
        command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, start_new_session=True
    )
    deadline = time.monotonic() + 240
    while not list((root / LEDGER).glob("views-*.json")):
        assert process.poll() is None, process.stderr.read().decode() if process.stderr else ""
        assert time.monotonic() < deadline, "no room finished in time"
        time.sleep(0.05)
    (worker,) = [p for p in procs.in_session(process.pid) if b"spawn_main" in _cmdline(p)]
    os.kill(worker, signal.SIGSEGV)
    _, stderr = process.communicate(timeout=120)
    lines = stderr.decode().strip().splitlines()
    assert process.returncode == 2, stderr
    assert len(lines) == 1, stderr
    assert re.search(
        rf"error: worker {worker} died of SIGSEGV while on room bathroom_\d+; rerun with --resume$",
        lines[0],
    ), lines[0]
    assert procs.wait_until_gone(lambda: procs.in_session(process.pid)) == []
    resumed = subprocess.run([*command, "--resume"], capture_output=True, text=True, timeout=600)
    assert resumed.returncode == 0, resumed.stderr
    assert digest_tree(root) == digest_tree(mini_dataset)


def _cmdline(pid: int) -> bytes:
    try:
        return Path(f"/proc/{pid}/cmdline").read_bytes()
    except OSError:
        return b""
