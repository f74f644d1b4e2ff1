"""The case library on the declarative framework: every registered case is discovered and
run in quick mode (its values held by the gate's gold), the loads reach the particle model as
consistent nodal forces, and a failing run is recorded while the case goes on."""
import json
import math
from pathlib import Path

import numpy as np
import pytest

from conftest import floats_in

from cases.cli import main
from cases.measuring import catalogue
from cases.framework import Case, Narrative, Settings
from cases.registry import CASES
from model.errors import MeshError
from model.loads import body_forces, traction_forces
from model.mesh import box, cube

ROOT = Path(__file__).resolve().parents[1]
LIBRARY = [name for name in CASES if name != "paper-cube"]   # the paper cube: `quick`


def test_every_case_declares_the_contract():
    """Every registered case is a Case named by its registry key, with a Settings class, an
    error (direction max) as headline, a Narrative of its own, tuples of gated metrics,
    columns and string notes that the catalogue knows, quick settings within its meshes, and
    gated directions among max, min and signed."""
    for name, case in CASES.items():
        assert isinstance(case, Case) and case.name == name
        assert issubclass(case.settings_class, Settings)
        assert catalogue.metric(case.headline).direction == "max"   # an error
        story = case.story()
        assert isinstance(story, Narrative) and story.case is case
        assert all(isinstance(t, tuple) for t in (case.gated, case.columns, story.notes))
        assert all(isinstance(line, str) for line in story.notes)
        for name in case.gated + case.columns:
            catalogue.metric(name)
        s = case.settings(quick=True)
        assert s.quick and set(s.meshes) <= set(case.meshes)
        assert set(catalogue.gated(*case.gated).values()) <= {"max", "min", "signed"}


PROSE = ("notes", "notes_for", "what_was_run", "references_line", "conclusion", "findings",
         "cell", "sections")


def test_a_case_declares_physics_and_its_narrative_holds_the_prose():
    """A case class declares the physics only: every report hook lives in its narrative (a
    Narrative subclass); a case without one is told by the default narrative, whose hooks
    say nothing of their own; a narrative's notes must be a tuple."""
    for case in CASES.values():
        assert not set(PROSE) & set(vars(type(case))), type(case).__name__
        assert type(case.story()) is not Narrative
    bare = type("Bare", (Case,), {"name": "bare", "title": "a bare case",
                                  "mesh": lambda self, family, s: None,
                                  "dirichlet": lambda self, mesh, bc, s: {}})()
    told = bare.story()
    assert type(told) is Narrative and told.case is bare
    s = Settings()
    assert (told.notes_for(s), told.what_was_run(s, []), told.conclusion(s, []),
            told.findings(s, [])) == ((), [], [], {})
    assert told.references_line(s).startswith("References: linear FEM P1 on the same mesh")
    with pytest.raises(TypeError, match="notes must be a tuple"):
        type("Loose", (Narrative,), {"notes": "one line"})


@pytest.mark.parametrize("name", LIBRARY)
def test_quick_case_writes_report_and_finite_metrics(library, name):
    """Each library case's quick run writes metrics.json, report.md, report.html and
    errors.png; its metrics record the case, quick mode, E = 10 kPa and nu = 0.45, one run
    per declared model with every gated key, only finite numbers and some headline value. The
    report opens with two to five lines including the glossary link, has grouped findings and
    no Definitions section, and every image it links exists."""
    out = library / name
    for f in ("metrics.json", "report.md", "report.html", "errors.png"):
        assert (out / f).is_file(), f
    data = json.loads((out / "metrics.json").read_text())
    assert data["case"] == name and data["parameters"]["quick"]
    assert data["params"]["E_Pa"] == 10e3 and data["params"]["nu"] == 0.45
    runs = data["runs"]
    assert {r["model"] for r in runs} == set(CASES[name].models)
    headline = data["headline"]
    assert any(r.get(headline) is not None for r in runs), "no run gave the headline metric"
    for r in runs:
        for k in data["gated"]:
            assert k in r, k
        for v in floats_in(r):
            assert math.isfinite(v)
    md = (out / "report.md").read_text()
    # at most three lines of conclusion, then the glossary's link, before anything else
    head = [line for line in md.split("## ")[0].strip().splitlines()[1:] if line.strip()]
    assert 2 <= len(head) <= 5 and any("[glossary](../glossary.md)" in line for line in head)
    assert "## Definitions" not in md                           # one glossary for all
    assert "## Findings" in md and "### " in md                # grouped findings
    for img in [line.split("](")[1].rstrip(")") for line in md.splitlines()
                if line.startswith("![")]:
        assert (out / img).is_file()
    # a quick run's every order and verdict says where it is read that it decides nothing;
    # the bench's costs and the failed runs are facts of the runs, stated as they are
    findings = md.split("## Findings")[1].split("\n## ")[0]
    for heading in [line for line in findings.splitlines() if line.startswith("### ")]:
        facts = any(heading == f"### {t}" for t in ("Cost", "Failures",
                                                     "Runs that could not start"))
        assert facts or heading.endswith(f"quick: not decided, `pbcm run {name}` decides)"), \
            heading


