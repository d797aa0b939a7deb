"""Turns library errors into one line on stderr and exit code 2, never a traceback."""

from __future__ import annotations

import sys
from collections.abc import Callable

import typer

from sgdata.errors import SgdataError

__all__ = ["run_app"]

EXIT_USER_ERROR = 2


def run_app(
    app: typer.Typer, prog_name: str, *, errors: tuple[type[Exception], ...] = (SgdataError,)
) -> Callable[[], None]:
    """A console-script entry point running ``app``; ``errors`` become one line + exit 2."""

    def main() -> None:
        try:
            app(prog_name=prog_name, standalone_mode=True)
        except errors as exc:
            print(f"{prog_name}: error: {exc}", file=sys.stderr)
            sys.exit(EXIT_USER_ERROR)
        except KeyboardInterrupt:
            print(f"{prog_name}: interrupted", file=sys.stderr)
            sys.exit(130)

    return main
