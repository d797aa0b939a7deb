"""The fuzzing harness every input surface shares: one contract, one runner, one report.

The contract, for every input a person can get wrong: sgdata answers with a clear one-line
error (an :class:`~sgdata.errors.SgdataError`, which the CLI turns into exit 2 and no
traceback) or with a correct result, and leaves nothing half-written (no temporary file of an
atomic write, no output after an error). A surface is one :class:`Surface`: a hypothesis
strategy of inputs and a ``feed`` that writes one input into an empty folder and hands it to
sgdata's public entry point. Adding a surface means adding one; the runner, the shrinking and
the report are shared.
"""

from __future__ import annotations

import contextlib
import shutil
import tempfile
import traceback
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import seed as hypothesis_seed
from hypothesis.errors import Flaky
from hypothesis.strategies import SearchStrategy

from sgdata.errors import SgdataError
from sgdata.fileio import TEMP_GLOB

__all__ = ["Failure", "Report", "Surface", "campaign", "check_contract"]


@dataclass(frozen=True)
class Surface:
    """One input surface: what a person can hand sgdata, and how sgdata is handed it."""

    name: str
    inputs: SearchStrategy  # the inputs, valid and broken (the one thing a new surface adds)
    # write one input under the empty folder and feed it to sgdata; raise AssertionError for a
    # wrong result; the session is what :attr:`session` yields (a server, a dataset, or None)
    feed: Callable[[Any, Path, Any], None]
    # paths under the folder that must not exist after sgdata refused the input
    outputs: tuple[str, ...] = ()
    # shared, costly state for every example of a campaign (a running server, a dataset)
    session: Callable[[Path], contextlib.AbstractContextManager[Any]] = lambda _: (
        contextlib.nullcontext()
    )
    # failure substring -> where that defect is reported (found here, fixed by its owner)
    known: dict[str, str] = field(default_factory=dict)
    # the one-line errors that refuse an input (seannet's surfaces: its own hierarchy)
    refusals: tuple[type[Exception], ...] = (SgdataError,)


@dataclass
class Failure:
    """A broken contract: its kind and the last (shrunk) input that broke it."""

    kind: str  # "traceback: <Type> at <file:line>", "not one line", "half-written", "wrong result"
    message: str
    example: Any


@dataclass
class Report:
    """What a campaign over one surface tried and found."""

    surface: str
    tried: int = 0  # examples fed, shrinking included
    refused: int = 0  # examples answered with a one-line SgdataError
    failures: dict[str, Failure] = field(default_factory=dict)  # kind -> the shrunk input
    known: dict[str, int] = field(default_factory=dict)  # known defect -> examples hitting it


class ContractBroken(Exception):
    """Raised inside the hypothesis test so it shrinks the input that broke the contract."""


_KINDS: dict[str, type[ContractBroken]] = {}


def _broken(kind: str) -> ContractBroken:
    """An exception of a class of its own per kind: hypothesis tells bugs apart by class and
    place raised, so each kind of failure is searched for and shrunk separately."""
    if kind not in _KINDS:
        _KINDS[kind] = type(f"ContractBroken{len(_KINDS)}", (ContractBroken,), {})
    return _KINDS[kind](kind)


def check_contract(surface: Surface, example: Any, work: Path, session: Any) -> Failure | bool:
    """Feed one input; the broken contract as a :class:`Failure`, else whether it was refused."""
    refused = False
    try:
        surface.feed(example, work, session)
    except surface.refusals as exc:
        refused = True
        text = str(exc)
        if not text.strip() or "\n" in text.strip():
            return Failure("not one line", text, example)
        left = [p for p in surface.outputs if (work / p).exists()]
        if left:
            return Failure("half-written", f"{left} exist after: {text}", example)
    except AssertionError as exc:  # its message up to the first colon names the kind
        return Failure(f"wrong result: {str(exc).split(':')[0][:80]}", str(exc), example)
    except Exception as exc:  # noqa: BLE001 - any other exception is the traceback we hunt
        frames = traceback.extract_tb(exc.__traceback__)
        ours = [f for f in frames if "/sgdata/" in f.filename or "/seannet/" in f.filename]
        ours = ours or frames
        where = f"{Path(ours[-1].filename).name}:{ours[-1].lineno}"  # the last line of ours
        return Failure(f"traceback: {type(exc).__name__} at {where}", str(exc)[:300], example)
    temps = sorted(str(p.relative_to(work)) for p in work.rglob(TEMP_GLOB))
    if temps:
        return Failure("half-written", f"temporary files left: {temps}", example)
    return refused


def campaign(
    surface: Surface,
    examples: int,
    *,
    seed: int = 0,
    session: Any = None,
    work_root: Path | None = None,
) -> Report:
    """Feed ``examples`` inputs of ``surface`` (seeded) and report every broken contract.

    Each kind of failure is shrunk by hypothesis to a small input; after the first one the
    search goes on for a while to find others (hypothesis' multiple-bug reporting).

    Args:
        session: the surface's shared state, when the caller has it (a test fixture); else
            ``surface.session`` makes it for this campaign.
        work_root: where each example's folder is made (a fresh temporary folder if None).
    """
    report = Report(surface.name)
    with contextlib.ExitStack() as stack:
        root = work_root or Path(stack.enter_context(tempfile.TemporaryDirectory()))
        if session is None:
            session = stack.enter_context(surface.session(root / "session"))
        counter = iter(range(1 << 62))

        @hypothesis_seed(seed)
        @settings(
            max_examples=examples,
            database=None,
            deadline=None,
            phases=(Phase.generate, Phase.target, Phase.shrink),
            suppress_health_check=list(HealthCheck),
            report_multiple_bugs=True,
        )
        @given(surface.inputs)
        def run(example: Any) -> None:
            report.tried += 1
            work = root / f"ex{next(counter)}"
            work.mkdir(parents=True)
            try:
                found = check_contract(surface, example, work, session)
            finally:
                shutil.rmtree(work, ignore_errors=True)
            if found is True:
                report.refused += 1
            if not isinstance(found, Failure):
                return
            for needle, where in surface.known.items():
                if needle in found.kind or needle in found.message:
                    key = f"{needle} ({where})"
                    report.known[key] = report.known.get(key, 0) + 1
                    return
            report.failures[found.kind] = found  # the last one of a kind is the shrunk one
            raise _broken(found.kind)

        with contextlib.suppress(ContractBroken, Flaky, BaseExceptionGroup):
            run()
    return report
