"""docs/navigation.md as code: make the navigation runs, then write its tables from them.

    python bench/navigation.py variants DATA OUT [the run's pair options] [--subset 4800]
        [--variant-epochs 3]
    python bench/navigation.py run DATA OUT --localizer RUN [--localizer RUN ...]
        [--pairs 20000] [--val-pairs 2000] [--image-size 96] [--epochs 10] [--episodes 20]
        [--workers 2] [--encoder resnet18] [--pretrained imagenet-lite0] [--cross-layout 0.5]
        [--jitter 0.2] [--fusion early] [--full-maps DIR|- ...] [--val-epsilon]
    python bench/navigation.py epsilon DATA OUT --localizer RUN [...] [--val-episodes 10]
    python bench/navigation.py tables [OUT] [-o docs/navigation.md]

``run`` appends what made the runs (commit at process start, command, dataset manifest
sha256 and format version) to ``OUT/provenance.jsonl`` (:mod:`seannet.provenance`; the
tables' stamp names every such call), trains the navigator into ``OUT/navigator`` (pairs
cached in ``OUT/navigator_pairs``; skipped once trained) and runs ``seannet navigate`` of
every localizer on the test rooms under the paper's rule and ``--replan`` into ``OUT/navigate``
(it resumes where a killed run stopped). ``--full-maps`` derives each localizer's maps from
its spacing-1 maps instead of rendering them; ``--val-epsilon`` runs again with the stop
thresholds that ``epsilon`` chose on the val rooms, into ``OUT/navigate-val-epsilon``.

``epsilon`` chooses each localizer's stop threshold on the val rooms
(:mod:`seannet.navigation.stop_threshold`) into ``OUT/epsilon.json``.

``variants`` chooses the navigator on val before ``run``: each variant (fusion, ImageNet init,
light jitter) is trained on the same subset of ``run``'s cached train pairs (``--subset``
pairs spread over every train room) for ``--variant-epochs`` and scored on all its val pairs;
``OUT/variants.json`` holds the table.

``tables`` rewrites the blocks of docs/navigation.md between ``<!-- bench/navigation.py: NAME
-->`` and ``<!-- end NAME -->``: ``paper`` (the paper's Table II) always; ``measured``,
``variants`` and ``epsilon`` from ``OUT`` when given. No figure in them is typed by hand.
"""

from __future__ import annotations

import argparse
import json
import re
from pathlib import Path

import numpy as np

import seannet  # noqa: F401  (imports torch's compiler stack first: see tests/conftest.py)
from seannet.data.datasets import dataset_identity
from seannet.data.live_views import LiveRooms
from seannet.markdown import table
from seannet.navigation.benchmark import results_path, run_navigation, seed_maps
from seannet.navigation.config import FUSIONS, NavigationTestConfig, NavigatorConfig
from seannet.navigation.navigator_training import fit_navigator, train_navigator
from seannet.navigation.pairs import PairSet, render_pairs
from seannet.navigation.stop_threshold import (
    EPSILON_OFFSETS,
    VAL_EPISODES,
    VAL_EPSILON,
    choose_epsilon,
)
from seannet.navigation.tables import (
    EPSILON_HEADER,
    INTERVAL,
    RATE_HEADER,
    SPLIT_HEADER,
    TIME_HEADER,
    epsilon_rows,
    rate_rows,
    read_results,
    time_rows,
)
from seannet.provenance import (
    append_provenance,
    provenance_record,
    read_provenance,
    stamp,
)
from seannet.training.runs import BEST, HISTORY, load_checkpoint
from seannet.weights import LITE0_WEIGHTS
from sgdata import markdown
from sgdata.dataset import Dataset
from sgdata.errors import SgdataError
from sgdata.fileio import atomic_write_text

ROOT = Path(__file__).resolve().parents[1]

# docs/navigation.md's runs: the test's defaults, the navigator's with more pairs than the CLI's
TEST = NavigationTestConfig(replan=True)
NAVIGATOR = NavigatorConfig(train_pairs=20_000, val_pairs=2_000)
RUN_STEP = "run"  # provenance records of `run` (with VAL_SUFFIX: of `run --val-epsilon`)
NO_FULL_MAPS = "-"  # --full-maps of a localizer whose maps are to be built
VARIANTS = "variants.json"
EPSILON = "epsilon.json"
VAL_SUFFIX = "-val-epsilon"  # navigate, strips and provenance of the run with those
# navigator variants compared on val (name: config changes, ImageNet init)
NAVIGATOR_VARIANTS = {
    "resnet18, late fusion (siamese)": ({"fusion": "late"}, None),
    "resnet18, early fusion": ({"fusion": "early"}, None),
    "resnet18, early fusion, light jitter 0.2": ({"fusion": "early", "jitter": 0.2}, None),
    "lite0 ImageNet, early fusion": (
        {"fusion": "early", "encoder": "efficientnet_lite0"},
        Path(LITE0_WEIGHTS),
    ),
}
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


