"""The suite's tiers (pyproject's markers): `make test-fast` skips only the tests marked
`slow`, so the mark is kept for few tests, each saying beside it why it is slow."""

from __future__ import annotations

import re
from pathlib import Path

TESTS = Path(__file__).resolve().parents[1]
MOST_SLOW = 10  # issue 46: at most ten, each saying why
SLOW = re.compile(r"^\s*@pytest\.mark\.slow\b(?P<rest>.*)$")


def test_at_most_ten_tests_are_slow_and_each_says_why() -> None:
    marks, silent = [], []
    for path in sorted(TESTS.rglob("*.py")):
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            found = SLOW.match(line)
            if found is None:
                continue
            where = f"{path.relative_to(TESTS)}:{number}"
            marks.append(where)
            reason = found["rest"].strip()
            if not reason.startswith("#") or len(reason.lstrip("# ")) < 20:
                silent.append(where)
    assert len(marks) <= MOST_SLOW, marks
    assert silent == [], f"a slow mark says why beside it: {silent}"
    assert "pytest.mark.slow" not in (TESTS / "conftest.py").read_text()  # no blanket marking
