"""One model minus another on the same rooms, from two ``seannet compare`` outputs.

    python bench/paired.py DATA A_DIR:MODEL B_DIR:MODEL [--split test]

For comparisons run apart (e.g. a new SeanNet against a baseline compared earlier on the same
data): the triplet-accuracy difference with its 95 % room-bootstrap interval, as
``seannet compare`` prints for the models of one run
(``seannet.evaluation.compare.paired_difference``).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from seannet.evaluation.compare import COMPARISON, paired_difference, triplets_per_room  # noqa: E402


def runs_of(spec: str) -> list[dict]:
    folder, _, model = spec.rpartition(":")
    entries = json.loads((Path(folder) / f"{COMPARISON}.json").read_text())["models"]
    return next(e["runs"] for e in entries if e["model"] == model)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("data", type=Path)
    parser.add_argument("a")
    parser.add_argument("b")
    parser.add_argument("--split", default="test")
    args = parser.parse_args()
    d = paired_difference(
        runs_of(args.a), runs_of(args.b), triplets_per_room(args.data, args.split)
    )
    print(
        f"{args.a} minus {args.b}: {100 * d['mean']:+.1f} points, 95 % room-bootstrap "
        f"[{100 * d['low']:+.1f}, {100 * d['high']:+.1f}] over {d['rooms']} rooms"
    )


if __name__ == "__main__":
    main()
