"""A user's own problem from the command line (`pbcm run --problem FILE.toml`, `pbcm problem
new`): the worked example of examples/cylinder against its closed form, every mistake of a
spec refused before computing, the template, and the run's folder."""
import json
import os
import re
import subprocess
import sys
import tomllib
from pathlib import Path

import meshio
import numpy as np
import pytest

from cases.cli import main
from cases.measuring.error_model import ROUND_OFF
from cases.library.problem import EXAMPLE_MESH, ProblemError, case_of, load, template
from cases.library.problem.case import on_triangles
from cases.library.problem.spec import KEYS
from model.loads import boundary_facets
from model.mesh import cube, read_with_sets
from model.units import MM

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "cylinder" / "cylinder.toml"


def example_spec():
    """The example's TOML, parsed (its numbers: the push, the material, the measures)."""
    return tomllib.loads(EXAMPLE.read_text())


def section_area(mesh, axis=2, at=0.0):
    """The area [m^2] of the mesh's boundary triangles in the plane x_axis = at: the
    cross-section of the example's prism."""
    tri = boundary_facets(mesh.tets)
    tri = tri[(np.abs(mesh.points[tri, axis] - at) < 1e-12).all(axis=1)]
    p = mesh.points[tri]
    return 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1).sum()


def run_problem(toml, out):
    assert main(["run", "--problem", str(toml), "--quick", "--models", "fem-linear", "--out",
                 str(out)]) == 0
    return json.loads((out / "metrics.json").read_text())


@pytest.fixture(scope="module")
def example_run(tmp_path_factory):
    """`pbcm run --problem examples/cylinder/cylinder.toml --quick --models fem-linear`, run
    in an empty folder without --out: written to reports/problems/cylinder there."""
    here = tmp_path_factory.mktemp("problem")
    before = os.getcwd()
    os.chdir(here)
    try:
        assert main(["run", "--problem", str(EXAMPLE), "--quick", "--models",
                     "fem-linear"]) == 0
    finally:
        os.chdir(before)
    out = here / "reports" / "problems" / "cylinder"
    return out, json.loads((out / "metrics.json").read_text())


def close(value, exact):
    return abs(value / exact - 1) <= ROUND_OFF


def test_fem_linear_reproduces_the_uniaxial_compression_closed_form(example_run):
    """On the example, a cylinder pushed along its axis between sliding ends, the strain is
    uniform: fem-linear's end force is E A strain (A the section of the mesh), its bulge at
    the rim nu strain r, and its axial displacement -strain z, to the solver's round-off, in
    the metrics.json the run writes; so are the FEM references'."""
    _, data = example_run
    spec = example_spec()
    [run] = data["runs"]
    assert run["model"] == "fem-linear" and run["failed"] is None
    mesh = load(EXAMPLE).mesh
    E, nu = spec["material"]["E"], spec["material"]["nu"]
    height = mesh.points[:, 2].max()
    strain = -spec["displacement"][0]["value"][2] * MM / height
    force = E * section_area(mesh) * strain
    for key in ("end_force_n", "end_force_fem_n", "reaction_n"):
        assert close(run[key], force), (key, run[key], force)
    radius = spec["measure"][1]["at"][0]
    for key in ("bulge_mm", "bulge_fem_mm"):
        assert close(run[key], nu * strain * radius), (key, run[key])
    z_mm = np.linspace(0.0, height / MM, spec["measure"][2]["samples"])
    for key in ("axial_mm", "axial_fem_mm"):
        assert np.allclose(run[key], -strain * z_mm, rtol=0, atol=ROUND_OFF * strain
                           * height / MM), key
    assert run["end_force_rel_err"] <= ROUND_OFF and run["axial_rel_err"] <= ROUND_OFF


