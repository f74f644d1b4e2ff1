"""The package's dependency rules, checked on its import graph (docs/architecture.md).

Every import counts, also one inside a function: an import circle that loads only because one
of its imports is deferred is still a circle.
"""
import ast
from pathlib import Path

import pytest

from cases.registry import MODULES

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("model", "reference", "cases")


def module_name(path):
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def modules():
    """{module name: source path} of every module of the three packages."""
    return {module_name(p): p for pkg in PACKAGES for p in sorted((ROOT / pkg).rglob("*.py"))}


def imports_of(name, path, known):
    """The package modules that module ``name`` imports, anywhere in its body."""
    is_package = path.name == "__init__.py"
    out = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = name.split(".") if is_package else name.split(".")[:-1]
                base = base[:len(base) - (node.level - 1)]
                source = ".".join(base + ([node.module] if node.module else []))
            else:
                source = node.module
            # `from pkg import sub` imports the submodule when there is one
            targets = [f"{source}.{a.name}" if f"{source}.{a.name}" in known else source
                       for a in node.names]
        else:
            continue
        for t in targets:
            while t and t not in known:      # `import a.b.c` of a name inside a module
                t = t.rpartition(".")[0]
            if t and t != name:
                out.add(t)
    return out


def graph():
    known = modules()
    return {name: imports_of(name, path, known) for name, path in known.items()}


def circles(g):
    """The strongly connected components of more than one module (Tarjan), sorted."""
    index, low, stack, on, out = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in sorted(g.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(g):
        if v not in index:
            visit(v)
    return sorted(out)


def layer(name):
    """model, reference, harness (flat in cases/), case (cases/library), study, tool or
    cli."""
    parts = name.split(".")
    if parts[0] != "cases":
        return parts[0]
    if len(parts) == 1:
        return "harness"
    return {"library": "case", "studies": "study", "tools": "tool", "cli": "cli"}.get(
        parts[1], "harness")


def test_the_circle_finder_finds_a_circle():
    g = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}
    assert circles(g) == [["a", "b", "c"]]
    assert circles({"a": {"b"}, "b": set()}) == []


def test_the_graph_sees_deferred_and_relative_imports():
    g = graph()
    # cases.registry imports nothing of the package statically; cases.report imports costs
    assert "cases.costs" in g["cases.report"]
    # `from ...costs import SOURCE` three levels up, in a subpackage
    assert "cases.costs" in g["cases.studies.convergence.cost"]
    assert "cases.library.common" in g["cases.library.paper_cube"]


def test_no_import_circle_anywhere():
    assert circles(graph()) == []


@pytest.mark.parametrize("low, high", [("model", "cases"), ("reference", "cases"),
                                       ("harness", "case"), ("harness", "study"),
                                       ("harness", "tool"), ("harness", "cli"),
                                       ("case", "study"), ("case", "tool"), ("case", "cli"),
                                       ("tool", "study"), ("tool", "cli"), ("study", "tool"),
                                       ("study", "cli"), ("model", "reference")])
def test_layer_never_imports_a_higher_one(low, high):
    g = graph()
    bad = sorted((a, b) for a, bs in g.items() for b in bs
                 if layer(a) == low and (b == high or layer(b) == high))
    assert bad == []


def test_no_case_imports_another():
    g = graph()
    cases = set(MODULES.values())
    bad = sorted((a, b) for a, bs in g.items() for b in bs if a in cases and b in cases)
    assert bad == []
    # a case's helper module (common geometry, a report part) imports no case either
    helpers = {m for m in g if layer(m) == "case" and m not in cases}
    assert sorted((a, b) for a in helpers for b in g[a] if b in cases) == []


def test_no_study_imports_another_studys_modules():
    g = graph()

    def study_of(m):
        parts = m.split(".")
        return parts[2] if len(parts) > 2 and parts[1] == "studies" else None

    bad = sorted((a, b) for a, bs in g.items() for b in bs
                 if study_of(a) and study_of(b) and study_of(a) != study_of(b))
    assert bad == []


def test_reference_takes_the_mesh_from_model_never_its_physics():
    g = graph()
    allowed = {"model", "model.mesh", "model.geometry", "model.bc", "model.errors",
               "model.material", "model.units"}
    used = {b for a, bs in g.items() if layer(a) == "reference" for b in bs
            if layer(b) == "model"}
    assert used <= allowed, used - allowed


def test_nothing_points_outside_the_repository():
    """A clone has no ../shared: neither the README nor the code nor docs send the reader
    there."""
    texts = [ROOT / "README.md", *ROOT.glob("docs/**/*"), *(p for pkg in PACKAGES
                                                             for p in (ROOT / pkg).rglob("*.py"))]
    bad = [str(p.relative_to(ROOT)) for p in texts if p.is_file()
           and any(s in p.read_text() for s in ("../shared", "MODEL.md", "VERDICTS.md"))]
    assert bad == []
