"""bench/ as thin scripts: each imports the installed packages (``sgdata``, ``seannet``, third
party) and the standard library only; none edits ``sys.path``, imports a sibling script or the
tests, or loads a module at run time. What two scripts share lives in the package."""

from __future__ import annotations

import ast
import functools
import importlib.metadata
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
BENCH = ROOT / "bench"
# never importable from a bench script, whatever the environment installs under the name
NOT_INSTALLED = ("tests", "conftest", "bench")
# the project's own packages: a script uses their public names only
PACKAGES = ("sgdata", "seannet", "sgdata_cli")
# run-time loaders: a script that needs one is reaching for code the package does not offer
LOADERS = ("import_module", "__import__", "spec_from_file_location", "run_path", "run_module")


def _called(node: ast.Call) -> str:
    f = node.func
    return f.attr if isinstance(f, ast.Attribute) else f.id if isinstance(f, ast.Name) else ""


@functools.cache
def _installed() -> frozenset[str]:
    """The top-level modules the environment offers: the standard library's and those of
    installed distributions (``sgdata``, ``seannet``, ``sgdata_cli``, third party)."""
    return frozenset(sys.stdlib_module_names) | set(importlib.metadata.packages_distributions())


def bench_problems(folder: Path, installed: frozenset[str]) -> list[str]:
    """What makes a script of ``folder`` more than a thin one, one line each: a ``sys.path``
    or ``site.addsitedir`` edit, an import of a sibling script, of the tests or of a module
    not ``installed``, a private name of the project's packages, a run-time loader. Relative
    imports count as sibling imports."""
    siblings = {p.stem for p in folder.glob("*.py")}
    problems = []
    for path in sorted(folder.glob("*.py")):
        where = path.name
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            names: list[str] = []
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                if node.level:
                    problems.append(f"{where}:{node.lineno}: relative import (a sibling)")
                    continue
                names = [node.module or ""]
                private = [a.name for a in node.names if a.name.startswith("_")]
                if private and names[0].partition(".")[0] in PACKAGES:
                    problems.append(f"{where}:{node.lineno}: imports private {', '.join(private)}")
                if node.module == "sys" and any(a.name == "path" for a in node.names):
                    problems.append(f"{where}:{node.lineno}: sys.path")
            elif isinstance(node, ast.Attribute) and node.attr == "path":
                if isinstance(node.value, ast.Name) and node.value.id == "sys":
                    problems.append(f"{where}:{node.lineno}: sys.path")
            elif isinstance(node, ast.Call) and _called(node) == "addsitedir":
                problems.append(f"{where}:{node.lineno}: site.addsitedir")
            elif isinstance(node, ast.Call) and _called(node) in LOADERS:
                problems.append(f"{where}:{node.lineno}: {_called(node)} (a run-time import)")
            for name in names:
                top = name.partition(".")[0]
                if top in siblings:
                    problems.append(f"{where}:{node.lineno}: imports the sibling script {name}")
                elif top in NOT_INSTALLED:
                    problems.append(f"{where}:{node.lineno}: imports {name} (not the package)")
                elif top not in installed:
                    problems.append(f"{where}:{node.lineno}: imports {name}, not installed")
    return problems


def test_bench_scripts_import_only_installed_packages() -> None:
    assert bench_problems(BENCH, _installed()) == []


@pytest.mark.parametrize(
    ("script", "problem"),
    [
        ("import sys\nsys.path.insert(0, 'x')\n", "bad.py:2: sys.path"),
        ("from sys import path\npath.append('x')\n", "bad.py:1: sys.path"),
        ("import site\nsite.addsitedir('x')\n", "bad.py:2: site.addsitedir"),
        ("from good import helper\n", "bad.py:1: imports the sibling script good"),
        ("from . import good\n", "bad.py:1: relative import (a sibling)"),
        ("from conftest import build_tiny_room\n", "bad.py:1: imports conftest"),
        ("import tests.conftest\n", "bad.py:1: imports tests.conftest"),
        ("import not_a_package_anywhere\n", "bad.py:1: imports not_a_package_anywhere"),
        ("import importlib\nimportlib.import_module('good')\n", "bad.py:2: import_module"),
        (
            "import importlib.util\nimportlib.util.spec_from_file_location('g', 'good.py')\n",
            "bad.py:2: spec_from_file_location",
        ),
        ("import runpy\nrunpy.run_path('good.py')\n", "bad.py:2: run_path"),
        ("from sgdata.render.renderer import _rot_x\n", "bad.py:1: imports private _rot_x"),
    ],
    ids=[
        "sys.path",
        "from sys import path",
        "addsitedir",
        "sibling",
        "relative",
        "conftest",
        "tests",
        "not installed",
        "import_module",
        "spec_from_file_location",
        "run_path",
        "private name",
    ],
)
def test_a_script_that_is_not_thin_is_found(tmp_path: Path, script: str, problem: str) -> None:
    """Each way a script reaches past the package is named, once; a thin sibling is not."""
    (tmp_path / "good.py").write_text("import json\nfrom sgdata import markdown\n")
    (tmp_path / "bad.py").write_text(script)
    found = bench_problems(tmp_path, _installed())
    assert len(found) == 1 and found[0].startswith(problem), found
