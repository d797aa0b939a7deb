"""The house's layering (docs/architecture.md): stages import downwards only, no cycles, and
the reading side loads no USD, renderer or torch."""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
# Pipeline stages from the bottom up; a module may import its own stage and those below it.
STAGES = (
    "world",
    "usd",
    "render",
    "annotate",
    "dataset",
    "validate",
    "label",
    "pipeline",
    "pictures",
)
HEAVY = ("pxr", "pyrender", "open3d", "trimesh", "torch", "OpenGL", "sgdata.render", "sgdata.usd")


def _imports(path: Path) -> set[str]:
    """Every sgdata module a file imports, at module level or inside functions."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            found.add(node.module)
        elif isinstance(node, ast.Import):
            found.update(a.name for a in node.names)
    return {m for m in found if m == "sgdata" or m.startswith("sgdata.")}


def _stage(module: str) -> str | None:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 and parts[1] in STAGES else None


def _modules() -> list[tuple[str, Path]]:
    out = []
    for path in sorted((ROOT / "sgdata").rglob("*.py")):
        rel = path.relative_to(ROOT).with_suffix("")
        parts = list(rel.parts[:-1] if rel.name == "__init__" else rel.parts)
        out.append((".".join(parts), path))
    return out


def test_stages_import_downwards_only() -> None:
    wrong = []
    for module, path in _modules():
        own = _stage(module)
        if own is None:
            continue
        for target in _imports(path):
            other = _stage(target)
            if other is not None and STAGES.index(other) > STAGES.index(own):
                wrong.append(f"{module} imports {target}")
    assert wrong == []


def test_world_and_render_never_import_each_other_and_dataset_needs_no_usd() -> None:
    rules = {"world": ("render",), "render": ("world",), "dataset": ("usd", "render")}
    wrong = []
    for module, path in _modules():
        banned = rules.get(_stage(module) or "", ())
        wrong += [f"{module} -> {t}" for t in _imports(path) if _stage(t) in banned]
    assert wrong == []


def test_no_module_level_import_cycle() -> None:
    """Module-level imports (the ones that run at import time) form no cycle."""
    graph: dict[str, set[str]] = {}
    names = {m for m, _ in _modules()}
    for module, path in _modules():
        tree = ast.parse(path.read_text(encoding="utf-8"))
        deps = set()
        for node in tree.body:
            if isinstance(node, ast.ImportFrom) and node.module in names:
                deps.add(node.module)
        graph[module] = deps - {module}
    state: dict[str, int] = {}

    def visit(node: str, trail: list[str]) -> None:
        state[node] = 1
        for nxt in graph.get(node, ()):
            if state.get(nxt) == 1:
                pytest.fail("import cycle: " + " -> ".join([*trail, node, nxt]))
            if nxt not in state:
                visit(nxt, [*trail, node])
        state[node] = 2

    for module in sorted(graph):
        if module not in state:
            visit(module, [])


def test_no_module_is_past_600_lines() -> None:
    long = [
        f"{p.relative_to(ROOT)}: {n}"
        for p in sorted([*(ROOT / "sgdata").rglob("*.py"), *(ROOT / "seannet").rglob("*.py")])
        if (n := len(p.read_text(encoding="utf-8").splitlines())) > 600
    ]
    assert long == []


@pytest.mark.parametrize(
    "statement",
    [
        "import sgdata",
        "import sgdata.dataset",
        "from sgdata.dataset import Dataset, read_table, observations_schema",
        "from sgdata import Dataset, validate_dataset",
    ],
)
def test_the_reading_side_loads_no_usd_renderer_or_torch(statement: str) -> None:
    code = f"import sys; {statement}; print(','.join(sorted(sys.modules)))"
    loaded = (
        subprocess.run(
            [sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=ROOT
        )
        .stdout.strip()
        .split(",")
    )
    assert [m for m in loaded if m.split(".")[0] in HEAVY or m.startswith(HEAVY)] == []


def test_every_module_says_its_job_in_a_docstring() -> None:
    missing = [
        str(path.relative_to(ROOT))
        for _, path in _modules()
        if not ast.get_docstring(ast.parse(path.read_text(encoding="utf-8")))
    ]
    assert missing == []
