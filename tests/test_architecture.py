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
            # `from pkg import sub` imports the submodule when there is one, and runs the
            # package's __init__ first: both are imported
            targets = [f"{source}.{a.name}" if f"{source}.{a.name}" in known else source
                       for a in node.names] + [source]
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
    """The circle finder reports a three-module import cycle as one sorted component, leaves out a
    module that only imports into the cycle, and reports no circle for an acyclic graph."""
    g = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}
    assert circles(g) == [["a", "b", "c"]]
    assert circles({"a": {"b"}, "b": set()}) == []


def test_the_graph_sees_deferred_and_relative_imports():
    """The import graph turns relative imports into edges to the named package modules: the report
    imports the costs module, the convergence study's cost module imports it from three levels
    up, and the paper-cube case imports the common geometry module; an import inside a
    function (the index's of the answers module) is an edge too."""
    g = graph()
    # cases.registry imports nothing of the package statically; cases.reporting.report imports costs
    assert "cases.reporting.costs" in g["cases.reporting.report"]
    # `from ...costs import SOURCE` three levels up, in a subpackage
    assert "cases.reporting.costs" in g["cases.studies.convergence.cost"]
    assert "cases.library.common" in g["cases.library.paper_cube"]
    # `from . import answers` inside the index's build function only
    assert "cases.reporting.answers" in g["cases.reporting.index"]


def test_no_import_circle_anywhere():
    """The import graph of model, reference and cases, counting imports inside functions too,
    contains no circle of two or more modules."""
    assert circles(graph()) == []


@pytest.mark.parametrize("low, high", [("model", "cases"), ("reference", "cases"),
                                       ("harness", "case"), ("harness", "study"),
                                       ("harness", "tool"), ("harness", "cli"),
                                       ("case", "study"), ("case", "tool"), ("case", "cli"),
                                       ("tool", "study"), ("tool", "cli"), ("study", "tool"),
                                       ("study", "cli"), ("model", "reference")])
def test_layer_never_imports_a_higher_one(low, high):
    """No module of the lower layer of each pair imports a module of the higher one: model and
    reference never import cases, the harness never imports a case, study, tool or command, and
    model never imports reference."""
    g = graph()
    bad = sorted((a, b) for a, bs in g.items() for b in bs
                 if layer(a) == low and (b == high or layer(b) == high))
    assert bad == []


def test_no_case_imports_another():
    """No case module imports another case; a case's helper modules import no case except a
    narrative importing its own case, and every narrative module belongs to a case or is the
    shared sentences module."""
    g = graph()
    cases = set(MODULES.values())
    bad = sorted((a, b) for a, bs in g.items() for b in bs if a in cases and b in cases)
    assert bad == []
    # a case's helper module (common geometry) imports no case either, and a case's
    # narrative (its report prose) imports its own case alone
    helpers = {m for m in g if layer(m) == "case" and m not in cases}
    own = {f"cases.library.narratives.{m.rsplit('.', 1)[1]}": m for m in cases}
    assert sorted((a, b) for a in helpers for b in g[a] if b in cases and own.get(a) != b) == []
    shared = {"cases.library.narratives.sentences"}     # the prose every narrative shares
    assert {a for a in helpers if a.startswith("cases.library.narratives.")} <= set(own) | shared


def test_no_study_imports_another_studys_modules():
    """No module of one study under cases/studies imports a module of another study."""
    g = graph()

    def study_of(m):
        parts = m.split(".")
        return parts[2] if len(parts) > 2 and parts[1] == "studies" else None

    bad = sorted((a, b) for a, bs in g.items() for b in bs
                 if study_of(a) and study_of(b) and study_of(a) != study_of(b))
    assert bad == []


def _reference_may_take():
    """The model modules docs/architecture.md says the references take, from its bullet
    "`reference` takes from `model` only the modules ... never its physics"."""
    import re
    text = " ".join(DOC.read_text().split())
    m = re.search(r"`reference` takes from `model` only the modules (.*?) \(", text)
    assert m, "docs/architecture.md no longer states which model modules reference takes"
    return {f"model.{n}" for n in re.findall(r"`(\w+)`", m.group(1))}