def navigator_config(args: argparse.Namespace) -> NavigatorConfig:
    return NavigatorConfig(
        encoder=args.encoder,
        image_size=args.image_size,
        epochs=args.epochs,
        train_pairs=args.pairs,
        val_pairs=args.val_pairs,
        cross_layout=args.cross_layout,
        jitter=args.jitter,
        fusion=args.fusion,
    )


def run(args: argparse.Namespace) -> None:
    out: Path = args.out
    out.mkdir(parents=True, exist_ok=True)
    suffix = VAL_SUFFIX if args.val_epsilon else ""
    append_provenance(out, args.data, step=RUN_STEP + suffix)
    config = navigator_config(args)
    if args.full_maps:
        if len(args.full_maps) != len(args.localizer):
            raise SystemExit("give one --full-maps per --localizer, in the same order")
        given = {
            run: source
            for run, source in zip(args.localizer, args.full_maps, strict=True)
            if str(source) != NO_FULL_MAPS
        }
        rooms = list(Dataset.open(args.data).rooms(TEST.split))
        seed_maps(args.localizer, given, rooms, out / "navigate" / "maps", spacing=TEST.spacing)
    navigator = out / "navigator"
    if not (navigator / BEST).is_file():
        cache = out / "navigator_pairs"
        train_navigator(config, args.data, navigator, cache=cache, pretrained=args.pretrained)
    epsilon = None
    if args.val_epsilon:
        chosen = json.loads((out / EPSILON).read_text())["localizers"]
        epsilon = {Path(c["run"]): (c["chosen"], VAL_EPSILON) for c in chosen}
    run_navigation(
        args.localizer,
        navigator,
        args.data,
        TEST.replace(episodes=args.episodes),
        epsilon=epsilon,
        workers=args.workers,
        out=out / f"navigate{suffix}",
        maps=out / "navigate" / "maps",  # maps do not depend on epsilon
        strips=out / f"strips{suffix}",
        progress=lambda text: print(text, flush=True),
    )


def epsilon_verb(args: argparse.Namespace) -> None:
    """Each localizer's stop threshold chosen on the val rooms
    (:func:`seannet.navigation.stop_threshold.choose_epsilon`); ``OUT/epsilon.json``."""
    out: Path = args.out
    record = choose_epsilon(
        args.localizer,
        out / "navigator",
        args.data,
        out / "epsilon",
        NavigationTestConfig(split="val", episodes=args.val_episodes),
        workers=args.workers,
        progress=lambda text: print(text, flush=True),
    )
    record = {"provenance": provenance_record(args.data, step="epsilon"), **record}
    atomic_write_text(out / EPSILON, json.dumps(record, indent=2))


def variants(args: argparse.Namespace) -> None:
    """Train each of :data:`NAVIGATOR_VARIANTS` on the same train subset; score on val."""
    out: Path = args.out
    base = navigator_config(args)
    identity = dataset_identity(args.data)
    with LiveRooms(args.data) as live:
        train_set, val_set = (
            render_pairs(live, split, count, base, cache=out / "navigator_pairs", identity=identity)
            for split, count in (("train", base.train_pairs), ("val", base.val_pairs))
        )
    subset = _spread(train_set, args.subset)
    rows = []
    for name, (changes, pretrained) in NAVIGATOR_VARIANTS.items():
        config = base.replace(epochs=args.variant_epochs, train_pairs=len(subset), **changes)
        directory = out / "variants" / re.sub(r"[^a-z0-9]+", "-", name.lower()).strip("-")
        history_file = directory / HISTORY
        if not history_file.is_file():
            fit_navigator(
                config, subset, val_set, directory, identity=identity, pretrained=pretrained
            )
        history = json.loads(history_file.read_text())
        best = max(history, key=lambda h: h["val_accuracy"])
        rows.append(
            {
                "variant": name,
                "config": config.to_dict(),
                "best_epoch": best["epoch"],
                "val_accuracy": best["val_accuracy"],
                "val_by_action": best["val_by_action"],
                "seconds_per_epoch": sum(h["seconds"] for h in history) / len(history),
            }
        )
        print(f"{name}: val {100 * best['val_accuracy']:.1f} %", flush=True)
    record = {
        "provenance": provenance_record(args.data, step="variants"),
        "train_pairs": len(subset),
        "val_pairs": len(val_set),
        "epochs": args.variant_epochs,
        "variants": rows,
    }
    atomic_write_text(out / VARIANTS, json.dumps(record, indent=2))


