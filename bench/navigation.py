"""docs/navigation.md as code: make the navigation runs, then write its tables from them.

    python bench/navigation.py run DATA OUT --localizer RUN [--localizer RUN ...]
        [--pairs 20000] [--val-pairs 2000] [--image-size 96] [--epochs 10] [--episodes 20]
        [--workers 2] [--encoder resnet18] [--pretrained imagenet-lite0] [--cross-layout 0.5]
        [--jitter 0.2]
    python bench/navigation.py tables [OUT] [-o docs/navigation.md]

``run`` records what made the runs (commit, command, dataset manifest sha256 and format
version) in ``OUT/provenance.json``, trains the navigator into ``OUT/navigator`` (pairs cached
in ``OUT/navigator_pairs``; skipped once trained) and runs ``seannet navigate`` of every
localizer on the test rooms under the paper's rule and ``--replan`` into ``OUT/navigate``
(it resumes where a killed run stopped).

``tables`` rewrites the blocks of docs/navigation.md between ``<!-- bench/navigation.py: NAME
-->`` and ``<!-- end NAME -->``: ``paper`` (the paper's Table II) always, ``measured`` from
``OUT`` when given. No figure in them is typed by hand.
"""

from __future__ import annotations

import argparse
import json
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "bench"))

from results import provenance  # noqa: E402  (bench/results.py: one home for provenance)

import seannet  # noqa: E402,F401  (imports torch's compiler stack first: see tests/conftest.py)
from seannet.navigation.navigate import run_navigation  # noqa: E402
from seannet.navigation.navigator import NavigatorConfig  # noqa: E402
from seannet.navigation.tables import (  # noqa: E402
    RATE_HEADER,
    SPLIT_HEADER,
    TIME_HEADER,
    rate_rows,
    read_results,
    time_rows,
)
from seannet.navigation.train_navigator import train_navigator  # noqa: E402
from seannet.training.runs import BEST, HISTORY, load_checkpoint  # noqa: E402
from sgdata.fileio import atomic_write_text  # noqa: E402

SPLIT = "test"
PROVENANCE = "provenance.json"
# The paper's Table II (§VI-B): success and failure rates in percent, N / A, over
# 5,476 N and 204,136 A cases in 20 test rooms.
PAPER_CASES = (5476, 204136)
PAPER_TABLE_II = {
    "SeanNet": ((80.2, 65.2), (2.4, 6.2), (13.2, 21.7), (4.1, 6.8)),
    "ResNet-50": ((29.0, 3.4), (0.3, 0.5), (70.2, 95.2), (0.4, 0.9)),
    "ResNeXt-50": ((26.0, 14.5), (0.6, 0.48), (72.8, 84.7), (0.7, 0.3)),
    "VGG-16": ((62.3, 20.1), (0.7, 1.8), (35.5, 74.2), (1.5, 3.9)),
    "GoogLeNet": ((69.4, 30.6), (1.8, 3.3), (25.5, 58.8), (3.3, 7.3)),
}


def run(args: argparse.Namespace) -> None:
    out: Path = args.out
    out.mkdir(parents=True, exist_ok=True)
    atomic_write_text(out / PROVENANCE, json.dumps(provenance(args.data, sys.argv), indent=2))
    config = NavigatorConfig(
        encoder=args.encoder,
        image_size=args.image_size,
        epochs=args.epochs,
        train_pairs=args.pairs,
        val_pairs=args.val_pairs,
        cross_layout=args.cross_layout,
        jitter=args.jitter,
    )
    navigator = out / "navigator"
    if not (navigator / BEST).is_file():
        cache = out / "navigator_pairs"
        train_navigator(config, args.data, navigator, cache=cache, pretrained=args.pretrained)
    run_navigation(
        args.localizer,
        navigator,
        args.data,
        split=SPLIT,
        episodes=args.episodes,
        replan=True,
        workers=args.workers,
        out=out / "navigate",
        progress=lambda text: print(text, flush=True),
    )


def _table(header: list[str], rows: list[list[str]]) -> list[str]:
    return [
        "| " + " | ".join(header) + " |",
        "|" + "---|" * len(header),
        *("| " + " | ".join(r) + " |" for r in rows),
    ]


def paper_rows() -> list[list[str]]:
    """The paper's Table II in the measured tables' columns."""
    return [
        [f"paper, {name}", f"{PAPER_CASES[0]:,} / {PAPER_CASES[1]:,}"]
        + [f"{n} / {a}" for n, a in rates]
        for name, rates in PAPER_TABLE_II.items()
    ]


