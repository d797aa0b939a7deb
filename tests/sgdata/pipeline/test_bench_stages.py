"""bench/stages.py: the real room tasks, timed stage by stage, on one tiny room (EGL)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path
from types import ModuleType

from ...bench_scripts import load_bench

ROOT = Path(__file__).resolve().parents[3]
# One bathroom with 2 layouts at 64 px: what the pipeline does, in a few seconds.
TINY_TOML = """\
[dataset]
name = "stages"
[rooms]
types = ["bathroom"]
[layouts]
count = 2
[camera]
width = 64
height = 64
"""


def _bench() -> ModuleType:
    return load_bench("stages")


def test_stages_add_up_to_the_wall_time(tmp_path: Path) -> None:
    config = tmp_path / "stages.toml"
    config.write_text(TINY_TOML)
    command = [sys.executable, str(ROOT / "bench/stages.py"), "--config", str(config)]
    command += ["--rooms", "1", "--views", "4", "--png-sample", "2", "--png-levels", "1", "6"]
    env = {**os.environ, "LP_NUM_THREADS": "1"}
    out = subprocess.run([*command, "--json"], capture_output=True, text=True, env=env, check=True)
    result = json.loads(out.stdout.strip().splitlines()[-1])
    bench = _bench()

    assert (result["rooms"], result["views"], result["textures"]) == (1, 4, True)
    rows = {(s["phase"], s["stage"]): s for s in result["stages"]}
    assert list(rows) == [(phase, key) for phase, key, _ in bench.STAGES]
    assert all(s["seconds"] >= 0 and s["ms_per_view"] >= 0 for s in rows.values())
    # every stage of a view ran, in its real function, as often as the pipeline calls it
    for key in ("rgb_pass", "rgb_readback", "id_pass", "id_readback", "boxes", "encode"):
        assert rows[("views", key)]["calls"] == 4 and rows[("views", key)]["seconds"] > 0, key
    for key in ("read_room", "read_geometry", "usd_open", "scene_build", "parquet", "rows"):
        assert rows[("views", key)]["seconds"] > 0, key
    assert rows[("views", "read_geometry")]["calls"] <= 2  # once per layout rendered
    for key in ("generate_room", "write_room", "sample_layouts", "write_layout", "read_room"):
        assert rows[("scenes", key)]["seconds"] > 0, key
    # the rows are exclusive times: they add up to the wall time, named stages nearly all of it
    assert abs(sum(s["share"] for s in rows.values()) - 1) < 0.01
    assert abs(result["stages_s"] - result["wall_s"]) < 0.01 * result["wall_s"]
    assert 0.9 < result["coverage"] <= 1.0
    assert result["views_per_s"] > result["views_per_s_with_scenes"] > 0
    assert result["renderer_start_s"] > 0 and result["warm_up_views_s"] > 0

    png = result["png"]
    assert [p["level"] for p in png] == [None, 1, 6] and result["png_images"] == 2
    assert all(p["lossless"] and p["bytes"] > 0 and p["ms"] > 0 for p in png)
    assert png[0]["same_as_generator"]  # the generator's own row; a level matching it is marked

    table = bench.report(result).splitlines()
    assert "| stage | phase | total s | ms per view | share |" in table
    # header, a row per stage, wall time; the PNG table's header and a row per level
    assert sum(line.startswith("| ") for line in table) == 1 + len(bench.STAGES) + 1 + 1 + 2
    assert any(line.startswith("| level 1 |") for line in table)