def _spread(pairs: PairSet, count: int) -> PairSet:
    """``count`` pairs taken evenly over ``pairs`` (so over every room)."""
    pick = np.linspace(0, len(pairs) - 1, num=min(count, len(pairs))).round().astype(int)
    return PairSet(pairs.current[pick], pairs.goal[pick], pairs.labels[pick],
                   pairs.poses[pick], pairs.rooms[pick])  # fmt: skip


def variants_block(out: Path) -> str:
    """The table of ``out/variants.json``."""
    record = json.loads((out / VARIANTS).read_text())
    made = record["provenance"]
    actions = ("forward", "left", "right")
    rows = [
        [v["variant"], f"{100 * v['val_accuracy']:.1f}"]
        + [f"{100 * v['val_by_action'][a][0]:.1f}" for a in actions]
        + [str(v["best_epoch"] + 1), f"{v['seconds_per_epoch']:.0f}"]
        for v in record["variants"]
    ]
    header = ["navigator", "val acc %", *(f"{a} %" for a in actions), "best epoch", "s / epoch"]
    return "\n".join(
        [
            stamp([made]),
            "",
            f"Each variant trained on the same {record['train_pairs']:,} train pairs for "
            f"{record['epochs']} epochs, scored on {record['val_pairs']:,} val pairs.",
            "",
            *table(header, rows),
        ]
    )


def paper_rows() -> list[list[str]]:
    """The paper's Table II in the measured tables' columns."""
    return [
        [f"paper, {name}", f"{PAPER_CASES[0]:,} / {PAPER_CASES[1]:,}"]
        + [f"{n} / {a}" for n, a in rates]
        for name, rates in PAPER_TABLE_II.items()
    ]


def measured_block(out: Path, suffix: str = "") -> str:
    """The tables of ``out``'s runs (``navigate{suffix}``), stamped with what made them."""
    made = read_provenance(out, RUN_STEP + suffix, legacy=f"provenance{suffix}.json")
    results = read_results(results_path(out / f"navigate{suffix}", TEST.split))
    history = json.loads((out / "navigator" / HISTORY).read_text())
    state = load_checkpoint(out / "navigator" / BEST)
    config = state["config"]
    init = f"ImageNet init {state['pretrained']}" if state.get("pretrained") else "random init"
    best = max(history, key=lambda h: h["val_accuracy"])
    lines = [
        stamp(made),
        "",
        f"Navigator: {best['train_pairs']:,} train pairs at {config['image_size']} px, "
        f"{config['encoder']} ({init}, {config.get('fusion', 'late')} fusion), goals of "
        f"another layout {100 * config.get('cross_layout', 0.0):.0f} %, light jitter ±"
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
        f"{results['seed']}); each cell: percent [{INTERVAL}], N / A.",
        "",
        "The paper's rule (a collision ends the episode), beside the paper's Table II:",
        "",
        *table(RATE_HEADER, paper_rows() + rate_rows(results, "paper")),
        "",
        *table(SPLIT_HEADER, rate_rows(results, "paper", split=True)),
    ]
    if results.get("replan"):
        lines += [
            "",
            "Bump and replan (beyond the paper):",
            "",
            *table(RATE_HEADER, rate_rows(results, "replan")),
            "",
            *table(SPLIT_HEADER, rate_rows(results, "replan", split=True)),
        ]
    lines += ["", "Time per episode:", "", *table(TIME_HEADER, time_rows(results))]
    lines += ["", *table(EPSILON_HEADER, epsilon_rows(results))]
    return "\n".join(lines)


def epsilon_block(out: Path) -> str:
    """The stop thresholds tried on val rooms (``OUT/epsilon.json``), then the test with the
    chosen ones."""
    record = json.loads((out / EPSILON).read_text())
    header = ["localizer", *(f"{o:+.2f}" for o in EPSILON_OFFSETS), "chosen"]
    rows = []
    for loc in record["localizers"]:
        cells = [
            f"{g['epsilon']:.3f}: {100 * g['success']['N']:.0f} / {100 * g['success']['A']:.0f}"
            for g in loc["grid"]
        ]
        rows.append([loc["label"], *cells, f"{loc['chosen']:.3f}"])
    lines = [
        stamp([record["provenance"]]),
        "",
        f"{record['episodes_per_case_and_room']} episodes per case and room on the "
        f"{record['split']} rooms, paper rule; each cell: epsilon: success % N / A. Columns: "
        "offsets from the localizer's eval epsilon; chosen: the best mean of N and A.",
        "",
        *table(header, rows),
    ]
    if results_path(out / f"navigate{VAL_SUFFIX}", TEST.split).is_file():
        lines += ["", "The test rooms with the chosen thresholds:", ""]
        lines.append(measured_block(out, VAL_SUFFIX))
    return "\n".join(lines)


