"""The house's layering (docs/architecture.md): stages import downwards only, no cycles
(imports inside functions, type-only imports and run-time ones by literal count), seannet
reaches only the sgdata it may, and the reading side loads no USD, renderer or torch."""

from __future__ import annotations

import ast
import re
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
# seannet's stages from the bottom up; its top-level modules (errors, weights: plain facts)
# sit below them all
SEANNET_STAGES = (
    "data",
    "model",
    "training",
    "detection",
    "evaluation",
    "methods",
    "navigation",
    "protocol",
)
# The sgdata a seannet module may import: the dataset and its vocabularies (classes, relation
# types), seeds, atomic files, errors. Only the live views (rendering a dataset's rooms again)
# reach the generator's stages.
SEANNET_MAY_IMPORT = (
    "sgdata.dataset",
    "sgdata.seeds",
    "sgdata.fileio",
    "sgdata.markdown",  # the one markdown table helper
    "sgdata.errors",
    "sgdata.scene_files",
    "sgdata.lazy_face",
    "sgdata.annotate.relations",  # the relation types: the dataset's own vocabulary
    "sgdata.annotate.slots",  # M, the slot count: the dataset's own slot table
    "sgdata.world.catalog",  # the class vocabulary when a model is built without a dataset
    "sgdata.pipeline.executors",  # spawned workers that die with their parent (navigate)
)
LIVE_VIEWS_MAY_IMPORT = ("sgdata.render", "sgdata.usd", "sgdata.annotate", "sgdata.world.poses")
# the detector trains on and is scored against the COCO export any other tool would read
# (checked by the labeling tool's field reader), and proposes boxes to the labeling tool
# through the tool's own contract
DETECTION_MAY_IMPORT = {
    "seannet.detection.train": ("sgdata.label.coco_export",),
    "seannet.detection.coco_views": ("sgdata.label.annotations",),
    "seannet.detection.proposer": ("sgdata.label.box_proposer",),
}
HEAVY = ("pxr", "pyrender", "open3d", "trimesh", "torch", "OpenGL", "sgdata.render", "sgdata.usd")


def _imports(
    path: Path, package: str = "sgdata", *, dynamic: bool = False, module: str = ""
) -> set[str]:
    """Every ``package`` module a file imports: at module level, inside functions and under
    ``if TYPE_CHECKING:`` (a circle of types is still a circle for a reader); with
    ``dynamic``, also the modules it imports at run time: a literal handed to
    ``import_module`` or ``__import__``, the literal module name or ``.py`` path handed to
    ``spec_from_file_location`` (a bare file name is a sibling of ``module``, the file's own
    name), and in a file that calls ``import_module`` itself, every import path
    ``"pkg.module:name"`` it holds (a registry resolving its own table; a record that only
    names a builder another module resolves is data, not an import)."""
    found = set()
    tree = ast.parse(path.read_text(encoding="utf-8"))
    resolves = dynamic and any(
        isinstance(n, ast.Call) and _called(n) == "import_module" for n in ast.walk(tree)
    )
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            found.add(node.module)  # and each name, which may be a submodule of a package:
            found.update(f"{node.module}.{a.name}" for a in node.names)  # _owner settles it
        elif isinstance(node, ast.Import):
            found.update(a.name for a in node.names)
        elif resolves and isinstance(node, ast.Constant) and isinstance(node.value, str):
            if IMPORT_PATH.fullmatch(node.value):
                found.add(node.value.partition(":")[0])
        elif dynamic and isinstance(node, ast.Call) and _called(node) in DYNAMIC_IMPORTS:
            first = node.args[0] if node.args else None
            if isinstance(first, ast.Constant) and isinstance(first.value, str):
                found.add(first.value)
        elif dynamic and isinstance(node, ast.Call) and _called(node) == "spec_from_file_location":
            found |= _file_location_edges(node, module)
    return {m for m in found if m == package or m.startswith(package + ".")}


IMPORT_PATH = re.compile(r"[a-z_][a-z0-9_]*(\.[a-z_][a-z0-9_]*)+(:[A-Za-z_]\w*)?")
DYNAMIC_IMPORTS = ("import_module", "__import__")  # their first argument names the module


