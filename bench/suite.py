"""docs/benchmarks.md as code: run the benchmark scripts, keep what each printed, write the page.

    .venv/bin/python bench/suite.py run OUT                 # the suite, then the page (~15 min)
    .venv/bin/python bench/suite.py run OUT --rooms 24 --views 30 --validate out/results \\
        --extras channels,assets,fuzz                       # and the scripts the suite skips
    .venv/bin/python bench/suite.py page OUT                # the page again from OUT

``run`` runs each measure in a fresh process, one after the other, and keeps its figures in
``OUT/<measure>.json`` with a stamp taken when the measure started: commit and dirty flag,
the machine (CPU, cores, memory, GPU), the load average, the date (UTC), and the command.
Every script's figures are its own machine-readable output (``--json``; the loader's table as
it printed it). ``page`` writes docs/benchmarks.md atomically from those files and nothing
else: no figure in it is typed by hand. A measure with no file in ``OUT`` is listed with the
command that measures it; figures measured before the page was generated live, dated and
fingerprinted, in :data:`OLDER` (the page names its sha256 and the commits it quotes).

Measures:

- render: annotated views/s of the pipeline (merged RGB mesh + id pass + boxes, slots,
  relations) against plain pyrender (one node per object, an RGB and a SEG pass) on the same
  views of 4 generated rooms, both on one llvmpipe thread (``LP_NUM_THREADS=1``), flat and
  textured;
- generate: ``sgdata generate`` end to end on ``--rooms`` rooms with 1 and 2 local workers
  and with Ray (a local instance, 2 workers), each twice, interleaved: each one's fastest
  round, its workers' peak memory, and how far its ratios move from round to round; and
  1 worker against the render measure, run first in the same measure;
- profile: where the time of ``sgdata generate`` goes, on the same ``--rooms`` with 1 and 2
  local workers (``bench/generate.py --profile``): the command's wall time by step, each task
  phase's worker time by stage and the time outside the tasks;
- loader: ``bench/loader.py`` on a ``tiny`` dataset generated for the run;
- validate: ``sgdata validate`` on a dataset (``--validate``, default that ``tiny`` one);
- train: ``bench/train_step.py`` on that ``tiny`` one: each network docs/results.md trains,
  its step timed by the training budget's own rule and the batches ``1200`` s buy it;
- extras (``--extras``): ``bench/channels.py``, ``bench/assets.py``, ``bench/fuzz.py``,
  ``bench/tests.py`` (the test suite as README.md runs it, ``make test`` and ``make test-fast``).

``page`` keeps the section of a measure with no file in ``OUT`` as the current page has it
(its own stamp says when and at which commit it was measured), so one measure can be re-run
alone without losing the others.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import platform
import re
import shutil
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any, NamedTuple

from seannet.provenance import ProcessState
from seannet.training.step_table import step_table
from sgdata.fileio import atomic_write_text
from sgdata.markdown import table

BENCH = Path(__file__).resolve().parent
ROOT = BENCH.parent

PY = sys.executable
PAGE = ROOT / "docs" / "benchmarks.md"
# the hand-assembled page this generator replaced: its figures, each naming its commit
OLDER = ROOT / "docs" / "benchmarks-2026-12-02.md"
CORE = ("render", "generate", "profile", "loader", "validate", "train")
EXTRAS = ("channels", "assets", "fuzz", "tests")
# the ratios the project holds itself to (issue 25): aims, not measurements
AIMS = {
    "textured: pipeline/naive": ">= 2x",
    "textured/flat": ">= 0.8x",
    "2 workers / 1": ">= 1.8x",
    "1 worker / rendering alone": ">= 0.85x",
    "Ray local / local pool": ">= 0.9x",  # issue 52
    "channels / RGB only": ">= 0.85x",
    "meshes / procedural, annotated view": ">= 0.5x",
}


SETTLE_LOAD = 0.5  # per core: the 1-minute load average a measure waits for before it starts


def settle(max_s: float) -> float:
    """Wait, at most ``max_s`` seconds, for the 1-minute load average to fall to
    :data:`SETTLE_LOAD` per core, so that what the previous measure left winding down (Ray's
    processes, two generate workers) does not run on the next one's clock; the seconds
    waited."""
    limit = SETTLE_LOAD * (os.cpu_count() or 1)
    start = time.monotonic()
    while os.getloadavg()[0] > limit and time.monotonic() - start < max_s:
        time.sleep(2)
    return round(time.monotonic() - start, 1)


def machine_stamp() -> dict[str, Any]:
    """The code and the machine now: commit and dirty flag, CPU, cores, memory, GPU, the
    1-minute load average, the date (UTC)."""
    code = ProcessState.capture(ROOT)
    cpu = platform.processor() or platform.machine()
    cpuinfo = Path("/proc/cpuinfo")
    if cpuinfo.is_file():
        names = re.findall(r"^model name\s*:\s*(.+)$", cpuinfo.read_text(), re.MULTILINE)
        cpu = names[0].strip() if names else cpu
    memory = (
        os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") if hasattr(os, "sysconf") else 0
    )
    gpu = ""
    if shutil.which("nvidia-smi"):
        listed = subprocess.run(["nvidia-smi", "-L"], capture_output=True, text=True, check=False)
        gpu = "; ".join(listed.stdout.strip().splitlines())
    return {
        "commit": code.commit,
        "dirty": code.dirty,
        "cpu": cpu,
        "cores": os.cpu_count(),
        "memory_gib": round(memory / 2**30, 1),
        "gpu": gpu or "none",
        "load_average": round(os.getloadavg()[0], 2),
        "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
    }


def _last_json(stdout: str) -> Any:
    return json.loads(stdout.strip().splitlines()[-1])


def _json_lines(stdout: str) -> list[Any]:
    return [json.loads(line) for line in stdout.splitlines() if line.startswith("{")]


class Measure(NamedTuple):
    """One script the suite runs: its commands (from the arguments and a tiny dataset), how
    its output is read (parse: each command's stdout, the wall seconds of them all, the
    commands) and shown (section). A named tuple, not a dataclass: tests load this script
    without registering it as a module."""

    title: str
    commands: Callable[[argparse.Namespace, Path], list[list[str]]]
    parse: Callable[[list[str], float, list[list[str]]], Any]
    section: Callable[[Any], list[str]]
    env: dict[str, str] | None = None


def _render_commands(args: argparse.Namespace, tiny: Path) -> list[list[str]]:
    return [[PY, str(BENCH / "render.py"), "--rooms", "4", "--views", str(args.views), "--json"]]


def _render_section(r: dict[str, Any]) -> list[str]:
    rows = [
        ("pipeline, flat (annotated views/s)", f"{r['pipeline']:.1f}", ""),
        ("plain pyrender RGB + SEG, flat (views/s)", f"{r['naive']:.1f}", ""),
        ("pipeline / plain pyrender, flat", f"{r['pipeline/naive']:.2f}x", ""),
        ("pipeline, textured (annotated views/s)", f"{r['pipeline_textured']:.1f}", ""),
        ("plain pyrender, textured (views/s)", f"{r['naive_textured']:.1f}", ""),
        (
            "**pipeline / plain pyrender, textured**",
            f"**{r['textured: pipeline/naive']:.2f}x**",
            AIMS["textured: pipeline/naive"],
        ),
        ("pipeline textured / flat", f"{r['textured/flat']:.2f}x", AIMS["textured/flat"]),
    ]
    return table(("measurement", "figure", "aim"), rows)


GENERATE_RUNS = (("local, 1 worker", 1, "local"), ("local, 2 workers", 2, "local"),
                 ("Ray, 2 workers", 2, "ray"))  # fmt: skip
GENERATE_ROUNDS = 2  # each configuration twice, interleaved: one round's noise shows


def _generate_commands(args: argparse.Namespace, tiny: Path) -> list[list[str]]:
    """The render measure first (the figure end to end is held to, in the same run), then
    each configuration's rounds."""
    one = [PY, str(BENCH / "generate.py"), "--one", str(args.rooms)]
    return [
        *_render_commands(args, tiny),
        *(
            [*one, str(workers), "--executor", executor]
            for _ in range(GENERATE_ROUNDS)
            for _, workers, executor in GENERATE_RUNS
        ),
    ]


