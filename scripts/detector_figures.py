"""The figures of docs/detector.md from committed evidence, never from a run folder a later
session will not have.

python scripts/detector_figures.py record --detector RUN --cards CARDS --data DATA \
        [--navigation OUT ...]
    copies the small JSON files of a detector run (curve, test scores, the val threshold
    curve, provenance), of its benchmark cards and of navigation tests run with
    ``--stop-policy`` (their stop_policy.json, true or detected graphs) into
    results/detector/<name>-<recipe>/
python scripts/detector_figures.py doc
    writes docs/detector.md's figures block from those files alone
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from seannet.markdown import pct, table
from seannet.navigation.stop_policy import STOP_POLICY
from seannet.provenance import read_provenance, stamp
from sgdata.dataset import Dataset
from sgdata.fileio import atomic_write_bytes
from sgdata.markdown import replace_block

ROOT = Path(__file__).resolve().parents[1]
RECORDS = ROOT / "results" / "detector"
DOC = ROOT / "docs" / "detector.md"
BEGIN, END = "<!-- detector-figures -->", "<!-- /detector-figures -->"
RUN_FILES = ("detector.json", "eval_test.json", "provenance.jsonl")
CASES = ("N", "A")
GRAPHS = "graphs_test.json"


def record(detector: Path, cards: Path, data: Path, navigation: tuple[Path, ...] = ()) -> Path:
    """Copy the evidence into the dataset's folder of :data:`RECORDS`; returns it."""
    ds = Dataset.open(data)
    folder = RECORDS / f"{ds.manifest.name}-{ds.manifest.recipe_fingerprint()[:16]}"
    (folder / "cards").mkdir(parents=True, exist_ok=True)
    for out in navigation:
        policy = json.loads((out / STOP_POLICY).read_text())
        graphs = "detected" if "graphs" in policy else "truth"
        _copy(out / STOP_POLICY, folder / "navigation" / f"{graphs}.json")
    for name in RUN_FILES:
        _copy(detector / name, folder / name)
    threshold = detector / "graphs" / ds.manifest_sha256[:16] / "threshold.json"
    _copy(threshold, folder / "threshold.json")
    for card in sorted(cards.glob("*/card.json")):
        _copy(card, folder / "cards" / f"{card.parent.name}.json")
    if (detector / GRAPHS).exists():  # seannet detector graphs: what the graphs lose
        _copy(detector / GRAPHS, folder / GRAPHS)
    return folder


def _copy(source: Path, target: Path) -> None:
    """Evidence is committed: a copy cut short must not leave half a file behind."""
    atomic_write_bytes(target, source.read_bytes())


def _detector_rows(folder: Path) -> list[str]:
    run = json.loads((folder / "detector.json").read_text())
    test = json.loads((folder / "eval_test.json").read_text())
    chosen = run["best_epoch"]
    curve = table(
        ("epoch", "train views seen", "loss", "val AP", "val AP50", "seconds"),
        (
            (
                e["epoch"],
                e["steps"] * run["config"]["batch_size"],
                f"{e['loss']:.3f}",
                f"{e['val_ap']:.3f}",
                f"{e['val_ap50']:.3f}" + (" (chosen)" if e["epoch"] == chosen else ""),
                f"{e['seconds']:.0f}",
            )
            for e in run["epochs"]
        ),
        right=range(1, 6),
    )
    per_class = sorted(test["ap50_per_class"].items(), key=lambda kv: kv[1])
    config = ", ".join(f"{k} {v}" for k, v in run["config"].items())
    return [
        f"**The detector**: test AP **{test['ap']:.3f}**, AP50 **{test['ap50']:.3f}** on "
        f"{test['views']} test views (pycocotools; aim: AP50 >= 0.7, missed). It trained "
        f"{run['seconds'] / 60:.0f} min on two cores and stopped by {run['stopped']} ({config}).",
        "",
        *curve,
        "",
        "AP50 per class on test: the five lowest "
        + ", ".join(f"{n} {v:.2f}" for n, v in per_class[:5])
        + "; the five highest "
        + ", ".join(f"{n} {v:.2f}" for n, v in per_class[-5:])
        + f" ({len(per_class)} classes with a test box).",
    ]


def _localizer_rows(folder: Path) -> list[str]:
    threshold = json.loads((folder / "threshold.json").read_text())
    rows = []
    for path in sorted((folder / "cards").glob("*.json")):
        card = json.loads(path.read_text())
        summary = card["summary"]
        truth, recall = summary["accuracy"]["mean"], summary["recall1"]["mean"]
        # a method that reads no box has no sweep: its figures are the same on any graph
        if summary.get("box_noise") is None:
            same = "reads no graph"
            rows.append((f"`{card['method']}`", pct(truth), same, "-", pct(recall), same, "-"))
            continue
        noise = {n["label"]: n for n in summary["box_noise"]}
        detected = next((v for k, v in noise.items() if k.startswith("detected-")), {})
        accuracy = detected.get("accuracy")
        rows.append(
            (
                f"`{card['method']}`",
                pct(truth),
                pct(accuracy),
                "-" if accuracy is None else f"{100 * (accuracy - truth):+.1f}",
                pct(recall),
                pct(detected.get("recall1")),  # cards made before the sweep kept it lack it
                pct(noise.get("S0.05-P0-Q0", {}).get("accuracy")),
            )
        )
    f1 = threshold["val_f1"][f"{threshold['threshold']:g}"]
    return [
        f"**The localizers** on the test views, with the generator's graphs and with the "
        f"detector's (score >= {threshold['threshold']:g}, chosen on val: F1 {f1:.2f}), %: "
        "triplet accuracy, and recall@1 of each view of another layout among the map "
        "layout's views (the map's graphs detected too); one seed each, trained on true graphs:",
        "",
        *table(
            (
                "method",
                "triplets, true",
                "triplets, detected",
                "points",
                "R@1, true",
                "R@1, detected",
                "triplets, jitter S 0.05",
            ),
            rows,
            right=range(1, 7),
        ),  # fmt: skip
    ]