def test_the_run_writes_what_a_case_writes_with_its_toml_verbatim(example_run):
    """The problem's folder, reports/problems/NAME by default, holds what a library case's
    holds (metrics.json with its name, problem and gated metrics, the report, the figures,
    the states), its headline is its first measure, and the TOML is copied byte for byte."""
    out, data = example_run
    assert (out / EXAMPLE.name).read_bytes() == EXAMPLE.read_bytes()
    assert data["case"] == "cylinder" and data["headline"] == "end_force_rel_err"
    assert {"end_force_rel_err", "bulge_rel_err", "axial_rel_err"} <= set(data["gated"])
    assert data["problem"]["mesh_sha256"] and data["problem"]["spec_sha256"]
    for name in ("report.md", "report.html", "run.json", "errors.png", "profile_axial.png"):
        assert (out / name).is_file(), name
    assert list((out / "vtu").glob("*.vtu"))
    report = (out / "report.md").read_text()
    assert "pbcm run --problem" in report and "end_force" in report
    # the glossary it links travels with it: a problem's folder lives anywhere
    assert "Definitions: [glossary](glossary.md)." in report
    assert "end_force" in (out / "glossary.md").read_text()      # its own measures defined


def test_a_problem_is_blessed_and_checked_like_a_case(example_run, tmp_path):
    """`pbcm bless` keeps a problem's quick metrics as gold and `pbcm check` passes them, in
    a fresh process too (which never read the TOML: the gate takes the direction of the
    problem's own metrics from the file)."""
    out, _ = example_run
    gold = tmp_path / "gold"
    assert main(["bless", "--metrics", str(out), "--gold", str(gold)]) == 0
    assert (gold / "cylinder.quick.jsonl").is_file()
    checked = subprocess.run([sys.executable, "-m", "cases.cli", "check", "--metrics",
                              str(out), "--gold", str(gold)], capture_output=True, text=True)
    assert checked.returncode == 0, checked.stdout + checked.stderr


def test_a_problem_the_library_gold_never_saw_is_new_not_an_error(example_run, tmp_path,
                                                                  capsys):
    """Checked against the library's gold (which knows no problem), a problem's metrics are
    'new, not gated yet' (exit 3, 0 with --allow-new), never a refusal: a user's problem
    beside the library's reports does not break the library's gate."""
    out, _ = example_run
    gold = Path(__file__).resolve().parents[1] / "gold"
    assert main(["check", "--metrics", str(out), "--gold", str(gold)]) == 3
    assert "NEW  cylinder (quick) every model: new, not gated yet" in capsys.readouterr().out
    assert main(["check", "--metrics", str(out), "--gold", str(gold), "--allow-new"]) == 0


def test_a_traction_reaches_model_and_fem_as_the_same_force(tmp_path):
    """A traction on the example's top (its push replaced by a pressure) loads model and FEM
    alike: the bottom's reaction is the traction times the section and the axial
    displacement is -t z / E, to round-off (uniaxial stress)."""
    text = EXAMPLE.read_text().replace('file = "cylinder.msh"', f'file = "{EXAMPLE_MESH}"')
    text = text.replace('name = "cylinder"', 'name = "pressed"')
    push = '[[displacement]]        # the top pushed 0.2 mm down (1 % strain), free to slide ' \
           'sideways\non = "top"\nvalue = [0.0, 0.0, -0.2]\ncomponents = ["z"]\n'
    assert push in text
    text = text.replace(push, "").replace("# [[traction]]\n# on = \"top\"\n# value = "
                                          "[10.0, 0.0, 0.0]",
                                          '[[traction]]\non = "top"\nvalue = [0.0, 0.0, -50.0]')
    text = text.replace('on = "top"\naxis = "z"', 'on = "bottom"\naxis = "z"')
    toml = tmp_path / "pressed.toml"
    toml.write_text(text)
    [run] = run_problem(toml, tmp_path / "out")["runs"]
    mesh = load(toml).mesh
    # the supports push the bottom up: the reaction, signed as the library's, reads -t A
    force = -50.0 * section_area(mesh)
    assert close(run["end_force_n"], force) and close(run["end_force_fem_n"], force)
    height = mesh.points[:, 2].max()
    assert np.allclose(run["axial_mm"], -50.0 / 10e3 * np.linspace(0, height, 11) / MM,
                       rtol=0, atol=1e-8 * 50.0 / 10e3 * height / MM)