def _generate_section(result: dict[str, Any]) -> list[str]:
    """Each configuration's rounds and its fastest, with its largest rendering worker's peak
    memory once 3 rooms were rendered and at the end (flat when equal); the ratios of the
    fastest, with the range of the same ratio round by round (how far one round's noise
    moves it); 1 worker against the render measure's textured pipeline run just before."""
    runs = result["runs"]
    n = len(GENERATE_RUNS)
    rounds = [runs[k::n] for k in range(n)]  # per configuration, its rounds in order
    best = [max(r["views_per_s"] for r in rs) for rs in rounds]
    rows = [
        (
            f"{label}: {rs[0]['views']} views in " + ", ".join(f"{r['wall_s']} s" for r in rs),
            f"{b:.2f} views/s",
            " / ".join(
                f"{max(r[k] for r in rs):.0f}"
                for k in ("worker_peak_after_3_mib", "worker_peak_after_all_mib")
            ),
            _contention(rs),
            "",
        )
        for (label, _, _), rs, b in zip(GENERATE_RUNS, rounds, best, strict=True)
    ]

    def ratio(name: str, over: int, under: int) -> tuple[str, str, str, str]:
        pairs = zip(rounds[over], rounds[under], strict=True)
        each = [a["views_per_s"] / b["views_per_s"] for a, b in pairs]
        spread = f" (rounds {min(each):.2f}x to {max(each):.2f}x)" if len(each) > 1 else ""
        return f"**{name}**", f"{best[over] / best[under]:.2f}x{spread}", "", "", AIMS[name]

    rendered = result["render"]["pipeline_textured"]
    alone = [r["views_per_s"] / rendered for r in rounds[0]]
    rows += [
        ratio("2 workers / 1", 1, 0),
        ratio("Ray local / local pool", 2, 1),
        (
            f"**1 worker / rendering alone** (`bench/render.py` textured: {rendered:.1f} "
            "annotated views/s)",
            f"{best[0] / rendered:.2f}x (rounds {min(alone):.2f}x to {max(alone):.2f}x)",
            "",
            "",
            AIMS["1 worker / rendering alone"],
        ),
    ]
    header = ("run (each round's wall time)", "fastest round",
              "worker peak after 3 rooms / all (MiB)",
              "per worker: threads; context switches a view (voluntary / involuntary)",
              "aim")  # fmt: skip
    return table(header, rows)


