"""The real-time study on a user's problem (`pbcm run realtime --problem FILE.toml`): the
problem carried to every mesh of its refinement family as the FEM references carry it, a
uniform stress reproduced on a refined level, the study's folder, a rerun drawn from the
same timings, and bad options refused before computing."""
import json
import os
from pathlib import Path

import numpy as np
import pytest

from cases.cli import main
from cases.library.problem import EXAMPLE_MESH, load
from cases.library.problem.family import family, levels_for
from cases.measuring.error_model import ROUND_OFF
from cases.running import store as S
from model import build
from model.bc import Proportional, bc_arrays
from model.units import MM

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "cylinder" / "cylinder.toml"
PUSH = ('[[displacement]]        # the top pushed 0.2 mm down (1 % strain), free to slide '
        'sideways\non = "top"\nvalue = [0.0, 0.0, -0.2]\ncomponents = ["z"]\n')
PRESSURE = 50.0          # [Pa] on the top of the pressed variant


def pressed(tmp_path, gravity=0.0):
    """The example with its push replaced by a pressure on the top (the reaction measured on
    the bottom), and ``gravity``: a TOML file in ``tmp_path``."""
    text = EXAMPLE.read_text().replace('file = "cylinder.msh"', f'file = "{EXAMPLE_MESH}"')
    text = text.replace('name = "cylinder"', 'name = "pressed"')
    assert PUSH in text
    text = text.replace(PUSH, "").replace(
        "# [[traction]]\n# on = \"top\"\n# value = [10.0, 0.0, 0.0]",
        f'[[traction]]\non = "top"\nvalue = [0.0, 0.0, {-PRESSURE}]')
    text = text.replace('on = "top"\naxis = "z"', 'on = "bottom"\naxis = "z"')
    text = text.replace("gravity = 0.0", f"gravity = {gravity}")
    toml = tmp_path / "pressed.toml"
    toml.write_text(text)
    return toml


def test_a_proportional_ramp_scales_every_prescribed_value():
    """A whole boundary condition ramped: at t every prescribed value is t / t_ramp of its
    end value (then held), the free components stay free, and the velocity is the end value
    over the ramp's time while it lasts."""
    bc = {0: (1.0, None, -2.0), 3: (None, 0.5, None), 4: (0.0, 0.0, 0.0)}
    ramp = Proportional(bc, 2.0)
    mask, end = bc_arrays(bc, 5)
    for t, k in ((0.0, 0.0), (0.5, 0.25), (2.0, 1.0), (3.0, 1.0)):
        m, u = ramp.arrays(t, 5)
        assert np.array_equal(m, mask) and np.array_equal(u, k * end)
        assert ramp(t)[0] == (k * 1.0, None, k * -2.0)
    assert np.array_equal(ramp.velocity(1.0, 5), end / 2.0)
    assert not ramp.velocity(2.5, 5).any()


def test_the_family_refines_until_its_size_and_carries_the_supports():
    """The example's family: the mesh, then each level eight times its tetrahedra, up to the
    first with at least min_tets (a quick run: at most the first two); on every level the sliding ends hold z on exactly the
    nodes of their planes, the point supports stay single nodes, and the reaction is summed
    over the top plane's nodes."""
    spec = load(EXAMPLE)
    assert levels_for(288) == 4 and levels_for(288, min_tets=2304) == 2
    assert levels_for(288, quick=True) == 2
    # a mesh already that large is its own family, in a quick run too
    assert levels_for(150_000) == 1 and levels_for(150_000, quick=True) == 1
    fam = family(spec, min_tets=3000)
    assert [lv.mesh.n_tets for lv in fam] == [288, 2304, 18432]
    assert fam[0].dirichlet == spec.dirichlet and fam[0].mesh is spec.mesh
    top_z = spec.mesh.points[:, 2].max()
    for lv in fam:
        p = lv.mesh.points
        ends = np.flatnonzero(np.isclose(p[:, 2], 0.0, atol=1e-12)
                              | np.isclose(p[:, 2], top_z, atol=1e-12))
        held_z = sorted(i for i, u in lv.dirichlet.items() if u[2] is not None)
        assert held_z == ends.tolist()
        assert sum(u[0] is not None for u in lv.dirichlet.values()) == 1    # the centre
        assert sum(u[1] is not None for u in lv.dirichlet.values()) == 2    # centre, rim
        top = np.flatnonzero(np.isclose(p[:, 2], top_z, atol=1e-12))
        assert np.array_equal(lv.reaction[0], top) and lv.reaction[1] == 2
        assert all(lv.dirichlet[int(i)][2] == pytest.approx(-0.2 * MM) for i in top)