def _file_location_edges(call: ast.Call, module: str) -> set[str]:
    """The modules a ``spec_from_file_location`` call names by literals: its module name, and
    each ``.py`` path among its arguments (``pkg/entry.py`` is ``pkg.entry``; a bare
    ``entry.py``, as in ``Path(__file__).parent / "entry.py"``, a sibling of ``module``)."""
    edges = set()
    for node in ast.walk(call):
        if not (isinstance(node, ast.Constant) and isinstance(node.value, str)):
            continue
        text = node.value
        if text.endswith(".py"):
            dotted = text.removesuffix(".py").removeprefix("./").replace("/", ".")
            if "." not in dotted and module:
                dotted = f"{module.rpartition('.')[0]}.{dotted}"
            edges.add(dotted.removesuffix(".__init__"))
        elif IMPORT_PATH.fullmatch(text) and node is (call.args[0] if call.args else None):
            edges.add(text)
    return edges


def _called(node: ast.Call) -> str:
    f = node.func
    return f.attr if isinstance(f, ast.Attribute) else f.id if isinstance(f, ast.Name) else ""


def _stage(module: str) -> str | None:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 and parts[1] in STAGES else None


def _modules(package: str = "sgdata") -> list[tuple[str, Path]]:
    out = []
    for path in sorted((ROOT / package).rglob("*.py")):
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


@pytest.mark.parametrize("package", ["sgdata", "seannet"])
def test_no_import_cycle(package: str) -> None:
    """No cycle among a package's modules, counting imports inside functions and dynamic
    ones: a circle closed by a deferred or a run-time import is still a circle (each module
    needs the others)."""
    _assert_no_cycle(_modules(package), package)


# a registry loading its entry at run time, each way a circle can close with no import line
DYNAMIC_LOADS = {
    "import_module": 'import importlib\ndef load():\n    importlib.import_module("pkg.entry")\n',
    "__import__": 'def load():\n    __import__("pkg.entry")\n',
    "resolved table": (
        'import importlib\nTABLE = {"a": "pkg.entry:Thing"}\n'
        "def load(where):\n    importlib.import_module(where)\n"
    ),
    "spec_from_file_location, module name": (
        "import importlib.util\ndef load(path):\n"
        '    importlib.util.spec_from_file_location("pkg.entry", path)\n'
    ),
    "spec_from_file_location, path": (
        "import importlib.util\ndef load():\n"
        '    importlib.util.spec_from_file_location("entry", "pkg/entry.py")\n'
    ),
    "spec_from_file_location, sibling file": (
        "import importlib.util\nfrom pathlib import Path\ndef load():\n"
        '    importlib.util.spec_from_file_location("e", Path(__file__).parent / "entry.py")\n'
    ),
}


@pytest.mark.parametrize("load", DYNAMIC_LOADS)
def test_a_circle_closed_by_a_dynamic_import_is_found(tmp_path: Path, load: str) -> None:
    """A registry that imports its entries by name or file, and an entry that imports the
    registry: no ``import`` statement closes the circle, the check still sees it."""
    (tmp_path / "registry.py").write_text(DYNAMIC_LOADS[load])
    (tmp_path / "entry.py").write_text("from pkg.registry import TABLE\n")
    modules = [("pkg.registry", tmp_path / "registry.py"), ("pkg.entry", tmp_path / "entry.py")]
    with pytest.raises(pytest.fail.Exception, match="pkg.entry -> pkg.registry"):
        _assert_no_cycle(modules, "pkg")


def test_a_circle_closed_by_importing_a_module_from_its_package_is_found(tmp_path: Path) -> None:
    """``from pkg import entry`` names the module ``entry``, not the package's face (the
    executors' deferred ``from sgdata.pipeline import ray_executor`` hid such a circle)."""
    (tmp_path / "registry.py").write_text("def load():\n    from pkg import entry\n")
    (tmp_path / "entry.py").write_text("from pkg.registry import TABLE\n")
    modules = [("pkg.registry", tmp_path / "registry.py"), ("pkg.entry", tmp_path / "entry.py")]
    with pytest.raises(pytest.fail.Exception, match="pkg.entry -> pkg.registry"):
        _assert_no_cycle(modules, "pkg")