def test_quick_library_passes_the_committed_bounds(library, capsys):
    """The quick runs of the whole library pass `pbcm check` against the committed gold,
    models without gold counting as new."""
    # --allow-new: a preset or term added since the bounds were blessed is new, not failed
    status = main(["check", "--metrics", str(library), "--gold",
                   str(ROOT / "gold"), "--allow-new"])
    out = capsys.readouterr().out
    assert status == 0, out[-3000:]


def test_traction_becomes_consistent_nodal_forces():
    """A uniform traction on the x = L face of a box: the nodal forces sum to traction x area,
    act only on that face, and their moment about the face centre is zero (by hand: the face
    is 16 x 8 mm, the load 3 Pa along -y)."""
    mesh = box(5, 3, 4, 0.032, 0.016, 0.008, "six")
    f = traction_forces(mesh, 0, 0.032, (0.0, -3.0, 0.0))
    assert f.sum(axis=0) == pytest.approx([0.0, -3.0 * 0.016 * 0.008, 0.0], abs=1e-18)
    loaded = np.flatnonzero(np.abs(f).sum(axis=1) > 0)
    assert np.allclose(mesh.points[loaded, 0], 0.032)
    arm = mesh.points[loaded, 2] - 0.004
    assert (arm * f[loaded, 1]).sum() == pytest.approx(0.0, abs=1e-18)
    # corner nodes of a structured face carry less than interior ones
    assert f[loaded, 1].min() < f[loaded, 1].max() < 0


def test_body_force_becomes_a_quarter_of_each_tetrahedron():
    """A uniform body force gives nodal forces summing to the force density times the cube's
    volume, and node 0 receives a quarter of the force on each tetrahedron it belongs to."""
    mesh = cube(3, 0.032, "five")
    f = body_forces(mesh, (0.0, -9810.0, 0.0))
    assert f[:, 1].sum() == pytest.approx(-9810.0 * 0.032**3, rel=1e-12)
    i = 0
    assert f[i, 1] == pytest.approx(-9810.0 * mesh.volumes[(mesh.tets == i).any(axis=1)].sum()
                                    / 4, rel=1e-12)


def test_self_weight_fem_is_the_closed_form_and_torsion_is_saint_venant_order(library):
    """The sliding self-weight reference is exact (P2 reproduces the quadratic closed form);
    the torsion reference is Saint-Venant's torque within a few per cent (its end effect)."""
    sw = json.loads((library / "self-weight" / "metrics.json").read_text())
    r = next(r for r in sw["runs"] if r["bc"] == "sliding")
    assert r["top_settlement_fem_mm"] == pytest.approx(r["top_settlement_cf_mm"], rel=1e-8)
    tor = json.loads((library / "torsion" / "metrics.json").read_text())
    fem = tor["runs"][0]["torque_fem_nm"]
    assert 0.98 < fem / tor["closed_form"]["torque_nm"] < 1.05