def measured_block(out: Path) -> str:
    """The tables of ``out``'s runs, stamped with what made them."""
    made = json.loads((out / PROVENANCE).read_text())
    results = read_results(out / "navigate" / f"navigate_{SPLIT}.json")
    history = json.loads((out / "navigator" / HISTORY).read_text())
    state = load_checkpoint(out / "navigator" / BEST)
    config = state["config"]
    init = f"ImageNet init {state['pretrained']}" if state.get("pretrained") else "random init"
    best = max(history, key=lambda h: h["val_accuracy"])
    dirty = " with uncommitted changes" if made["dirty"] else ""
    lines = [
        f"Made {made['started']} by commit `{made['commit'][:12]}`{dirty} on `{made['data']}` "
        f"(manifest sha256 `{made['manifest_sha256'][:16]}`, format {made['format_version']}): "
        f"`{made['command']}`.",
        "",
        f"Navigator: {best['train_pairs']:,} train pairs at {config['image_size']} px, "
        f"{config['encoder']} ({init}), goals of another layout "
        f"{100 * config.get('cross_layout', 0.0):.0f} %, light jitter ±"
        f"{100 * config.get('jitter', 0.0):.0f} %; best epoch {best['epoch'] + 1} of "
        f"{len(history)}, val accuracy "
        f"{100 * best['val_accuracy']:.1f} % on {best.get('val_pairs', 0):,} val pairs.",
    ]
    for part, what in (("val_by_action", "action"), ("val_by_distance", "goal distance, cells")):
        cells = [f"{k} {100 * a:.1f} % ({n})" for k, (a, n) in best.get(part, {}).items()]
        if cells:
            lines.append(f"Val accuracy by {what}: " + ", ".join(cells) + ".")
    episodes = results["episodes_per_case_and_room"]
    lines += [
        "",
        f"{episodes} episodes per case and room, the same for every localizer (seed "
        f"{results['seed']}); each cell: percent [Wilson 95 % interval], N / A.",
        "",
        "The paper's rule (a collision ends the episode), beside the paper's Table II:",
        "",
        *_table(RATE_HEADER, paper_rows() + rate_rows(results, "paper")),
        "",
        *_table(SPLIT_HEADER, rate_rows(results, "paper", split=True)),
    ]
    if results.get("replan"):
        lines += [
            "",
            "Bump and replan (beyond the paper):",
            "",
            *_table(RATE_HEADER, rate_rows(results, "replan")),
            "",
            *_table(SPLIT_HEADER, rate_rows(results, "replan", split=True)),
        ]
    lines += ["", "Time per episode:", "", *_table(TIME_HEADER, time_rows(results))]
    return "\n".join(lines)


def replace_block(text: str, name: str, body: str) -> str:
    """``text`` with the block ``name`` holding ``body``.

    Raises:
        SystemExit: the document has no such block.
    """
    begin, end = f"<!-- bench/navigation.py: {name} -->", f"<!-- end {name} -->"
    pattern = re.compile(re.escape(begin) + r".*?" + re.escape(end), re.S)
    if not pattern.search(text):
        raise SystemExit(f"no block {begin} ... {end} in the document")
    return pattern.sub(lambda _: f"{begin}\n{body}\n{end}", text)


def write_tables(out: Path | None, doc: Path) -> None:
    """Rewrite ``doc``'s ``paper`` block, and its ``measured`` block from ``out`` if given."""
    text = replace_block(doc.read_text(), "paper", "\n".join(_table(RATE_HEADER, paper_rows())))
    if out is not None:
        text = replace_block(text, "measured", measured_block(out))
    atomic_write_text(doc, text)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="verb", required=True)
    go = sub.add_parser("run", help="make the runs")
    go.add_argument("data", type=Path)
    go.add_argument("out", type=Path)
    go.add_argument("--localizer", type=Path, action="append", required=True)
    go.add_argument("--pairs", type=int, default=20000)
    go.add_argument("--val-pairs", type=int, default=2000)
    go.add_argument("--image-size", type=int, default=96)
    go.add_argument("--epochs", type=int, default=10)
    go.add_argument("--encoder", default="resnet18")
    go.add_argument("--pretrained", type=Path, help="ImageNet init, e.g. imagenet-lite0")
    go.add_argument("--cross-layout", type=float, default=0.0)
    go.add_argument("--jitter", type=float, default=0.0)
    go.add_argument("--episodes", type=int, default=20)
    go.add_argument("--workers", type=int, default=2)
    tables = sub.add_parser("tables", help="write docs/navigation.md's tables")
    tables.add_argument("out", type=Path, nargs="?")
    tables.add_argument("-o", "--output", type=Path, default=ROOT / "docs" / "navigation.md")
    args = parser.parse_args(argv)
    if args.verb == "run":
        run(args)
    else:
        write_tables(args.out, args.output)


if __name__ == "__main__":
    main()