def test_reference_takes_the_mesh_from_model_never_its_physics():
    """reference imports from model only the modules the architecture doc lists."""
    g = graph()
    allowed = _reference_may_take()
    assert "model.system" not in allowed and "model.terms" not in allowed
    used = {b for a, bs in g.items() if layer(a) == "reference" for b in bs
            if layer(b) == "model"}
    assert used <= allowed, used - allowed


def test_importing_every_reference_loads_none_of_the_models_physics():
    """At run time too: a fresh interpreter that imports every reference module has loaded no
    model module beyond those the doc lists (the model package loads its physics lazily)."""
    import subprocess
    import sys
    mods = sorted(p.stem for p in (ROOT / "reference").glob("*.py") if p.stem != "__init__")
    code = ("import importlib, sys\n"
            + "".join(f"importlib.import_module('reference.{m}')\n" for m in mods)
            + "print(' '.join(m for m in sys.modules if m.startswith('model.')))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         cwd=ROOT, check=True).stdout.split()
    assert set(out) <= _reference_may_take(), set(out) - _reference_may_take()


def test_nothing_points_outside_the_repository():
    """A clone has no ../shared: neither the README nor the code nor docs send the reader
    there."""
    texts = [ROOT / "README.md", *ROOT.glob("docs/**/*"), *(p for pkg in PACKAGES
                                                             for p in (ROOT / pkg).rglob("*.py"))]
    bad = [str(p.relative_to(ROOT)) for p in texts if p.is_file()
           and any(s in p.read_text() for s in ("../shared", "MODEL.md", "VERDICTS.md"))]
    assert bad == []


DOC = ROOT / "docs" / "architecture.md"


def _rooms_table():
    """{folder: its row's text} of docs/architecture.md's rooms table."""
    out = {}
    for line in DOC.read_text().splitlines():
        cells = [c.strip() for c in line.split("|")]
        if len(cells) > 3 and cells[1].startswith("`") and cells[1].endswith("/`"):
            out[cells[1].strip("`").rstrip("/")] = cells[2]
    return out


def test_the_rooms_table_names_every_folder_of_the_harness_and_every_module_in_it():
    """docs/architecture.md's picture of the rooms is the package's: every package folder of
    cases/ has its row, every row of cases/ is a folder, and the harness's rows (cases/ itself
    and its measuring, running and reporting rooms) name every module in them."""
    rows = _rooms_table()
    folders = {str(p.parent.relative_to(ROOT)) for p in (ROOT / "cases").glob("*/__init__.py")}
    assert {f for f in rows if f.startswith("cases/")} == folders
    for folder in ("cases", "cases/measuring", "cases/running", "cases/reporting"):
        names = {p.stem for p in (ROOT / folder).glob("*.py") if p.stem != "__init__"}
        missing = sorted(n for n in names if f"`{n}`" not in rows[folder]
                         and f"`{n}.py`" not in rows[folder])
        assert missing == [], (folder, missing)


def test_the_rooms_table_names_every_module_of_model_reference_the_studies_and_the_tools():
    """The rows of model/, reference/, cases/studies/ and cases/tools/ name every module and
    sub-package in them (the command and case folders name theirs by rule: one module per
    command, one per case)."""
    rows = _rooms_table()
    for folder in ("model", "reference", "cases/studies", "cases/tools"):
        path = ROOT / folder
        names = ({p.stem for p in path.glob("*.py") if p.stem != "__init__"}
                 | {p.parent.name for p in path.glob("*/__init__.py")})
        text = rows[folder]
        missing = sorted(n for n in names if not any(
            form in text for form in (f"`{n}`", f".{n}`", f"`{n}.py`", f"`{n}/`")))
        assert missing == [], (folder, missing)


def _stated_rules():
    """[(room, [rooms it must not import])] from the doc's bullets of the form
    "`A/` imports neither `B/` nor `C/`" or "`A/` imports no `B/`"."""
    import re
    out = []
    for line in DOC.read_text().splitlines():
        m = re.match(r"- `(cases/\w+)/` imports (?:neither|no) (.*);$", line.strip())
        if m:
            out.append((m.group(1), re.findall(r"`(cases/\w+)/`", m.group(2))))
    return out


def test_the_rooms_import_as_the_doc_says():
    """Each direction the doc states between the harness's rooms holds on the import graph:
    measuring imports neither running nor reporting, running imports no reporting."""
    rules = _stated_rules()
    assert ("cases/measuring", ["cases/running", "cases/reporting"]) in rules
    assert ("cases/running", ["cases/reporting"]) in rules
    g = graph()
    for room, banned in rules:
        src, bans = room.replace("/", "."), [b.replace("/", ".") for b in banned]
        bad = sorted((a, b) for a, bs in g.items() if a.startswith(src + ".") for b in bs
                     if any(b == x or b.startswith(x + ".") for x in bans))
        assert bad == [], (room, bad)


def test_a_tool_imports_no_study_and_no_case():
    """The doc's rule for the tools holds on the import graph: no tool imports a study, and of
    the library of cases only its shared geometry."""
    text = " ".join(DOC.read_text().split())
    assert ("a tool imports no study and no case (of the library only its shared geometry, "
            "`cases.library.common`)") in text
    g = graph()
    bad = sorted((a, b) for a, bs in g.items() if a.startswith("cases.tools.") for b in bs
                 if b.startswith("cases.studies")
                 or (b.startswith("cases.library") and b != "cases.library.common"))
    assert bad == []


def test_model_and_reference_never_import_each_others_physics():
    """model never imports reference; reference takes from model only its mesh, geometry,
    boundary conditions, material, errors and units (checked above): neither imports the
    other's physics."""
    g = graph()
    assert sorted((a, b) for a, bs in g.items() if layer(a) == "model" for b in bs
                  if layer(b) == "reference") == []


def _prose_and_comments():
    """(path, text) of the README, docs/, and every docstring and comment of the packages and
    tests: where history must not be written."""
    out = [(ROOT / "README.md", (ROOT / "README.md").read_text())]
    out += [(p, p.read_text()) for p in ROOT.glob("docs/**/*") if p.is_file()
            and p.suffix in (".md", ".py")]
    for pkg in (*PACKAGES, "tests"):
        out += [(p, p.read_text()) for p in (ROOT / pkg).rglob("*.py")]
    return out


def test_the_readme_is_a_guide_of_at_most_300_lines_opening_on_the_answers():
    """The README is a user's guide: at most 300 lines, linking the answers
    (reports/index.md) before its first section, with the install and report commands each on
    a line of their own."""
    text = (ROOT / "README.md").read_text()
    assert len(text.splitlines()) <= 300
    head = text.split("\n## ", 1)[0]
    assert "reports/index.md" in head
    lines = {line.strip() for line in text.splitlines()}
    assert {"pip install -e .", "pbcm report"} <= lines


def test_no_issue_number_or_commit_hash_in_the_readme_docs_docstrings_or_comments():
    """History lives in commit messages: neither the README, the docs, nor the code and tests
    name an issue number or a commit hash."""
    import re
    issue = re.compile(r"\bissues? #?\d+\b|#\d{2,}\b", re.I)
    commit = re.compile(r"\b(?:commit|since|at) [0-9a-f]{7,40}\b")
    bad = [(str(p.relative_to(ROOT)), m.group(0)) for p, t in _prose_and_comments()
           for m in (*issue.finditer(t), *commit.finditer(t))]
    assert bad == []


def test_every_test_states_the_requirement_it_checks():
    """Every test function in tests/ has a docstring: the requirement it checks."""
    import ast
    bare = []
    for p in sorted((ROOT / "tests").glob("*.py")):
        for n in ast.walk(ast.parse(p.read_text())):
            if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef)) and n.name.startswith(
                    "test"):
                if not ast.get_docstring(n):
                    bare.append(f"{p.name}::{n.name}")
    assert bare == []
