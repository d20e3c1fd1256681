"""The import structure: layers point one way (studies → design → planning → kin), the parts of
``studies`` point one way too (the command line on top, the study engine below it, reports and plots
below that; :data:`STUDIES_PARTS`), a bundled study stands alone, and no module imports itself back
through a circle.

Every ``import``/``from … import`` in every module counts, including those inside functions and
under ``if TYPE_CHECKING`` (a circle that only typing hides is still a circle).  A ``from P import
name`` where ``P.name`` is a module is an import of that module; importing a name from a package is
an import of the package's ``__init__``.
"""
from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
LAYERS = ["kin", "planning", "design", "studies"]     # each may import only those before it (and itself)
#: what each part of ``studies`` may import of ``studies`` besides itself.  "studies" stands for the
#: package's own modules (studies/*.py: units, strict JSON, joint paths, task rows, published values),
#: the bottom: they import no sub-package.  The command line is on top and nothing imports it; the
#: benchmarks use the bottom only.
STUDIES_PARTS = {
    "studies": set(),
    "studies.toolpaths": set(),
    "studies.shape": {"studies"},
    "studies.report": {"studies", "studies.shape"},
    "studies.plots": {"studies"},
    "studies.study": {"studies", "studies.shape", "studies.report", "studies.plots", "studies.toolpaths"},
    "studies.bundled": {"studies", "studies.shape", "studies.study", "studies.report", "studies.plots",
                        "studies.toolpaths"},
    "studies.benchmarks": {"studies"},
    "studies.export": {"studies"},
    "studies.view": {"studies", "studies.shape", "studies.report", "studies.plots", "studies.export"},
    "studies.cli": {"studies", "studies.study", "studies.report", "studies.plots", "studies.toolpaths",
                    "studies.bundled", "studies.export", "studies.view", "studies.shape"},
}
#: folders of ``studies`` that hold data only, no Python: bundled sweep files, design tasks, work cells
STUDIES_DATA = {"studies.sweeps", "studies.tasks", "studies.cells"}


def _modules() -> dict[str, Path]:
    mods = {}
    for top in LAYERS:
        for path in (ROOT / top).rglob("*.py"):
            parts = list(path.relative_to(ROOT).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts.pop()
            mods[".".join(parts)] = path
    return mods


MODULES = _modules()


def _imports(name: str, path: Path) -> set[str]:
    """The project modules ``name`` imports (resolved to the deepest module that exists)."""
    tree = ast.parse(path.read_text(), filename=str(path))
    is_pkg = path.name == "__init__.py"
    out: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = name.split(".") if is_pkg else name.split(".")[:-1]
                base = base[: len(base) - (node.level - 1)]
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
            targets = [f"{mod}.{a.name}" if f"{mod}.{a.name}" in MODULES else mod for a in node.names]
        else:
            continue
        for t in targets:
            while t and t not in MODULES:
                t = t.rpartition(".")[0]
            if t and t != name:
                out.add(t)
    return out


GRAPH = {name: _imports(name, path) for name, path in MODULES.items()}


def _layer(mod: str) -> int:
    return LAYERS.index(mod.split(".")[0])


def test_the_walk_sees_the_project():
    # a walk that found nothing would pass everything below
    assert {"kin", "kin.chain", "planning.windows", "design.workspace", "studies.cli.main"} <= set(MODULES)
    assert "kin.chain" in GRAPH["kin.robot"]
    assert "planning.windows" in GRAPH["planning.toolpath.check"]


@pytest.mark.parametrize("name", sorted(MODULES))
def test_imports_point_down(name):
    upward = sorted(t for t in GRAPH[name] if _layer(t) > _layer(name))
    assert not upward, f"{name} ({LAYERS[_layer(name)]}) imports a higher layer: {upward}"


# ---- the parts of studies ------------------------------------------------------------------------------
def _part(mod: str) -> str:
    """The part of ``studies`` a module belongs to: its sub-package, or "studies" for the package's own modules."""
    head = ".".join(mod.split(".")[:2])
    return head if head in STUDIES_PARTS else "studies"


STUDIES_MODULES = sorted(m for m in MODULES if m.split(".")[0] == "studies")
BUNDLED_STUDIES = sorted(m for m in MODULES if m.startswith("studies.bundled."))


def test_every_folder_of_studies_has_its_place():
    # a new sub-package would otherwise count as the bottom and pass everything below
    folders = {f"studies.{d.name}": d for d in (ROOT / "studies").iterdir() if d.is_dir() and d.name != "__pycache__"}
    assert set(folders) == (set(STUDIES_PARTS) | STUDIES_DATA) - {"studies"}
    for name in STUDIES_DATA:
        assert not list(folders[name].rglob("*.py")), f"{name} is listed as data only"
    assert {_part(m) for m in STUDIES_MODULES} == set(STUDIES_PARTS)
    assert BUNDLED_STUDIES and "studies.study.context" in GRAPH["studies.study.run"]


def test_the_parts_of_studies_form_no_circle():
    assert _cycles({part: set(allowed) for part, allowed in STUDIES_PARTS.items()}) == []


@pytest.mark.parametrize("name", STUDIES_MODULES)
def test_parts_of_studies_point_down(name):
    part = _part(name)
    allowed = STUDIES_PARTS[part]
    wrong = sorted(t for t in GRAPH[name] if t.split(".")[0] == "studies" and _part(t) not in allowed | {part})
    assert not wrong, (f"{name} ({part}) imports {wrong}; {part} may import "
                       f"{', '.join(sorted(allowed)) or 'no other part of studies'}")


@pytest.mark.parametrize("name", BUNDLED_STUDIES)
def test_a_bundled_study_stands_alone(name):
    """A bundled study is a plain script: copied anywhere it runs, so it imports nothing of
    studies.bundled, nothing relative and nothing private (a module or name starting with "_")."""
    tree = ast.parse(MODULES[name].read_text(), filename=str(MODULES[name]))
    bad = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            pairs = [(a.name, None) for a in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module != "__future__":
            if node.level:
                bad.append(f"relative import (line {node.lineno})")
                continue
            pairs = [(node.module, a.name) for a in node.names]
        else:
            continue
        for module, attr in pairs:
            if module.split(".")[0] not in LAYERS:
                continue                                    # numpy, matplotlib, the standard library
            private = [p for p in module.split(".") + ([attr] if attr else []) if p.startswith("_")]
            if private or module.startswith("studies.bundled") or attr and module == "studies" and attr == "bundled":
                bad.append(f"{module}{'.' + attr if attr else ''} (line {node.lineno})")
    assert not bad, f"{name} imports what a copy of it would not have: {bad}"


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components with more than one module (Tarjan, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    comps = []
    counter = 0
    for root in graph:
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on.add(root)
        while work:
            v, it = work[-1]
            for w in it:
                if w not in index:
                    index[w] = low[w] = counter
                    counter += 1
                    stack.append(w)
                    on.add(w)
                    work.append((w, iter(sorted(graph[w]))))
                    break
                if w in on:
                    low[v] = min(low[v], index[w])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[v])
                if low[v] == index[v]:
                    comp = []
                    while True:
                        w = stack.pop()
                        on.discard(w)
                        comp.append(w)
                        if w == v:
                            break
                    if len(comp) > 1:
                        comps.append(sorted(comp))
    return comps


def test_cycle_finder_finds_a_circle():
    assert _cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert _cycles({"a": {"b"}, "b": set()}) == []


def test_no_import_circles():
    circles = _cycles(GRAPH)
    assert not circles, "modules that import each other in a circle: " + "; ".join(" ↔ ".join(c) for c in circles)
