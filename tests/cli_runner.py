"""`sgdata` and `seannet` run in the test's own process: the console script's entry point (its
one-line errors and exit codes included) with argv set, stdout and stderr captured.

For tests that are not about the process boundary. Tests of exit by signal, kill -9, a fresh
interpreter's imports or a server's start-up keep a real subprocess and say so.
"""

from __future__ import annotations

import contextlib
import io
import os
import sys
from collections.abc import Callable
from dataclasses import dataclass


@dataclass(frozen=True)
class Done:
    """What a command left: like :class:`subprocess.CompletedProcess`, text mode."""

    returncode: int
    stdout: str
    stderr: str


def run_cli(prog: str, *args: object, columns: int = 120) -> Done:
    """Run ``prog args...`` (prog ``sgdata`` or ``seannet``) through its console script's
    ``main``, as the shell would, in a terminal ``columns`` wide (rich wraps its output
    there); SystemExit becomes the return code."""
    if prog == "sgdata":
        from sgdata_cli.sgdata_app import main
    elif prog == "seannet":
        from sgdata_cli.seannet_app import main
    else:
        raise ValueError(f"prog is {prog!r}: expected 'sgdata' or 'seannet'")
    return run_main(main, prog, *args, columns=columns)


def run_main(main: Callable[[], object], prog: str, *args: object, columns: int = 120) -> Done:
    """Run a command's ``main`` (it reads ``sys.argv``) as ``prog args...``: a console
    script's, or a bench script's (tests/bench_scripts.py, ``run_bench``)."""
    out, err = io.StringIO(), io.StringIO()
    argv, sys.argv = sys.argv, [prog, *map(str, args)]
    saved = os.environ.get("COLUMNS")
    os.environ["COLUMNS"] = str(columns)
    code = 0
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            main()
    except SystemExit as exc:
        if isinstance(exc.code, str):  # sys.exit("message"): printed, exit status 1
            err.write(exc.code + "\n")
            code = 1
        else:
            code = exc.code or 0
    finally:
        sys.argv = argv
        if saved is None:
            os.environ.pop("COLUMNS")
        else:
            os.environ["COLUMNS"] = saved
    return Done(code, out.getvalue(), err.getvalue())
