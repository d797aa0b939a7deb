"""Executors: the same bytes whatever runs the rooms (local pool, Ray, worker count, hash seed)."""

from __future__ import annotations

import hashlib
import os
import subprocess
import sys
from pathlib import Path

import pytest

from sgdata.errors import ConfigError
from sgdata.pipeline.config import load_config
from sgdata.pipeline.executors import die_with_parent, executor_session, run_tasks
from sgdata.pipeline.generate import generate_dataset
from sgdata.pipeline.ledger import LEDGER


def digest_tree(root: Path) -> dict[str, str]:
    return {
        p.relative_to(root).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(root.rglob("*"))
        if p.is_file() and LEDGER not in p.parts
    }


@pytest.mark.parametrize("hash_seed", ["1", "2"])
def test_hash_seed_and_one_worker_give_the_same_bytes(
    tmp_path: Path, mini_dataset: Path, mini_config_file: Path, hash_seed: str
) -> None:
    """The mini dataset (2 workers, this process's hash seed) again with one worker under
    another PYTHONHASHSEED, through the real command: every file byte-identical."""
    root = tmp_path / "d"
    env = {**os.environ, "PYTHONHASHSEED": hash_seed}
    command = [sys.executable, "-m", "sgdata_cli.sgdata_app", "generate"]
    run = subprocess.run(
        [*command, str(mini_config_file), str(root), "--workers", "1"],
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert run.returncode == 0, run.stderr
    assert digest_tree(root) == digest_tree(mini_dataset)


# a real local Ray instance: 10 s alone, 87 s beside two busy workers (its start-up collapses)
@pytest.mark.quiet
def test_ray_executor_gives_the_same_bytes(
    tmp_path: Path, mini_dataset: Path, mini_config_file: Path
) -> None:
    root = tmp_path / "ray"
    generate_dataset(load_config(mini_config_file), root, workers=2, executor="ray")
    assert digest_tree(root) == digest_tree(mini_dataset)


def test_executor_options_are_checked() -> None:
    with pytest.raises(ConfigError, match="--executor 'dask': expected one of local, ray"):
        list(run_tasks(len, [((),)], executor="dask"))
    with pytest.raises(ConfigError, match="--address is for --executor ray"):
        list(run_tasks(len, [((),)], address="127.0.0.1:6379"))


def test_a_worker_whose_parent_is_gone_exits() -> None:
    """Armed after its parent died, a worker exits at once (the race the re-check closes)."""
    code = (
        "import sys; from sgdata.pipeline.executors import die_with_parent; "
        "die_with_parent(1); sys.exit(0)"
    )
    done = subprocess.run([sys.executable, "-c", code], timeout=60)
    assert done.returncode == 1  # its parent is not pid 1
    die_with_parent(os.getppid())  # our real parent: nothing happens


def test_a_session_keeps_one_local_pool_across_calls_and_nested_sessions() -> None:
    """Inside a session every run_tasks call (a nested session's too) runs in the same
    spawned worker; outside one, each call starts its own, gone when the call ends."""
    with executor_session(workers=1):
        first = list(run_tasks(os.getpid, [()], workers=1))
        with executor_session(workers=1):
            nested = list(run_tasks(os.getpid, [()], workers=1))
        second = list(run_tasks(os.getpid, [()], workers=1))
        other = list(run_tasks(os.getpid, [(), ()], workers=2))  # another size: its own pool
    alone = list(run_tasks(os.getpid, [()], workers=1))
    assert first == nested == second and os.getpid() not in first
    assert set(other).isdisjoint(first) and alone != first
    assert not any(Path(f"/proc/{pid}").exists() for pid in first + other + alone)