def test_a_registry_loading_a_file_by_a_variable_path_closes_no_circle(tmp_path: Path) -> None:
    """The registry's own ``file.py:factory`` loader names no module: no edge, no circle."""
    (tmp_path / "registry.py").write_text(
        "import importlib.util\ndef load(name, path):\n"
        "    importlib.util.spec_from_file_location(name, path)\n"
    )
    (tmp_path / "entry.py").write_text("from pkg.registry import TABLE\n")
    modules = [("pkg.registry", tmp_path / "registry.py"), ("pkg.entry", tmp_path / "entry.py")]
    _assert_no_cycle(modules, "pkg")


def _assert_no_cycle(modules: list[tuple[str, Path]], package: str) -> None:
    names = {m for m, _ in modules}
    graph: dict[str, set[str]] = {}
    for module, path in modules:
        found = _imports(path, package, dynamic=True, module=module)
        edges = {_owner(t, names) for t in found}
        graph[module] = edges - {module, None}
    state: dict[str, int] = {}

    def visit(node: str, trail: list[str]) -> None:
        state[node] = 1
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == 1:
                pytest.fail("import cycle: " + " -> ".join([*trail, node, nxt]))
            if nxt not in state:
                visit(nxt, [*trail, node])
        state[node] = 2

    for module in sorted(graph):
        if module not in state:
            visit(module, [])


def _owner(target: str, names: set[str]) -> str | None:
    """The module an import names: ``a.b.c`` itself, or the package ``a.b`` whose face
    re-exports ``c``. A package's own face is left out: it only re-exports, lazily."""
    while target and target not in names:
        target = target.rpartition(".")[0]
    return None if not target or target.count(".") == 0 else target


def _seannet_stage(module: str) -> int:
    parts = module.split(".")
    if len(parts) > 1 and parts[1] in SEANNET_STAGES:
        return SEANNET_STAGES.index(parts[1])
    return -1  # seannet.errors, seannet.weights: below every stage


def test_seannet_stages_import_downwards_only() -> None:
    wrong = []
    for module, path in _modules("seannet"):
        if module == "seannet":
            continue  # the face re-exports lazily from every stage
        own = _seannet_stage(module)
        for target in _imports(path, "seannet"):
            if target != "seannet" and _seannet_stage(target) > own:
                wrong.append(f"{module} imports {target}")
    assert wrong == []


def test_seannet_imports_only_the_sgdata_it_may() -> None:
    wrong = []
    for module, path in _modules("seannet"):
        allowed = SEANNET_MAY_IMPORT
        if module == "seannet.data.live_views":
            allowed += LIVE_VIEWS_MAY_IMPORT
        allowed += DETECTION_MAY_IMPORT.get(module, ())
        for target in _imports(path, "sgdata"):
            if not any(target == a or target.startswith(a + ".") for a in allowed):
                wrong.append(f"{module} imports {target}")
    assert wrong == []


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


@pytest.mark.parametrize("package", ["sgdata", "seannet"])
def test_every_module_says_its_job_in_a_docstring(package: str) -> None:
    missing = [
        str(path.relative_to(ROOT))
        for _, path in _modules(package)
        if not ast.get_docstring(ast.parse(path.read_text(encoding="utf-8")))
    ]
    assert missing == []


# seannet's faces are lazy: importing one loads torch only when a name that needs it is used,
# and the data stage never loads torchvision's model code
@pytest.mark.parametrize(
    ("statement", "banned"),
    [
        ("import seannet", ("torch",)),
        ("import seannet.data, seannet.model, seannet.training", ("torch",)),
        ("import seannet.evaluation, seannet.navigation", ("torch",)),
        ("from seannet.data import TripletDataset", ("torchvision.models", "seannet.model")),
    ],
)
def test_seannet_faces_load_lazily(statement: str, banned: tuple[str, ...]) -> None:
    code = f"import sys; {statement}; print(','.join(sorted(sys.modules)))"
    loaded = (
        subprocess.run(
            [sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=ROOT
        )
        .stdout.strip()
        .split(",")
    )
    assert [m for m in loaded if m in banned or m.startswith(tuple(b + "." for b in banned))] == []