def test_cantilever_metrics_carry_its_problem_and_closed_form(library):
    """The cantilever's metrics record its geometry, load and material (1 mN on a 64 mm
    beam), a closed-form tip deflection equal to the Timoshenko formula worked by hand, a FEM
    tip deflection 85-100 % of it (the clamped root is stiffer), and per run the tip
    deflection, P2 displacement error and stress correlation."""
    d = json.loads((library / "cantilever" / "metrics.json").read_text())
    assert {"length_mm", "height_mm", "width_mm", "load_N", "E_Pa", "nu"} <= set(d["params"])
    assert d["params"]["load_N"] == 1e-3 and d["params"]["length_mm"] == 64.0
    # by hand: P L^3 / 3EI + P L / (5/6 G A) with I = 16^4 / 12 mm^4
    E, nu, P, L, a = 10e3, 0.45, 1e-3, 0.064, 0.016
    by_hand = P * L**3 / (3 * E * a**4 / 12) + P * L / (5 / 6 * E / (2 * (1 + nu)) * a * a)
    assert d["closed_form"]["tip_deflection_mm"] == pytest.approx(by_hand * 1e3, rel=1e-12)
    fem = d["reference"]["tip_deflection_mm"]
    assert 0.85 < fem / d["closed_form"]["tip_deflection_mm"] < 1.0   # a clamped root: stiffer
    for r in d["runs"]:
        assert "tip_deflection_mm" in r and "disp_rel_l2_p2" in r and "stress_corr" in r


def test_scorecard_index(library):
    """The scorecard index opens with the 'Which reading?' section listing every paper-cube
    model above the scorecard, links each case's report, marks quick mode, and colours the
    HTML cells."""
    from cases.reporting.index import index_documents
    md, html = index_documents(library, list(CASES))
    assert md.split("\n\n")[1].startswith("**Which reading?**")
    answers = md.split("## Scorecard")[0]
    assert all(f"| {m} |" in answers for m in json.loads(
        (library / "paper-cube" / "metrics.json").read_text())["parameters"]["models"])
    # one row per population: each case's first boundary condition links its report
    assert all(f"[{name}/" in md and f"({name}/report.md)" in md for name in CASES)
    assert "(quick)" in md
    assert "background:" in html


class Broken(Case):
    """A case whose 'six' mesh cannot be built: its runs are recorded as failed and the other
    mesh still runs."""

    name = "broken"
    title = "a test case"
    meshes = ("five", "six")
    models = ("msm",)

    def mesh(self, family, s):
        if family == "six":
            raise MeshError("no six mesh here")
        return cube(3, 0.032, family)

    def dirichlet(self, mesh, bc, s):
        out = {int(i): (0.0, 0.0, 0.0) for i in mesh.nodes_on_plane("y", 0.0)}
        out.update({int(i): (0.0, -1e-3, 0.0) for i in mesh.nodes_on_plane("y", 0.032)})
        return out

    def driven(self, mesh, bc, s):
        return mesh.nodes_on_plane("y", 0.032), 1


def test_a_failed_mesh_is_recorded_and_the_case_goes_on(tmp_path):
    """A case whose six mesh cannot be built records those runs as failed with the mesh
    error, while the five-mesh run completes with positive metrics and the report lists the
    runs that could not start."""
    from cases.reporting.report import write_case
    from cases.running.runner import run
    case = Broken()
    s = case.settings()
    runs, fields = run(case, s, log=False)
    bad = [r for r in runs if r["mesh"] == "six"]
    good = [r for r in runs if r["mesh"] == "five"]
    assert bad and all(r["failed"].startswith("mesh: no six mesh") for r in bad)
    assert good and good[0]["failed"] is None
    assert good[0]["reaction_ratio"] > 0 and good[0]["disp_rel_l2_p2"] > 0
    write_case(tmp_path, case, s, runs, fields)
    assert "Runs that could not start" in (tmp_path / "report.md").read_text()


@pytest.mark.parametrize("quick", [True, False])
def test_a_study_takes_its_settings_back_from_the_parameters_it_recorded(quick):
    """Every study derives its settings (full, quick, given) and, for a rewrite, takes them
    back from the parameters its metrics.json records, equal to those it ran with; a selection
    it fixes is not taken."""
    from cases.registry import studies
    for name, study in studies().items():
        s = study.settings(quick=quick, E=12e3, nu=0.495, meshes=("bcc",))
        assert (s.E, s.nu, s.quick) == (12e3, 0.495, quick), name
        if "meshes" in study.selections:
            assert tuple(s.meshes) == ("bcc",), name
        elif hasattr(s, "meshes"):
            assert tuple(s.meshes) != ("bcc",), name
        recorded = json.loads(json.dumps(s.describe()))
        taken = study.settings(quick=quick, **study.recorded_settings(recorded))
        assert json.loads(json.dumps(taken.describe())) == recorded, name