def _contention(rounds: list[dict[str, Any]]) -> str:
    """A configuration's threads per worker (the first round's, by origin) and its context
    switches a view (each round's), or nothing for runs measured before they were counted."""
    if "context_switches_per_view" not in rounds[0]:
        return ""
    workers = rounds[0]["worker_threads_by_origin"]
    threads = " · ".join(
        f"{sum(w.values())} ({', '.join(f'{n} {c}' for n, c in w.items())})" for w in workers
    )
    switches = ", ".join(
        "{} / {}".format(*(f"{v:.0f}" for v in r["context_switches_per_view"])) for r in rounds
    )
    return f"{threads}; {switches}"


def _profile_commands(args: argparse.Namespace, tiny: Path) -> list[list[str]]:
    one = [PY, str(BENCH / "generate.py"), "--one", str(args.rooms)]
    return [[*one, str(workers), "--profile"] for workers in (1, 2)]


def _profile_section(runs: list[dict[str, Any]]) -> list[str]:
    """One row per (phase, stage) of either run: seconds and share of its phase, 1 worker
    beside 2; the command's rows are wall time, a task phase's are worker time."""
    cells: dict[tuple[str, str], list[str]] = {}
    for k, run in enumerate(runs):
        for row in run["profile"]:
            cell = f"{row['seconds']:.2f} s ({100 * row['share']:.1f} %)"
            cells.setdefault((row["phase"], row["stage"]), ["", ""])[k] = cell
    lines = [
        f"{runs[0]['views']} views of {runs[0]['rooms']} rooms: {runs[0]['wall_s']} s with 1 "
        f"worker, {runs[1]['wall_s']} s with 2 (profiled: every stage timed). Phase `command` "
        "is the command's wall time by step (`scenes` and `views`: each task phase's wall); "
        "phases `scenes` and `views` are their workers' time summed, by stage, with "
        "`outside the tasks` what no task claimed (workers starting, idle while the last "
        "rooms finish, results coming back). A worker's `USD load` is the time its main "
        "thread waited for a layout: a room's later layouts are read on a thread of their "
        "own while the one before renders (`sgdata.pipeline.layout_reader`).",
        "",
    ]
    lines += table(("phase", "stage", "1 worker", "2 workers"),
                   ([p, s, *c] for (p, s), c in cells.items()))  # fmt: skip
    if all("pipeline_share" in run for run in runs):
        shares = ", ".join(
            f"{run['workers']} worker{'s' * (run['workers'] > 1)} {run['pipeline_share']:.2f}"
            for run in runs
        )
        lines += [
            "",
            "Share of the workers' time (wall x workers) spent in the views' own pipeline "
            "(render, boxes, slots, relations, view record: what `bench/render.py` times), on "
            f"the very views generated: **{shares}**. 1.00 would be generating at the "
            "renderer's speed. Unlike the end-to-end section's ratio, no other rooms enter it; "
            "unlike it too, a renderer slowed by the worker's encoding and reading threads "
            "counts here as pipeline time, which flatters the share.",
        ]
    return lines


