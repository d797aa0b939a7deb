"""Loading a script of bench/ or scripts/ as a module: the one way tests load them, for their
tables and verbs, and run them in the test's own process (``run_bench``)."""

from __future__ import annotations

import importlib.util
from pathlib import Path
from types import ModuleType

from .cli_runner import Done, run_main

ROOT = Path(__file__).resolve().parents[1]
BENCH = ROOT / "bench"
SCRIPTS = ROOT / "scripts"


def load_bench(name: str) -> ModuleType:
    """``bench/<name>.py`` as a fresh module named ``bench_<name>``."""
    return _load(f"bench_{name}", BENCH / f"{name}.py")


def run_bench(name: str, *args: object) -> Done:
    """``python bench/<name>.py args...`` in this process: its output, and its exit status
    from SystemExit. For tests not about the process boundary (a fresh interpreter, a
    thread count set before torch loads)."""
    return run_main(load_bench(name).main, f"{name}.py", *args)


def load_script(name: str) -> ModuleType:
    """``scripts/<name>.py`` as a fresh module named ``script_<name>``."""
    return _load(f"script_{name}", SCRIPTS / f"{name}.py")


def _load(module_name: str, path: Path) -> ModuleType:
    spec = importlib.util.spec_from_file_location(module_name, path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module
