"""Long fuzzing campaigns over every input surface (tests/fuzz): per surface, the examples
tried, the failures found and the shrunk input of each.

    python bench/fuzz.py --examples 10000                 # every surface
    python bench/fuzz.py --examples 2000 --surface "USD rooms" --seed 3
    python bench/fuzz.py --examples 500 --json            # machine-readable

A campaign is the suite's own fuzz test (tests/fuzz/test_fuzz.py, a few seeded examples per
surface) run by pytest with more examples: this script sets its size, seed and surfaces and
prints the report each surface's test writes, so it imports no test module. Exit status 1
when any surface broke the contract.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

from seannet.provenance import ProcessState
from sgdata import markdown

ROOT = Path(__file__).resolve().parents[1]

TEST = "tests/fuzz/test_fuzz.py::test_every_surface_keeps_the_contract"
COLUMNS = ("surface", "examples tried", "refused (one-line error)", "failures", "known", "seconds")


def run_campaign(examples: int, seed: int, surfaces: list[str] | None) -> list[dict]:
    """The fuzz test under pytest with ``examples`` per surface; one report per surface run."""
    with tempfile.TemporaryDirectory(prefix="sgdata-fuzz-") as tmp:
        report = Path(tmp) / "report.jsonl"
        env = {
            **os.environ,
            "SGDATA_FUZZ_EXAMPLES": str(examples),
            "SGDATA_FUZZ_SEED": str(seed),
            "SGDATA_FUZZ_REPORT": str(report),
            **({"SGDATA_FUZZ_SURFACES": json.dumps(surfaces)} if surfaces else {}),
        }
        command = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", TEST]
        subprocess.run(command, cwd=ROOT, env=env, stdout=sys.stderr, check=False)
        if not report.exists():
            return []
        return [json.loads(line) for line in report.read_text(encoding="utf-8").splitlines()]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--examples", type=int, default=1000, help="examples per surface")
    parser.add_argument(
        "--seed", type=int, default=0, help="hypothesis seed (same seed: same inputs)"
    )
    parser.add_argument("--surface", action="append", help="only these (repeatable)")
    parser.add_argument("--json", action="store_true", help="one JSON object per surface")
    args = parser.parse_args()
    commit = ProcessState.capture(ROOT).commit[:7]
    reports = run_campaign(args.examples, args.seed, args.surface)
    if not reports:
        print("no surface ran: see pytest's output above (a --surface name it does not know?)")
        return 1
    if args.json:
        for report in reports:
            print(json.dumps({**report, "commit": commit}), flush=True)
    else:
        rows = [
            (
                r["surface"],
                r["tried"],
                r["refused"],
                len(r["failures"]),
                "; ".join(f"{k}: {n}" for k, n in r["known"].items()) or "-",
                f"{r['seconds']:.0f}",
            )
            for r in reports
        ]
        print(f"# fuzz campaign: --examples {args.examples} --seed {args.seed}, commit {commit}")
        print("\n".join(markdown.table(COLUMNS, rows, right=(1, 2, 3, 5))))
        details = [
            f"- {r['surface']}: {kind}: {f['message'][:300]}\n  shrunk input: {f['example'][:1000]}"
            for r in reports
            for kind, f in r["failures"].items()
        ]
        if details:
            print("\nFailures (the shrunk input of each):")
            print("\n".join(details))
    return 1 if any(r["failures"] for r in reports) else 0


if __name__ == "__main__":
    sys.exit(main())
