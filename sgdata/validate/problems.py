"""What a validation run returns: a :class:`Problem` per failure, a :class:`ValidationReport`."""

from __future__ import annotations

import json
from collections import Counter
from dataclasses import asdict, dataclass, field

__all__ = ["Problem", "ValidationReport", "Collector"]


@dataclass(frozen=True)
class Problem:
    """One failed check at one place of the dataset."""

    check: str  # check name, e.g. "objects.box2d" (see docs/validate.md)
    file: str  # path relative to the dataset root ("dataset.json", a shard, a scene)
    row: int | None  # 0-based row of the file, None for file-level problems
    field: str | None  # column or manifest key, nested as "objects[3].box2d"
    message: str  # what is wrong: the value found and what was expected

    def location(self) -> str:
        """``file:row:field`` with the parts that are known."""
        parts = [self.file]
        if self.row is not None:
            parts.append(str(self.row))
        if self.field:
            parts.append(self.field)
        return ":".join(parts)


@dataclass
class ValidationReport:
    """Every problem found, how many items each check looked at, and the run time."""

    root: str
    problems: list[Problem]
    checked: dict[str, int]  # check name -> items examined (rows, files, pairs ...)
    skipped: list[str]  # check names not run (e.g. images under --quick)
    elapsed: float  # seconds
    notes: list[str] = field(default_factory=list)  # what is worth saying but fails nothing

    @property
    def ok(self) -> bool:
        """True when no check failed."""
        return not self.problems

    def failures(self) -> dict[str, int]:
        """Check name -> number of problems (checks without problems included, as 0)."""
        counts = Counter(p.check for p in self.problems)
        return {name: counts.get(name, 0) for name in sorted(set(self.checked) | set(counts))}

    def to_dict(self) -> dict[str, object]:
        """Plain JSON-able dict (the ``--json`` output)."""
        failures = self.failures()
        return {
            "root": self.root,
            "ok": self.ok,
            "elapsed_s": round(self.elapsed, 3),
            "checks": [
                {"check": name, "checked": self.checked.get(name, 0), "failures": failures[name]}
                for name in failures
            ],
            "skipped": list(self.skipped),
            "problems": [asdict(p) for p in self.problems],
            "notes": list(self.notes),
        }

    def to_json(self) -> str:
        """The report as indented JSON text."""
        return json.dumps(self.to_dict(), indent=2)


@dataclass
class Collector:
    """Mutable sink the check functions append to; becomes a :class:`ValidationReport`."""

    problems: list[Problem] = field(default_factory=list)
    checked: Counter = field(default_factory=Counter)
    skipped: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)

    def count(self, check: str, n: int = 1) -> None:
        """Record that ``check`` examined ``n`` more items."""
        self.checked[check] += int(n)

    def add(
        self,
        check: str,
        file: str,
        message: str,
        *,
        row: int | None = None,
        field: str | None = None,
    ) -> None:
        """Record one problem."""
        self.checked[check] += 0  # a check that failed is listed even if it counted nothing
        self.problems.append(
            Problem(check, file, None if row is None else int(row), field, message)
        )
