"""A stage clock: where the time of ``sgdata generate`` goes, stage by stage, measured by the
room tasks themselves (``sgdata generate --profile``, ``bench/stages.py``).

A task names its steps (``with clock.stage("render"):``); the clock books each step's
*exclusive* time (its own, less that of the named steps inside it) to ``(phase, stage)``, so the
stages of a phase add up to its wall time when the task's body is itself a stage
(:data:`OTHER`: what no named step claims). The default clock, :data:`NO_CLOCK`, does nothing.
Clocks are plain data: a worker's clock comes back in its task's result
(:meth:`StageClock.totals`) and is added to the main process's (:meth:`StageClock.add`).
"""

from __future__ import annotations

import time
from collections import defaultdict
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from typing import Protocol

__all__ = ["NO_CLOCK", "OTHER", "Clock", "NoClock", "StageClock"]

OTHER = "other"  # a task's time outside its named stages


class Clock(Protocol):
    """What a room task asks of a clock."""

    def phase(self, name: str) -> Iterator[None]: ...  # a context manager

    def stage(self, name: str) -> Iterator[None]: ...  # a context manager


class NoClock:
    """The clock of a run that is not profiled: every stage is a no-op."""

    @contextmanager
    def phase(self, name: str) -> Iterator[None]:
        yield

    @contextmanager
    def stage(self, name: str) -> Iterator[None]:
        yield


NO_CLOCK = NoClock()


class StageClock:
    """Exclusive seconds and calls per ``(phase, stage)``."""

    def __init__(self) -> None:
        self.seconds: dict[tuple[str, str], float] = defaultdict(float)
        self.calls: dict[tuple[str, str], int] = defaultdict(int)
        self._phase = ""
        self._stack: list[list] = []  # [stage, seconds of the named stages inside it]

    @contextmanager
    def phase(self, name: str) -> Iterator[None]:
        """Book the stages of the block to phase ``name`` (``"scenes"``, ``"views"``)."""
        outer, self._phase = self._phase, name
        try:
            yield
        finally:
            self._phase = outer

    @contextmanager
    def stage(self, name: str) -> Iterator[None]:
        """Time the block as stage ``name`` of the current phase (exclusive of inner stages)."""
        start = time.perf_counter()
        self._stack.append([name, 0.0])
        try:
            yield
        finally:
            elapsed = time.perf_counter() - start
            _, inner = self._stack.pop()
            self.seconds[(self._phase, name)] += elapsed - inner
            self.calls[(self._phase, name)] += 1
            if self._stack:
                self._stack[-1][1] += elapsed

    def totals(self) -> dict[str, list]:
        """The clock as JSON-able data: ``{"phase/stage": [seconds, calls]}``."""
        return {f"{p}/{s}": [self.seconds[(p, s)], self.calls[(p, s)]] for p, s in self.seconds}

    def book(self, phase: str, stage: str, seconds: float) -> None:
        """Book ``seconds`` measured elsewhere to ``(phase, stage)`` as one call."""
        self.seconds[(phase, stage)] += seconds
        self.calls[(phase, stage)] += 1

    def add(self, totals: Mapping[str, list]) -> None:
        """Add another clock's :meth:`totals` (a worker's) to this one."""
        for key, (seconds, calls) in totals.items():
            phase, _, stage = key.partition("/")
            self.seconds[(phase, stage)] += float(seconds)
            self.calls[(phase, stage)] += int(calls)

    def rows(self, order: Mapping[str, tuple[str, ...]] | None = None) -> list[dict]:
        """One row per ``(phase, stage)``: ``phase``, ``stage``, ``calls``, ``seconds`` and
        ``share`` of its phase's total; phases and stages in ``order`` first (its phases
        mapped to their stages in pipeline order), the rest as first booked."""
        keys = list(self.seconds)
        if order:
            rank = {(p, s): (i, j) for i, p in enumerate(order) for j, s in enumerate(order[p])}
            keys.sort(key=lambda k: rank.get(k, (len(rank), 0)))
        totals: dict[str, float] = defaultdict(float)
        for (phase, _), seconds in self.seconds.items():
            totals[phase] += seconds
        return [
            {
                "phase": phase,
                "stage": stage,
                "calls": self.calls[(phase, stage)],
                "seconds": self.seconds[(phase, stage)],
                "share": self.seconds[(phase, stage)] / totals[phase] if totals[phase] else 0.0,
            }
            for phase, stage in keys
        ]