def test_a_refined_level_under_a_pressure_reproduces_uniaxial_stress(tmp_path):
    """The pressed example refined once: the traction's nodal forces sum to the pressure
    times the section on every level, and fem-linear's equilibrium there is the uniform
    stress state u_z = -t z / E at every node, to the solve's round-off; with gravity the
    loads sum to the weight rho g V on every level."""
    fam = family(load(pressed(tmp_path)), min_tets=2304)
    E = 10e3
    area = None
    for lv in fam:
        f = lv.f_ext
        if area is None:
            area = -f[:, 2].sum() / PRESSURE
        assert np.allclose(f.sum(axis=0), [0.0, 0.0, -PRESSURE * area], rtol=1e-12)
    lv = fam[1]
    pm = build("fem-linear", lv.mesh, load(pressed(tmp_path)).material)
    st = pm.solve_static(lv.dirichlet, f_ext=lv.f_ext, rtol=1e-12)
    z = lv.mesh.points[:, 2]
    scale = PRESSURE / E * z.max()
    assert np.abs(st.u[:, 2] + PRESSURE / E * z).max() <= ROUND_OFF * scale
    heavy = family(load(pressed(tmp_path, gravity=9.81)), min_tets=2304)
    weight = 1000.0 * 9.81 * area * z.max()
    for lv in heavy:
        assert lv.f_ext[:, 2].sum() == pytest.approx(-PRESSURE * area - weight, rel=1e-9)


@pytest.fixture(scope="module")
def study_run(tmp_path_factory):
    """`pbcm run realtime --problem pressed.toml --quick --models fem-linear msm`, run twice
    in an empty folder without --out, with a run store of its own that keeps timings: the
    second run is drawn from the first one's timings."""
    here = tmp_path_factory.mktemp("realtime-problem")
    toml = pressed(here)
    before, env = os.getcwd(), dict(os.environ)
    os.chdir(here)
    os.environ[S.ENV] = str(here / "store")
    os.environ[S.ENV_KINDS] = "realtime-problem-timing"
    args = ["run", "realtime", "--problem", str(toml), "--quick", "--models", "fem-linear",
            "msm"]
    try:
        assert main(args) == 0
        out = here / "reports" / "problems" / "pressed.realtime"
        first = (out / "report.md").read_bytes()
        assert main(args) == 0
    finally:
        os.chdir(before)
        os.environ.clear()
        os.environ.update(env)
    return toml, out, first, json.loads((out / "metrics.json").read_text())


def test_the_study_on_a_problem_writes_its_own_folder(study_run):
    """The problem's study is written to reports/problems/NAME.realtime (beside the
    problem's own folder, which it never touches), with the TOML verbatim, the glossary it
    links and the figure; every run is a level of the problem's mesh, the models' laws and
    FEM P1's twin solved on each, FEM P1's model-form error zero by definition, and the quick
    run says it decides nothing."""
    toml, out, _, data = study_run
    assert (out / toml.name).read_bytes() == toml.read_bytes()
    for name in ("report.md", "glossary.md", "error_vs_cost.png", "metrics.json"):
        assert (out / name).is_file(), name
    report = (out / "report.md").read_text()
    assert "Definitions: [glossary](glossary.md)." in report
    assert data["answer"].startswith("Quick: not decided")
    assert {r["mesh"] for r in data["runs"]} == {"cylinder-L0", "cylinder-L1"}
    assert {r["tets"] for r in data["runs"]} == {288, 2304}
    assert data["problem"]["mesh_sha256"] and data["problem"]["bc"] == "declared"
    for r in data["runs"]:
        assert r["cost"]["timed"] and r["failed"] is None
        assert np.isfinite(r["disp_rel_l2"]) and np.isfinite(r["disp_form_rel_l2"])
        if r["model"] == "fem-neohookean":
            assert r["disp_form_rel_l2"] == 0.0 and r["force_form_rel"] == 0.0
    assert {r["model"] for r in data["runs"]} == {"fem-linear", "msm", "fem-neohookean"}


def test_a_rerun_is_drawn_from_the_same_timings(study_run):
    """A second run on the same machine with the run store reads the first run's timings:
    its report is the same, byte for byte."""
    _, out, first, _ = study_run
    assert (out / "report.md").read_bytes() == first


