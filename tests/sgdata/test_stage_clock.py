"""The stage clock: exclusive time per (phase, stage), and a worker's clock added back."""

from __future__ import annotations

import pickle
import time

from sgdata.stage_clock import NO_CLOCK, StageClock


def test_a_stage_books_its_own_time_less_the_named_stages_inside() -> None:
    clock = StageClock()
    with clock.phase("views"), clock.stage("other"):
        time.sleep(0.02)
        for _ in range(2):
            with clock.stage("render"):
                time.sleep(0.03)
    render, other = clock.seconds[("views", "render")], clock.seconds[("views", "other")]
    assert clock.calls[("views", "render")] == 2 and clock.calls[("views", "other")] == 1
    assert 0.06 <= render < 0.2 and 0.02 <= other < 0.06
    rows = clock.rows({"views": ("render", "other")})
    assert [r["stage"] for r in rows] == ["render", "other"]
    assert abs(sum(r["share"] for r in rows) - 1) < 1e-9


def test_a_workers_clock_travels_and_adds_up() -> None:
    worker = pickle.loads(pickle.dumps(StageClock()))  # as a task's clock goes to a worker
    with worker.phase("scenes"), worker.stage("room"):
        pass
    main = StageClock()
    main.add(worker.totals())
    main.add(worker.totals())
    assert main.calls[("scenes", "room")] == 2
    assert main.seconds[("scenes", "room")] == 2 * worker.seconds[("scenes", "room")]
    main.book("scenes", "outside the tasks", 1.5)  # measured by the caller, not a block
    assert main.calls[("scenes", "outside the tasks")] == 1
    assert main.seconds[("scenes", "outside the tasks")] == 1.5


def test_no_clock_times_nothing() -> None:
    with NO_CLOCK.phase("views"), NO_CLOCK.stage("render"):
        pass
