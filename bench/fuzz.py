"""Long fuzzing campaigns over every input surface (tests/fuzz): per surface, the examples
tried, the failures found and the shrunk input of each.

    python bench/fuzz.py --examples 10000                 # every surface
    python bench/fuzz.py --examples 2000 --surface "USD rooms" --seed 3
    python bench/fuzz.py --examples 500 --json            # machine-readable

The test suite runs the same harness with a few seeded examples per surface
(tests/fuzz/test_fuzz.py). Exit status 1 when any surface broke the contract.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tests.fuzz.harness import campaign  # noqa: E402
from tests.fuzz.surfaces import SURFACES  # noqa: E402

COLUMNS = ("surface", "examples tried", "refused (one-line error)", "failures", "known", "seconds")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--examples", type=int, default=1000, help="examples per surface")
    parser.add_argument(
        "--seed", type=int, default=0, help="hypothesis seed (same seed: same inputs)"
    )
    parser.add_argument(
        "--surface", action="append", choices=sorted(SURFACES), help="only these (repeatable)"
    )
    parser.add_argument("--json", action="store_true", help="one JSON object per surface")
    args = parser.parse_args()
    commit = subprocess.run(
        ["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True, text=True
    ).stdout.strip()
    if not args.json:
        print(f"# fuzz campaign: --examples {args.examples} --seed {args.seed}, commit {commit}")
        print(f"| {' | '.join(COLUMNS)} |")
        print("|---|---:|---:|---:|---|---:|")
    broken = False
    details = []
    for name in args.surface or list(SURFACES):
        start = time.perf_counter()
        report = campaign(SURFACES[name], args.examples, seed=args.seed)
        seconds = time.perf_counter() - start
        broken |= bool(report.failures)
        known = "; ".join(f"{k}: {n}" for k, n in report.known.items()) or "-"
        if args.json:
            failures = {
                k: {"message": f.message, "example": repr(f.example)[:2000]}
                for k, f in report.failures.items()
            }
            print(
                json.dumps(
                    {
                        "surface": name,
                        "tried": report.tried,
                        "refused": report.refused,
                        "failures": failures,
                        "known": report.known,
                        "seconds": round(seconds, 1),
                        "commit": commit,
                    }
                ),
                flush=True,
            )
            continue
        row = (name, report.tried, report.refused, len(report.failures), known, f"{seconds:.0f}")
        print(f"| {' | '.join(map(str, row))} |", flush=True)
        details += [
            f"- {name}: {kind}: {f.message[:300]}\n  shrunk input: {repr(f.example)[:1000]}"
            for kind, f in report.failures.items()
        ]
    if details:
        print("\nFailures (the shrunk input of each):")
        print("\n".join(details))
    return 1 if broken else 0


if __name__ == "__main__":
    sys.exit(main())