def _loader_commands(args: argparse.Namespace, tiny: Path) -> list[list[str]]:
    return [[PY, str(BENCH / "loader.py"), "--data", str(tiny)]]


def _text_section(text: str) -> list[str]:
    """A script's own printed table, as it printed it."""
    return ["```text", text.strip(), "```"]


def _validate_commands(args: argparse.Namespace, tiny: Path) -> list[list[str]]:
    return [[PY, "-m", "sgdata_cli.sgdata_app", "validate", str(args.validate or tiny)]]


def _validate_section(r: dict[str, Any]) -> list[str]:
    return table(("dataset", "seconds"), [(f"`{r['dataset']}`", f"{r['seconds']:.1f}")])


def _channels_commands(args: argparse.Namespace, tiny: Path) -> list[list[str]]:
    return [[PY, str(BENCH / "channels.py"), str(tiny), "--views", str(args.views), "--json"]]


def _channels_section(r: dict[str, Any]) -> list[str]:
    rates = r["views_per_s"]
    rows = [
        ("RGB only (views/s)", f"{rates['rgb']:.1f}", ""),
        ("RGB + depth + instances (views/s)", f"{rates['channels']:.1f}", ""),
        ("channels / RGB only", f"{r['ratio']:.2f}x", AIMS["channels / RGB only"]),
        *((f"PNG bytes per view, {k}", f"{v:,}", "") for k, v in r["bytes_per_view"].items()),
    ]
    return [
        f"Room `{r['room']}`, {r['views']} views, each run twice (ABAB).",
        "",
        *table(("measurement", "figure", "aim"), rows),
    ]


def _assets_commands(args: argparse.Namespace, tiny: Path) -> list[list[str]]:
    return [[PY, str(BENCH / "assets.py"), "--views", str(args.views), "--json"]]


def _assets_section(r: dict[str, Any]) -> list[str]:
    rows = [(f"`{k}`", f"{v}") for k, v in r.items() if not k.startswith("ratio_")]
    ratios = [
        (f"meshes / procedural, {k.removeprefix('ratio_')}", f"{v:.2f}x")
        for k, v in r.items()
        if k.startswith("ratio_")
    ]
    return [*table(("ratio", "figure"), ratios), "", *table(("figure", "value"), rows)]