def _fidelity_rows(folder: Path) -> list[str]:
    """What the detected graphs lose against the generator's, when it was recorded."""
    if not (folder / GRAPHS).exists():
        return []
    found = json.loads((folder / GRAPHS).read_text())
    objects, lifting, relations = found["objects"], found["lifting"], found["relations"]
    rows = [("true objects found (IoU 0.5, same class)", pct(objects["recall"]))]
    for group, what in (("by_size", "{} objects"), ("by_dynamics", "dynamics {}")):
        rows += [(f"- {what.format(name)} ({row['true']:,})", pct(row["recall"]))
                 for name, row in objects[group].items()]  # fmt: skip
    centre = lifting["centre_error_m"]
    rows += [
        ("graph objects that are true", pct(objects["precision"])),
        ("3D box centre error, median / p90 (m)",
         "-" if centre["median"] is None else f"{centre['median']:.2f} / {centre['p90']:.2f}"),
        ("true relations with both objects found", pct(relations["with_both_ends"])),
        ("- of those, kept (same type, same direction)", pct(relations["kept_of_those"])),
        *((f"- {name} ({row['true']:,}), kept", pct(row["kept_of_those"]))
          for name, row in relations["by_type"].items()),
    ]  # fmt: skip
    return [
        f"**What the detected graphs lose** on the {found['views']:,} {found['split']} views "
        f"(`seannet detector graphs`, score >= {found['threshold']:g}), %:",
        "",
        *table(("measure", "value"), rows, right=(1,)),
    ]


def _navigation_rows(folder: Path) -> list[str]:
    """True against detected graphs in the navigation test, when both were recorded."""
    found = {p.stem: json.loads(p.read_text()) for p in (folder / "navigation").glob("*.json")}
    if not found:
        return []
    rows = []
    for graphs in ("truth", "detected"):
        if graphs not in found:
            continue
        (run,) = found[graphs]["runs"]
        choice = run["choice"]
        names = {
            "paper": "paper (S > ε), eval ε",
            "paper_val": f"paper, ε chosen on val ({choice.get('paper_label')})",
            "chosen": f"chosen on val ({choice['label']})",
        }
        for rule, name in names.items():
            rates = run["test"].get(rule)
            if rates is None:  # a record made before the row existed
                continue
            rows.append((
                f"`{run['model']}`", graphs, name,
                *(_rate(rates[case]["success"]) for case in CASES),
                *(_rate(rates[case]["localization"]) for case in CASES),
            ))  # fmt: skip
    any_run = next(iter(found.values()))
    episodes = any_run["test"]["episodes_per_case_and_room"]
    made = [f"{graphs}: {found[graphs]['made']}" for graphs in ("truth", "detected")
            if graphs in found]  # fmt: skip
    return [
        f"**Navigation** on the test rooms ({episodes} episodes per case and room, navigator "
        f"`{any_run['navigator']}`), success and localization failures (%, 95 % interval "
        "clustered by room), one seed:",
        "",
        *table(
            (
                "localizer",
                "graphs",
                "stop rule",
                "N success",
                "A success",
                "N localization",
                "A localization",
            ),
            rows,
            right=range(3, 7),
        ),  # fmt: skip
        "",
        *(f"- {line}" for line in made),
    ]


def _rate(cell: dict) -> str:
    return f"{cell['percent']:.1f} [{cell['low']:.0f}, {cell['high']:.0f}]"


def doc() -> str:
    """The figures block from every dataset folder of :data:`RECORDS`."""
    parts = []
    for folder in sorted(p for p in RECORDS.iterdir() if p.is_dir()):
        provenance = read_provenance(folder)
        for card in sorted((folder / "cards").glob("*.json")):
            provenance.append(json.loads(card.read_text())["provenance"])
        parts += [
            f"### `{folder.name}`",
            "",
            f"Written by `python scripts/detector_figures.py doc` from "
            f"[results/detector/{folder.name}](../results/detector/{folder.name}).",
            stamp(provenance),
            "",
        ]
        for section in (_detector_rows, _localizer_rows, _fidelity_rows, _navigation_rows):
            rows = section(folder)
            parts += [*rows, ""] if rows else []
    return "\n".join(parts).rstrip()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    rec = sub.add_parser("record")
    rec.add_argument("--detector", type=Path, required=True)
    rec.add_argument("--cards", type=Path, required=True)
    rec.add_argument("--data", type=Path, required=True)
    rec.add_argument("--navigation", type=Path, nargs="*", default=[])
    sub.add_parser("doc")
    args = parser.parse_args()
    if args.command == "record":
        print(record(args.detector, args.cards, args.data, tuple(args.navigation)))
    else:
        DOC.write_text(replace_block(DOC.read_text(), BEGIN, END, doc()))
        print(f"wrote {DOC}")


if __name__ == "__main__":
    main()