def test_a_traction_loads_exactly_the_selected_faces():
    """The model's nodal forces of a traction sum to traction x area over the selected
    faces, and FEM's traction is the value on points of those faces and zero elsewhere on
    the boundary."""
    spec = load(EXAMPLE)
    case = case_of(spec)
    mesh = spec.mesh
    tri = boundary_facets(mesh.tets)
    top = tri[np.isin(tri, spec.selections["top"].nodes).all(axis=1)]
    loads = type(case.loads(mesh, "declared", case.settings()))(
        surfaces=((top, (0.0, 0.0, -50.0)),), points=mesh.points)
    f = loads.nodal_forces(mesh)
    assert np.allclose(f.sum(axis=0), [0, 0, -50.0 * section_area(mesh, at=0.02)])
    centre = mesh.points[top].mean(axis=1)
    side = mesh.points[tri[~np.isin(tri, top).all(axis=1)]].mean(axis=1)
    t = loads.fem_traction(1e-9 * mesh.size)(np.vstack([centre, side]), None)
    assert np.allclose(t[:len(centre)], [0, 0, -50.0]) and not t[len(centre):].any()
    assert on_triangles(centre[None], mesh.points[top], 1e-12).all()


def test_gravity_acts_along_minus_up():
    """Gravity g loads the body with rho g along -up, the axis [mesh] up names."""
    text = EXAMPLE.read_text().replace("gravity = 0.0", "gravity = 9.81")
    data = tomllib.loads(text)
    from cases.library.problem.spec import parse
    spec = parse(data, EXAMPLE)
    case = case_of(spec)
    s = case.settings()
    assert np.allclose(case.loads(spec.mesh, "declared", s).body_force, [0, 0, -1000 * 9.81])


# ---------------------------------------------------------------- refused before computing

# (what is changed in the example, the key the message names)
BAD = [
    ('unit = "mm"\n', "", "mesh.unit"),                                   # missing key
    ("E = 10e3 ", "# E", "material.E"),
    ('name = "cylinder"', "", "missing key name"),
    ('unit = "mm"', 'uint = "mm"', "mesh.uint"),                          # unknown key
    ("gravity = 0.0", "gravty = 0.0", "unknown key gravty"),
    ('samples = 11', 'samples = 11\nstep = 2', "measure[3].step"),
    ('bottom = { axis = "z", at = 0.0 }', 'bottom = { axis = "z", at = 25.0 }',
     "select.bottom"),                                                    # selects no node
    ("min = [-0.1, -0.1, -0.1], max = [0.1, 0.1, 0.1]",
     "min = [5.1, 5.1, -0.1], max = [5.2, 5.2, 0.1]", "select.centre: selects no node"),
    ("min = [-0.1, -0.1, -0.1]", "min = [5.1, 5.1, -0.1]", "select.centre.max"),
    ('top = { set = "top" }', 'top = { set = "lid" }', "select.top.set"),
    ('bottom = { axis = "z", at = 0.0 }', 'bottom = { axis = "z", min = [0, 0, 0] }',
     "select.bottom"),
    ('unit = "mm"', 'unit = "kg"', "mesh.unit"),                          # not a length
    ('file = "cylinder.msh"', 'file = "missing.msh"', "mesh.file"),      # no such mesh
    ('name = "cylinder"', 'name = "cantilever"', "name"),                 # a library case
    ('name = "cylinder"', 'name = "../up"', "name"),                      # not a folder name
    ('on = "rim"\nfixed = ["y"]', 'on = "rim"\nfixed = ["z"]', "displacement"),   # rotation free
    ('on = "top"\naxis = "z"', 'on = "top"\naxis = "x"', "measure[1].on"),  # no reaction there
    ('name = "end_force"\nkind = "reaction"', 'name = "end_force"\nkind = "force"',
     "measure[1].kind"),
    ("through = [0.0, 0.0, 0.0]", "through = [50.0, 0.0, 0.0]", "measure[3].through"),
    ('on = "bottom"\nfixed = ["z"]', 'on = "top"\nfixed = ["z"]', "displacement[2].on"),
    ('name = "end_force"', 'name = "reaction"', "measure[1].name"),     # a suite's metric
    ('name = "bulge"', 'name = "tip_deflection"', "measure[2].name"),
    ("nu = 0.45", "nu = 0.5", "material.nu"),
    ("E = 10e3", 'E = "soft"', "material.E"),
    ("# models = [", "models = [\"no-such-model\"]\n# [", "models"),
    ("gravity = 0.0", "gravity = ", "not a valid TOML file"),
]