def replace_block(text: str, name: str, body: str) -> str:
    """``text`` with the block ``name`` holding ``body``.

    Raises:
        SystemExit: the document has no such block, or more than one.
    """
    begin, end = f"<!-- bench/navigation.py: {name} -->", f"<!-- end {name} -->"
    try:
        return markdown.replace_block(text, begin, end, body)
    except SgdataError as error:
        raise SystemExit(str(error)) from None


def write_tables(out: Path | None, doc: Path) -> None:
    """Rewrite ``doc``'s ``paper`` block, and its ``measured`` (and ``variants``, where they
    were compared) blocks from ``out`` if given."""
    text = replace_block(doc.read_text(), "paper", "\n".join(table(RATE_HEADER, paper_rows())))
    if out is not None:
        text = replace_block(text, "measured", measured_block(out))
        if (out / VARIANTS).is_file():
            text = replace_block(text, "variants", variants_block(out))
        if (out / EPSILON).is_file():
            text = replace_block(text, "epsilon", epsilon_block(out))
    atomic_write_text(doc, text)


def _pair_options(parser: argparse.ArgumentParser) -> None:
    """What the rendered pairs depend on: the same for ``run`` and ``variants``."""
    parser.add_argument("data", type=Path)
    parser.add_argument("out", type=Path)
    parser.add_argument("--pairs", type=int, default=NAVIGATOR.train_pairs)
    parser.add_argument("--val-pairs", type=int, default=NAVIGATOR.val_pairs)
    parser.add_argument("--image-size", type=int, default=NAVIGATOR.image_size)
    parser.add_argument("--cross-layout", type=float, default=NAVIGATOR.cross_layout)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="verb", required=True)
    go = sub.add_parser("run", help="make the runs")
    choose = sub.add_parser("variants", help="compare navigator variants on val")
    stop = sub.add_parser("epsilon", help="choose each localizer's stop threshold on val rooms")
    stop.add_argument("data", type=Path)
    stop.add_argument("out", type=Path)
    stop.add_argument("--localizer", type=Path, action="append", required=True)
    stop.add_argument("--val-episodes", type=int, default=VAL_EPISODES)
    stop.add_argument("--workers", type=int, default=2)
    for verb in (go, choose):
        _pair_options(verb)
    go.add_argument("--localizer", type=Path, action="append", required=True)
    go.add_argument("--epochs", type=int, default=NAVIGATOR.epochs)
    go.add_argument("--encoder", default=NAVIGATOR.encoder)
    go.add_argument("--pretrained", type=Path, help="ImageNet init, e.g. imagenet-lite0")
    go.add_argument("--jitter", type=float, default=NAVIGATOR.jitter)
    go.add_argument("--fusion", choices=FUSIONS, default=NAVIGATOR.fusion)
    go.add_argument("--episodes", type=int, default=TEST.episodes)
    go.add_argument("--workers", type=int, default=2)
    go.add_argument(
        "--val-epsilon",
        action="store_true",
        help=f"stop thresholds of OUT/{EPSILON} (the epsilon verb) into OUT/navigate-val-epsilon",
    )
    go.add_argument(
        "--full-maps",
        type=Path,
        action="append",
        help="a spacing-1 map directory per --localizer (same order) to derive the maps from; "
        f"{NO_FULL_MAPS!r}: build that localizer's maps",
    )
    choose.add_argument("--subset", type=int, default=4800, help="train pairs per variant")
    choose.add_argument("--variant-epochs", type=int, default=3)
    choose.set_defaults(
        epochs=1, encoder=NAVIGATOR.encoder, jitter=NAVIGATOR.jitter, fusion=NAVIGATOR.fusion
    )
    tables = sub.add_parser("tables", help="write docs/navigation.md's tables")
    tables.add_argument("out", type=Path, nargs="?")
    tables.add_argument("-o", "--output", type=Path, default=ROOT / "docs" / "navigation.md")
    args = parser.parse_args(argv)
    if args.verb == "run":
        run(args)
    elif args.verb == "variants":
        variants(args)
    elif args.verb == "epsilon":
        epsilon_verb(args)
    else:
        write_tables(args.out, args.output)


if __name__ == "__main__":
    main()