def test_rewrite_draws_the_report_again_from_its_record(study_run, tmp_path, capsys):
    """--rewrite draws the problem's study again from its metrics.json without computing,
    the same report; a TOML whose problem has changed since is refused."""
    toml, out, first, _ = study_run
    assert main(["run", "realtime", "--problem", str(toml), "--out", str(out),
                 "--rewrite"]) == 0
    assert (out / "report.md").read_bytes() == first
    changed = toml.parent / "changed.toml"
    changed.write_text(toml.read_text().replace("E = 10e3", "E = 20e3"))
    assert main(["run", "realtime", "--problem", str(changed), "--out", str(out),
                 "--rewrite"]) == 2
    assert "has changed" in capsys.readouterr().err
    assert (out / "report.md").read_bytes() == first


@pytest.mark.parametrize("extra, said", [
    (["--bcs", "clamped"], "the [[displacement]] entries"),
    (["--E", "5"], "[material] E"),
    (["--rewrite"], "run it first"),
])
def test_bad_options_are_refused_before_computing(extra, said, tmp_path, capsys):
    """What the TOML declares is refused on the command line, naming the key to edit,
    before anything is computed or written."""
    out = tmp_path / "out"
    assert main(["run", "realtime", "--problem", str(EXAMPLE), "--out", str(out),
                 *extra]) == 2
    assert said in capsys.readouterr().err and not out.exists()


def test_a_missing_problem_file_is_refused(tmp_path, capsys):
    """A problem file that does not exist is refused naming it, nothing written."""
    out = tmp_path / "out"
    assert main(["run", "realtime", "--problem", str(tmp_path / "none.toml"), "--out",
                 str(out)]) == 2
    assert "none.toml" in capsys.readouterr().err and not out.exists()


def test_an_exact_yardstick_is_an_identity_check_not_a_rank():
    """Where FEM P1 with the continuum's law reproduces the continuum on every mesh (a
    homogeneous field), its distance is an identity check: it is not ranked, the others are
    ranked by their model-form errors, nothing is said to cancel P1's error, an error within
    the solves' round-off is not resolved, and the answer says so; a law more accurate on a
    smaller real-time mesh than at its reach is named; two laws tied on one mesh are tied
    within round-off there."""
    from cases.studies.realtime import report as R

    def run(model, tets, form, dist, cost):
        row = {"model": model, "law": model, "tets": tets, "mesh": f"m-{tets}", "bc": "x",
               "accuracy": True, "failed": None, "disp_form_rel_l2": form,
               "disp_rel_l2": dist, "force_form_rel": 0.0, "force_rel": 0.0,
               "load_steps": 1, "cost": {"timed": True, "model": model, "tets": tets,
                                         "wall_s_per_simulated_s": cost,
                                         "wall_range": [cost, cost], "rounds": 5}}
        return row
    runs = [run(R.P1, 100, 0.0, 2e-8, 0.1), run(R.P1, 800, 0.0, 1e-8, 0.8),
            run("a", 100, 0.05, 0.05, 0.1), run("a", 800, 0.09, 0.09, 0.8),
            run("b", 100, 0.02, 0.02, 0.1), run("b", 800, 0.02, 0.02, 2.0)]
    data = {"runs": runs, "error_estimate": 1e-13, "top_force_n": 1.0, "machine": None}
    v = R.verdict(data)
    assert v["p1_exact"] == 2e-8 and not v["cancels"]
    # an exact reference's estimate is its own round-off: the solves' sets what is judged
    assert R._judged(2e-8, v).endswith("(not resolved)") and R._judged(0.05, v) == "0.0500"
    assert [k["model"] for k in v["ranks"]] == ["b", "a"] and v["pick"] == "b"
    assert v["smaller"] == {"a": [100, 0.05 + 2e-8]}
    answer = R.answer_line(data, v, False)
    assert "identity check" in answer and "a 100 tetrahedra" in answer
    # two laws tied at one mesh, every round: tied within round-off there, no two-mesh u_val
    twin = {**data, "runs": runs + [run("c", 100, 0.02, 0.02, 0.1), run("c", 800, 0.02, 0.02,
                                                                        2.0)]}
    said = R.answer_line(twin, R.verdict(twin), False)
    assert "is tied between 2 models, within round-off on one mesh: " in said
