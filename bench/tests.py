"""The test suite as README.md runs it (`make test`, or `make test-fast`): wall time, tests by
outcome, the slowest ten and the disk it wrote at its peak.

    .venv/bin/python bench/tests.py [--target test|test-fast] [--json]

The suite runs unchanged; its per-test times come from pytest's JUnit XML (``PYTEST_ADDOPTS``
adds ``--junitxml`` and a ``--basetemp`` of this script's own, whose size is polled every
2 s for the peak). Run it on a quiet machine: the suite's own timing tests wait for quiet.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import tempfile
import threading
import time
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]


def _size_mb(root: Path) -> float:
    total = 0
    for folder, _dirs, files in os.walk(root):
        for name in files:
            try:
                total += os.lstat(os.path.join(folder, name)).st_size
            except OSError:  # removed while we walked
                pass
    return total / 2**20


def _cases(junit: Path) -> list[dict[str, Any]]:
    cases = []
    for case in ET.parse(junit).getroot().iter("testcase"):
        outcome = "passed"
        for kind in ("failure", "error", "skipped"):
            if case.find(kind) is not None:
                outcome = {"failure": "failed", "error": "error", "skipped": "skipped"}[kind]
        cases.append(
            {
                "test": f"{case.get('classname', '')}::{case.get('name', '')}",
                "seconds": float(case.get("time", 0.0)),
                "outcome": outcome,
            }
        )
    return cases


def measure(target: str) -> dict[str, Any]:
    """Run ``make <target>`` once; its wall time, outcomes, slowest ten and peak disk."""
    with tempfile.TemporaryDirectory(prefix="bench-tests-") as scratch:
        junit, basetemp = Path(scratch) / "junit.xml", Path(scratch) / "basetemp"
        env = {
            **os.environ,
            "PYTEST_ADDOPTS": f"--junitxml={junit} --basetemp={basetemp}",
        }
        peak, done = [0.0], threading.Event()

        def poll() -> None:
            while not done.wait(2.0):
                if basetemp.exists():
                    peak[0] = max(peak[0], _size_mb(basetemp))

        poller = threading.Thread(target=poll, daemon=True)
        poller.start()
        start = time.perf_counter()
        run = subprocess.run(
            ["make", "-s", target], cwd=ROOT, env=env, capture_output=True, text=True, check=False
        )
        wall = time.perf_counter() - start
        done.set()
        poller.join()
        if not junit.is_file():
            raise SystemExit(f"make {target} wrote no JUnit XML:\n{run.stdout[-3000:]}")
        cases = _cases(junit)
        shutil.rmtree(basetemp, ignore_errors=True)
    outcomes: dict[str, int] = {}
    for case in cases:
        outcomes[case["outcome"]] = outcomes.get(case["outcome"], 0) + 1
    slowest = sorted(cases, key=lambda c: -c["seconds"])[:10]
    return {
        "target": target,
        "returncode": run.returncode,
        "wall_s": round(wall, 1),
        "tests": len(cases),
        "outcomes": outcomes,
        "test_seconds": round(sum(c["seconds"] for c in cases), 1),
        "peak_disk_mb": round(peak[0]),
        "slowest": [{**c, "seconds": round(c["seconds"], 1)} for c in slowest],
        "summary": run.stdout.strip().splitlines()[-1] if run.stdout.strip() else "",
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--target", choices=("test", "test-fast"), default="test")
    parser.add_argument("--json", action="store_true", help="one JSON line, for bench/suite.py")
    args = parser.parse_args()
    result = measure(args.target)
    if args.json:
        print(json.dumps(result))
        return
    print(
        f"make {result['target']}: {result['wall_s']:.0f} s wall, {result['tests']} tests "
        f"{result['outcomes']}, peak disk {result['peak_disk_mb']} MB"
    )
    for case in result["slowest"]:
        print(f"  {case['seconds']:7.1f} s  {case['test']}")


if __name__ == "__main__":
    main()