def _train_commands(args: argparse.Namespace, tiny: Path) -> list[list[str]]:
    return [[PY, str(BENCH / "train_step.py"), str(tiny), "--json"]]


def _train_section(r: dict[str, Any]) -> list[str]:
    return [
        f"A step of {r['batch_size']} triplets of the `cpu` preset, timed the way a run's "
        f"budget is ({r['clock']}; `seannet.training.budget.calibrate`): the networks "
        f"docs/results.md trains, and the batches per epoch {r['budget_s']:g} s buy each over "
        f"{r['epochs']} epochs. A budget buys batches in inverse proportion to these steps.",
        "",
        *step_table(r["networks"]),
    ]


def _fuzz_commands(args: argparse.Namespace, tiny: Path) -> list[list[str]]:
    return [[PY, str(BENCH / "fuzz.py"), "--examples", "200", "--json"]]


def _fuzz_section(reports: list[dict[str, Any]]) -> list[str]:
    rows = [
        (
            r["surface"],
            str(r["tried"]),
            str(r["refused"]),
            str(len(r["failures"])),
            f"{r['seconds']:.0f}",
        )
        for r in reports
    ]
    return table(("surface", "tried", "refused", "failures", "seconds"), rows)


def _tests_commands(args: argparse.Namespace, tiny: Path) -> list[list[str]]:
    script = str(BENCH / "tests.py")
    return [[PY, script, "--json"], [PY, script, "--target", "test-fast", "--json"]]


def _tests_section(runs: list[dict[str, Any]]) -> list[str]:
    """Each target's wall time, outcomes and peak disk; the full suite's slowest ten."""
    rows = [
        (
            f"`make {r['target']}`",
            f"{r['wall_s']:.0f} s ({r['wall_s'] / 60:.1f} min)",
            ", ".join(f"{n} {kind}" for kind, n in sorted(r["outcomes"].items())),
            f"{r['test_seconds']:.0f} s",
            f"{r['peak_disk_mb']:,} MB",
        )
        for r in runs
    ]
    lines = table(("command", "wall time", "tests", "sum of test times", "peak disk"), rows)
    full = next((r for r in runs if r["target"] == "test"), None)
    if full:
        lines += [
            "",
            f"The slowest ten of `make {full['target']}` (set-up, call and teardown):",
            "",
            *table(
                ("test", "seconds"),
                [(f"`{c['test']}`", f"{c['seconds']:.1f}") for c in full["slowest"]],
            ),
        ]
    return lines


_LP1 = {"LP_NUM_THREADS": "1"}
MEASURES: dict[str, Measure] = {
    "render": Measure(
        "Rendering, one llvmpipe thread (`bench/render.py`)",
        _render_commands,
        lambda outs, _s, _c: _last_json(outs[0]),
        _render_section,
        env=_LP1,
    ),
    "generate": Measure(
        "`sgdata generate` end to end (`bench/generate.py`)",
        _generate_commands,
        lambda outs, _s, _c: {
            "render": _last_json(outs[0]),
            "runs": [_last_json(o) for o in outs[1:]],
        },
        _generate_section,
        env=_LP1,  # for the render measure it runs first; generate's workers set it anyway
    ),
    "profile": Measure(
        "Where the time of `sgdata generate` goes (`bench/generate.py --profile`)",
        _profile_commands,
        lambda outs, _s, _c: [_last_json(o) for o in outs],
        _profile_section,
    ),
    "loader": Measure(
        "Training dataloader (`bench/loader.py`)",
        _loader_commands,
        lambda outs, _s, _c: outs[0],
        _text_section,
    ),
    "validate": Measure(
        "`sgdata validate`",
        _validate_commands,
        lambda _outs, seconds, commands: {
            "dataset": Path(commands[0][-1]).name,
            "seconds": round(seconds, 2),
        },
        _validate_section,
    ),
    "train": Measure(
        "A training step, by the budget's rule (`bench/train_step.py`)",
        _train_commands,
        lambda outs, _s, _c: _last_json(outs[0]),
        _train_section,
    ),
    "channels": Measure(
        "Channels: depth and instance masks (`bench/channels.py`)",
        _channels_commands,
        lambda outs, _s, _c: _last_json(outs[0]),
        _channels_section,
        env=_LP1,
    ),
    "assets": Measure(
        "Objects you bring: a room of mesh files (`bench/assets.py`)",
        _assets_commands,
        lambda outs, _s, _c: _last_json(outs[0]),
        _assets_section,
        env=_LP1,
    ),
    "fuzz": Measure(
        "Fuzz campaign (`bench/fuzz.py`)",
        _fuzz_commands,
        lambda outs, _s, _c: _json_lines(outs[0]),
        _fuzz_section,
    ),
    "tests": Measure(
        "The test suite (`bench/tests.py`)",
        _tests_commands,
        lambda outs, _s, _c: [_last_json(o) for o in outs],
        _tests_section,
    ),
}