@pytest.mark.parametrize("old, new, key", BAD, ids=[b[2] + ":" + b[1][:20] for b in BAD])
def test_a_bad_spec_is_refused_before_computing_naming_the_key(old, new, key, tmp_path,
                                                               capsys, monkeypatch):
    """Every mistake of a spec (a missing or unknown key, a selection of no node, a unit that
    is not a length, a mesh file that does not exist, a clashing name, free rigid motions...)
    is one line `pbcm: error: FILE: KEY: ...` with exit status 2, before any computing and
    without an output folder."""
    import cases.running.runner

    def computing(*args, **kw):
        raise AssertionError("the run started computing")
    monkeypatch.setattr(cases.running.runner, "run", computing)
    text = EXAMPLE.read_text()
    assert old in text
    text = text.replace(old, new, 1).replace('file = "cylinder.msh"',
                                             f'file = "{EXAMPLE_MESH}"')
    toml = tmp_path / "bad.toml"
    toml.write_text(text)
    out = tmp_path / "out"
    assert main(["run", "--problem", str(toml), "--quick", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and err.startswith("pbcm: error: "), err
    assert key in err, err
    assert not out.exists()


def test_the_command_line_refuses_what_the_toml_declares(capsys):
    """--problem takes its mesh, bcs and material from the TOML: --meshes, --bcs, --E, --nu
    and --rho are refused naming the key to edit; a case name with --problem, or neither,
    too."""
    for extra, said in ((["--meshes", "five"], "[mesh] file"), (["--E", "5"], "[material] E"),
                        (["cantilever"], "not both")):
        assert main(["run", "--problem", str(EXAMPLE), *extra]) == 2
        assert said in capsys.readouterr().err
    assert main(["run"]) == 2
    assert "--problem" in capsys.readouterr().err


# ---------------------------------------------------------------- the template


def test_the_template_parses_and_validates(tmp_path, capsys):
    """`pbcm problem new NAME --out FILE` writes a TOML that parses and validates as is (its
    mesh the shipped example's), in which every key of the schema is explained, and it
    never overwrites a file."""
    toml = tmp_path / "mine.toml"
    assert main(["problem", "new", "mine", "--out", str(toml)]) == 0
    spec = load(toml)
    assert spec.name == "mine" and spec.mesh_file.resolve() == EXAMPLE_MESH.resolve()
    assert case_of(spec).headline == "end_force_rel_err"
    comments = "\n".join(line for line in toml.read_text().splitlines()
                         if line.lstrip().startswith("#") or "#" in line)
    for table, keys in KEYS.items():
        for key in keys:
            assert re.search(rf"\b{key}\b", comments), f"{table}.{key} is not explained"
    assert main(["problem", "new", "mine", "--out", str(toml)]) == 2
    assert "exists" in capsys.readouterr().err


def test_the_worked_example_is_the_template():
    """examples/cylinder/cylinder.toml is what `pbcm problem new cylinder` writes there, so
    the example and the template cannot drift apart; its mesh is the committed one."""
    assert EXAMPLE.read_text() == template("cylinder", "cylinder.msh",
                                           "examples/cylinder/cylinder.toml")
    assert load(EXAMPLE).mesh_file.resolve() == EXAMPLE_MESH.resolve()


def test_named_sets_come_from_point_sets_cell_sets_and_physical_groups(tmp_path):
    """A selection `set = NAME` finds a point set, a cell set (the nodes of its cells) and a
    Gmsh physical group of the mesh file, in the mesh's own node numbering."""
    m = cube(3, 1.0, "six")
    path = tmp_path / "c.inp"
    meshio.write(path, meshio.Mesh(m.points, [("tetra", m.tets)],
                                   point_sets={"corner": np.array([0, 1])},
                                   cell_sets={"first": [np.array([0])]}))
    mesh, sets = read_with_sets(path)
    assert sets["corner"].tolist() == [0, 1]
    assert sets["first"].tolist() == sorted(m.tets[0].tolist())
    _, physical = read_with_sets(EXAMPLE_MESH)
    assert {"bottom", "top", "side", "body"} <= set(physical)
    assert len(physical["body"]) == mesh_nodes(EXAMPLE_MESH)


def mesh_nodes(path):
    return len(meshio.read(path).points)


def test_a_problem_error_is_a_pbcm_error():
    """Spec errors are the package's errors (the command line prints them as one line)."""
    from model import PbcmError
    assert issubclass(ProblemError, PbcmError)
