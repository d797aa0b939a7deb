"""bench/stages.py: the real room tasks time themselves stage by stage, on one tiny room (EGL)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

from sgdata.pipeline.room_tasks import COMMAND, OUTSIDE, stage_order

from ..bench_scripts import BENCH, load_bench

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


def test_stages_add_up_to_the_wall_time(tmp_path: Path) -> None:
    config = tmp_path / "stages.toml"
    config.write_text(TINY_TOML)
    command = [sys.executable, str(BENCH / "stages.py"), "--config", str(config)]
    command += ["--rooms", "1", "--views", "4", "--png-sample", "2", "--png-levels", "1", "6"]
    env = {**os.environ, "LP_NUM_THREADS": "1"}
    out = subprocess.run([*command, "--json"], capture_output=True, text=True, env=env, check=True)
    result = json.loads(out.stdout.strip().splitlines()[-1])

    assert (result["rooms"], result["views"], result["textures"]) == (1, 4, True)
    rows = {(s["phase"], s["stage"]): s for s in result["stages"]}
    # every stage the tasks name, in pipeline order, each timed where the library runs it (the
    # tasks run in this process: no command around them, no worker time outside them)
    tasks = {p: [s for s in ss if s != OUTSIDE] for p, ss in stage_order().items() if p != COMMAND}
    assert list(rows) == [(phase, s) for phase, stages in tasks.items() for s in stages]
    assert all(s["seconds"] >= 0 and s["ms_per_view"] >= 0 for s in rows.values())
    for key in ("render", "boxes", "slots", "relations", "view record"):
        assert rows[("views", key)]["calls"] == 4 and rows[("views", key)]["seconds"] > 0, key
    for key in ("USD load", "scene build", "rows + image encode", "Parquet write"):
        assert rows[("views", key)]["seconds"] > 0, key
    assert rows[("views", "USD load")]["calls"] <= 2  # once per layout rendered
    for key in ("room", "room USD", "layouts", "USD read"):
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

    table = load_bench("stages").report(result).splitlines()
    assert "| stage | phase | calls | total s | ms per view | share |" in table
    # header, a row per stage, wall time; the PNG table's header and a row per level
    assert sum(line.startswith("| ") for line in table) == 1 + len(rows) + 1 + 1 + 2
    assert any(line.startswith("| level 1 |") for line in table)