def run_measure(name: str, args: argparse.Namespace, tiny: Path, out: Path) -> dict[str, Any]:
    """Run one measure's commands, each in a fresh process; write ``out/<name>.json``
    (atomically) with the stamp taken at its start, the commands and the parsed figures."""
    measure = MEASURES[name]
    settled = settle(args.settle)
    stamp = {**machine_stamp(), "settled_s": settled}
    env = {**os.environ, **(measure.env or {})}
    commands = measure.commands(args, tiny)
    outputs, start = [], time.perf_counter()
    for command in commands:
        done = subprocess.run(command, capture_output=True, text=True, env=env, check=False)
        # fuzz exits 1 when it found a failure; tests reports the suite's own return code
        if done.returncode != 0 and name not in ("fuzz", "tests"):
            raise SystemExit(f"{name}: {' '.join(command)} failed:\n{done.stderr[-2000:]}")
        outputs.append(done.stdout)
    seconds = time.perf_counter() - start
    result = measure.parse(outputs, seconds, commands)
    record = {"measure": name, "stamp": stamp, "commands": commands, "result": result}
    out.mkdir(parents=True, exist_ok=True)
    atomic_write_text(out / f"{name}.json", json.dumps(record, indent=2))
    return record


def _stamp_line(record: dict[str, Any]) -> str:
    s = record["stamp"]
    dirty = " with uncommitted changes" if s["dirty"] else ""
    commands = "; ".join(
        "`" + " ".join(Path(c).name if c == PY else _short(c) for c in command) + "`"
        for command in record["commands"]
    )
    return (
        f"*Measured {s['date']} at commit `{s['commit'][:10]}`{dirty} on {s['cores']} x "
        f"{s['cpu']}, {s['memory_gib']} GiB, GPU {s['gpu']}, load average "
        f"{s['load_average']:.2f} at the start{_settled(s)}: {commands}.*"
    )


def _settled(stamp: dict[str, Any]) -> str:
    waited = stamp.get("settled_s", 0)
    return f" (after {waited:g} s waiting for it to settle)" if waited else ""


def _short(arg: str) -> str:
    """An argument as the page shows it: paths under the checkout relative to it."""
    try:
        return str(Path(arg).relative_to(ROOT))
    except ValueError:
        return arg


def _older_section(older: Path) -> list[str]:
    """The older page: dated, fingerprinted (sha256, the commits it quotes), its sections."""
    if not older.is_file():
        return []
    text = older.read_text(encoding="utf-8")
    digest = hashlib.sha256(text.encode("utf-8")).hexdigest()
    commits = sorted(set(re.findall(r"`([0-9a-f]{7,10})`", text)))
    sections = [line.removeprefix("## ") for line in text.splitlines() if line.startswith("## ")]
    return [
        "",
        "## Older figures",
        "",
        f"Measured before this page was generated and assembled by hand, each section naming "
        f"the commits it was measured at: [{older.name}]({older.name}) (sha256 "
        f"`{digest[:16]}…`; commits quoted: {', '.join(f'`{c}`' for c in commits)}). "
        "None of them is used above. Its sections: " + "; ".join(sections) + ".",
    ]


