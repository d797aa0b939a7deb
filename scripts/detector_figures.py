"""The figures of docs/detector.md from committed evidence, never from a run folder a later
session will not have.

python scripts/detector_figures.py record --detector RUN --cards CARDS --data DATA
    copies the small JSON files of a detector run (curve, test scores, the val threshold
    curve, provenance) and of its benchmark cards into results/detector/<name>-<recipe>/
python scripts/detector_figures.py doc
    writes docs/detector.md's figures block from those files alone
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from seannet.markdown import pct, table
from seannet.provenance import read_provenance, stamp
from sgdata.dataset import Dataset
from sgdata.fileio import atomic_write_bytes
from sgdata.markdown import replace_block

ROOT = Path(__file__).resolve().parents[1]
RECORDS = ROOT / "results" / "detector"
DOC = ROOT / "docs" / "detector.md"
BEGIN, END = "<!-- detector-figures -->", "<!-- /detector-figures -->"
RUN_FILES = ("detector.json", "eval_test.json", "provenance.jsonl")


def record(detector: Path, cards: Path, data: Path) -> Path:
    """Copy the evidence into the dataset's folder of :data:`RECORDS`; returns it."""
    ds = Dataset.open(data)
    folder = RECORDS / f"{ds.manifest.name}-{ds.manifest.recipe_fingerprint()[:16]}"
    (folder / "cards").mkdir(parents=True, exist_ok=True)
    for name in RUN_FILES:
        _copy(detector / name, folder / name)
    threshold = detector / "graphs" / ds.manifest_sha256[:16] / "threshold.json"
    _copy(threshold, folder / "threshold.json")
    for card in sorted(cards.glob("*/card.json")):
        _copy(card, folder / "cards" / f"{card.parent.name}.json")
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
        noise = {n["label"]: n["accuracy"] for n in summary.get("box_noise", [])}
        detected = next((v for k, v in noise.items() if k.startswith("detected-")), None)
        truth = summary["accuracy"]["mean"]
        rows.append(
            (
                f"`{card['method']}`",
                pct(truth),
                pct(detected),
                "-" if detected is None else f"{100 * (detected - truth):+.1f}",
                pct(noise.get("S0.05-P0-Q0")),
            )
        )
    f1 = threshold["val_f1"][f"{threshold['threshold']:g}"]
    return [
        f"**The localizers**, test triplet accuracy (%) with the generator's graphs and with the "
        f"detector's (score >= {threshold['threshold']:g}, chosen on val: F1 {f1:.2f}); one seed "
        "each, trained on true graphs:",
        "",
        *table(
            ("method", "true graphs", "detected graphs", "points", "jitter S 0.05"),
            rows,
            right=range(1, 5),
        ),
    ]


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
            *_detector_rows(folder),
            "",
            *_localizer_rows(folder),
            "",
        ]
    return "\n".join(parts).rstrip()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    rec = sub.add_parser("record")
    rec.add_argument("--detector", type=Path, required=True)
    rec.add_argument("--cards", type=Path, required=True)
    rec.add_argument("--data", type=Path, required=True)
    sub.add_parser("doc")
    args = parser.parse_args()
    if args.command == "record":
        print(record(args.detector, args.cards, args.data))
    else:
        DOC.write_text(replace_block(DOC.read_text(), BEGIN, END, doc()))
        print(f"wrote {DOC}")


if __name__ == "__main__":
    main()
