"""A worker's memory and threads do not grow with the rooms it renders. One worker renders
12 rooms: its threads (native ones included) after each room are those after the first (its
renderer and its encoding thread are made once), and its peak memory after the twelfth is
within 12 MiB of its peak after the third (each room's views, meshes and textures are let go
before the next room). Without a leak the peak grows ~7 MiB over those 9 rooms (the
allocator, shape caches), so a leak of 2 MiB a room fails it; smaller ones hide in that noise
(keeping every layout's meshes adds ~1 MiB a room)."""

from __future__ import annotations

from pathlib import Path

from sgdata.pipeline.config import load_config
from sgdata.pipeline.generate import GenerateProgress, generate_dataset

# 12 rooms of two types, ~18 views each at 128 px
TOML = """\
[dataset]
name = "memory"
seed = 3
[rooms]
types = ["kitchen", "bathroom"]
train = 6
val = 0
test = 0
[layouts]
count = 2
[camera]
width = 128
height = 128
[triplets]
train = 72
val = 0
test = 0
[appearance]
texture_size = 128
"""


def test_a_workers_memory_and_threads_are_flat_across_rooms(tmp_path: Path) -> None:
    config = tmp_path / "memory.toml"
    config.write_text(TOML)
    peaks: list[float] = []
    threads: list[int] = []
    origins: list[dict[str, int]] = []
    switches: list[tuple[int, int]] = []

    def progress(step: GenerateProgress) -> None:
        if step.phase == "views":
            peaks.append(step.worker_peak_mib)
            threads.append(step.worker_threads)
            origins.append(step.worker_threads_by_origin)
            switches.append(step.worker_context_switches)

    generate_dataset(load_config(config), tmp_path / "data", workers=1, progress=progress)
    assert len(peaks) == 12
    assert all(peak > 50 for peak in peaks)  # a real process's figure (MiB), not a default
    after_3, after_12 = peaks[2], peaks[-1]
    assert after_12 - after_3 < 12.0, peaks
    assert threads[0] > 1 and threads == [threads[0]] * 12, threads
    # by origin: the same pools after every room, and they add up to the kernel's count
    assert origins == [origins[0]] * 12 and sum(origins[0].values()) == threads[0], origins
    assert origins[0]["MainThread"] == 1, origins[0]
    assert origins[0]["sgdata-encode"] == origins[0]["sgdata-read"] == 1, origins[0]
    # context switches only grow, and rendering twelve rooms takes some
    assert all(b[0] >= a[0] and b[1] >= a[1] for a, b in zip(switches, switches[1:], strict=False))
    assert sum(switches[-1]) > sum(switches[0]) > 0, switches