def _sections(text: str) -> dict[str, list[str]]:
    """A page's measure sections by title, each as its lines (title to the next section)."""
    sections: dict[str, list[str]] = {}
    title = None
    for line in text.splitlines():
        if line.startswith("## "):
            title = line.removeprefix("## ")
            sections[title] = []
        elif title is not None:
            sections[title].append(line)
    return {t: lines[:-1] if lines and not lines[-1] else lines for t, lines in sections.items()}


def page(out: Path, older: Path = OLDER, current: str = "") -> str:
    """docs/benchmarks.md from the measures' files under ``out``; a measure with no file keeps
    its section from ``current`` (the page as it stands), stamp and all."""
    kept = _sections(current)
    lines = [
        "# Benchmarks",
        "",
        "Written by `python bench/suite.py page OUT` from the figures the benchmark scripts "
        "printed (`OUT/<measure>.json`); no figure here is typed by hand. Each section says "
        "when, at which commit and on which machine (with its load average) it was measured; "
        "ratios are taken within one run. Re-run the suite to measure your machine.",
    ]
    missing = []
    for name, measure in MEASURES.items():
        path = out / f"{name}.json"
        if not path.is_file():
            if measure.title in kept:
                lines += ["", f"## {measure.title}", *kept[measure.title]]
            else:
                missing.append(name)
            continue
        record = json.loads(path.read_text())
        lines += [
            "",
            f"## {measure.title}",
            "",
            _stamp_line(record),
            "",
            *measure.section(record["result"]),
        ]
    if missing:
        lines += ["", "## Not measured in this set", ""]
        for name in missing:
            flag = f" --extras {name}" if name in EXTRAS else ""
            lines.append(f"- {MEASURES[name].title}: `python bench/suite.py run OUT{flag}`.")
    lines += _older_section(older)
    return "\n".join(lines) + "\n"


def _generate_tiny(root: Path) -> None:
    subprocess.run(
        [PY, "-m", "sgdata_cli.sgdata_app", "generate", "tiny", str(root)],
        check=True,
        capture_output=True,
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="verb", required=True)
    go = sub.add_parser("run", help="run the measures into OUT, then write the page")
    go.add_argument("out", type=Path, help="where each measure's JSON goes")
    go.add_argument("--rooms", type=int, default=24, help="rooms of the generate runs")
    go.add_argument("--views", type=int, default=30, help="views per room of the render run")
    go.add_argument("--validate", type=Path, help="dataset to validate (default: tiny)")
    go.add_argument(
        "--settle",
        type=float,
        default=120.0,
        help=f"seconds at most to wait before each measure for the load to fall to "
        f"{SETTLE_LOAD:g} per core",
    )
    go.add_argument("--only", help=f"these measures only, comma-separated ({', '.join(CORE)})")
    go.add_argument("--extras", default="", help=f"also run these ({', '.join(EXTRAS)})")
    go.add_argument("-o", "--output", type=Path, default=PAGE)
    write = sub.add_parser("page", help="write the page from OUT")
    write.add_argument("out", type=Path)
    write.add_argument("-o", "--output", type=Path, default=PAGE)
    args = parser.parse_args()
    if args.verb == "run":
        names = [
            *(args.only.split(",") if args.only else CORE),
            *filter(None, args.extras.split(",")),
        ]
        unknown = [n for n in names if n not in MEASURES]
        if unknown:
            raise SystemExit(
                f"unknown measure {', '.join(unknown)}: expected {', '.join(MEASURES)}"
            )
        with tempfile.TemporaryDirectory() as tmp:
            tiny = Path(tmp) / "tiny"
            _generate_tiny(tiny)
            for name in names:
                print(f"{name} ...", flush=True)
                run_measure(name, args, tiny, args.out)
    current = args.output.read_text(encoding="utf-8") if args.output.is_file() else ""
    atomic_write_text(args.output, page(args.out, current=current))
    print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
