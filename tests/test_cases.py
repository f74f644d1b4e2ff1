"""The paper-cube case, its metrics and its report."""
import json
from html.parser import HTMLParser

import numpy as np
import pytest

from conftest import floats_in

from cases.measuring import metrics as M
from cases.cli import main
from cases.library.common import PAPER_LAYERS_MM as LAYERS_MM
from cases.library.paper_cube import SIZE_MM, make_mesh, static_bc
from cases.reporting.report import TIMING_KEYS
from model.material import Material
from model import PRESETS, ModelError
from reference import linear

FILES = ["metrics.json", "report.md", "report.html", "errors.png",
         "reaction_time.png", "run.json"] + [f"{kind}_{mesh}_{bc}.png" for kind in ("fig1", "profile")
                                 for mesh in ("five", "six") for bc in ("clamped", "sliding")]
KEYS = ["mesh", "bc", "model", "disp_rel_l2_p1", "disp_rel_l2_p2", "disp_max_rel_p2",
        "reaction_ratio", "stress_corr", "bulge_profile_mm", "bulge_profile_fem_mm",
        "alternation_rel",
        "reaction_time_rel_l2", "disp_end_push_rel_l2", "rest_time_s",
        "modal_rel_err", "modal_rel_err_free", "rigid_modes_free", "dyn_failed_dt4",
        "verdict_changes_dt4"]


def test_quick_run_writes_every_file_with_finite_metrics(quick):
    """The quick paper-cube run writes every report, figure and data file; metrics.json holds
    one run per mesh, base and model (each preset and the literal reading) with every
    expected key, only finite numbers, and no timings, commit or date. Those go to run.json,
    and one .vtu file is written per run plus FEM P2 per mesh and base."""
    for f in FILES:
        assert (quick / f).is_file(), f
    data = json.loads((quick / "metrics.json").read_text())
    runs = data["runs"]
    # meshes x conditions x every preset and the gated literal reading
    assert len(runs) == 2 * 2 * (len(PRESETS) + 1)
    assert {r["mesh"] for r in runs} == {"five", "six"}
    for r in runs:
        for k in KEYS:
            assert k in r, k
        assert all(np.isfinite(v) for v in floats_in(r))
        assert len(r["bulge_profile_mm"]) == len(LAYERS_MM)
        assert r["rigid_modes_free"] == 6 and r["modal_rel_err_free"] > 0
        # the sliding base poses no modal problem (two held corner nodes): not compared
        assert (r["modal_rel_err"] is None) == (r["bc"] == "sliding")
        if not r["dyn_failed"] and r["bc"] != "sliding":   # sliding: not scored
            assert r["reaction_time_rel_l2"] > 0 and (r["rest_time_s"] is None
                                                           or r["rest_time_s"] > 1.0)
        # quick mode repeats at dt/4 only the runs that blew up at dt
        assert (r["verdict_changes_dt4"] is None) == (r["dyn_failed"] is None)
    md = (quick / "report.md").read_text()
    assert "Only the dynamic runs that blew up at the case's step dt are repeated" in md
    env = data["environment"]
    assert {"python", "numpy", "numba", "scikit-fem"} <= set(env)
    # what changes between identical runs lives in run.json (ignored by git), not here
    assert not {"git_commit", "date"} & set(env)
    assert not any(k in r for r in runs for k in TIMING_KEYS)
    run = json.loads((quick / "run.json").read_text())
    assert {"git_commit", "date", "timings"} <= set(run) and len(run["timings"]) == len(runs)
    # every preset, the literal reading and FEM P2
    assert len(list((quick / "vtu").glob("*.vtu"))) == 2 * 2 * (len(PRESETS) + 2)


def test_the_full_setting_repeats_every_dynamic_run_at_a_quarter_of_the_step():
    """repeat_dt4 = "every" (the full run's): a run that comes to rest at dt is run again at
    dt/4, which does not change its verdict; the report says every run was repeated."""
    from cases.library.paper_cube import CASE
    from cases.running.runner import run
    s = CASE.settings(quick=True, repeat_dt4="every", meshes=("five",), bcs=("clamped",),
                      models=("msm",))
    (r,), _ = run(CASE, s, log=False)
    assert r["dyn_failed"] is None and r["dyn_failed_dt4"] is None
    assert r["verdict_changes_dt4"] is False
    assert CASE.story().notes_for(s)[0].startswith("The dynamic run is repeated at a quarter")
    with pytest.raises(ModelError, match="repeat_dt4 must be one of 'every', 'blew up'"):
        CASE.settings(quick=True, repeat_dt4="some")


def test_html_parses_and_every_figure_exists(quick):
    """report.html parses and holds at least one image per PNG file, each embedded as base64
    with a data-src naming an existing file; every image report.md links exists and report.md
    has a Findings section."""
    class Images(HTMLParser):
        def __init__(self):
            super().__init__()
            self.images = []

        def handle_starttag(self, tag, attrs):
            if tag == "img":
                self.images.append(dict(attrs))

    parser = Images()
    parser.feed((quick / "report.html").read_text())
    parser.close()
    assert len(parser.images) >= len([f for f in FILES if f.endswith(".png")])
    for img in parser.images:
        assert img["src"].startswith("data:image/png;base64,")
        assert (quick / img["data-src"]).is_file()
    md = (quick / "report.md").read_text()
    for name in [line.split("](")[1].rstrip(")") for line in md.splitlines()
                 if line.startswith("![")]:
        assert (quick / name).is_file()
    assert "## Findings" in md


def test_same_command_gives_the_same_metrics(quick, tmp_path):
    """A second, narrower run reproduces the first one's runs exactly (timings aside)."""
    out = tmp_path / "again"
    assert main(["run", "paper-cube", "--quick", "--meshes", "five", "--models",
                 "pbcm-corner", "pbcm-variational", "msm", "--out", str(out)]) == 0
    first = {(r["mesh"], r["bc"], r["model"]): r
             for r in json.loads((quick / "metrics.json").read_text())["runs"]}
    for r in json.loads((out / "metrics.json").read_text())["runs"]:
        ref = first[(r["mesh"], r["bc"], r["model"])]
        for k in r:
            if k not in TIMING_KEYS:
                assert r[k] == ref[k], k


def test_fem_against_itself_has_zero_error_and_alternation():
    """Linear P2 FEM compared with itself on the five mesh gives zero displacement errors and
    no alternation on either base (none readable on the clamped base, below 1e-12 on the
    sliding base), and the sliding base's layer profile is the uniform lateral expansion
    0.45 x 1.7e-3 / 2 m."""
    mesh = make_mesh("five")
    L = SIZE_MM * 1e-3
    layers = [y * 1e-3 for y in LAYERS_MM]
    for bc in ("clamped", "sliding"):
        u = linear.solve(mesh, Material(10e3, 0.45), static_bc(mesh, bc), element="P2").u
        assert M.rel_l2(u, u) == 0 and M.max_rel(u, u) == 0
        profile = M.layer_profile(mesh.points, u, layers, L)
        free = np.ones(len(profile), bool)
        if bc == "clamped":
            free[[0, -1]] = False
        amplitude, relative = M.alternation(profile, profile, free)
        if bc == "clamped":     # three free layers: no alternation can be told apart
            assert amplitude is None
        else:
            assert abs(amplitude) < 1e-12 * np.abs(profile).max() and abs(relative) < 1e-12
        if bc == "sliding":  # homogeneous: uniform lateral expansion nu * 1.7 / 32 * 16 mm
            assert np.allclose(profile, 0.45 * 1.7e-3 / 2, rtol=1e-9)


def test_paper_pattern_is_the_sign_pattern_of_the_second_differences():
    """paper_pattern holds for an alternating five-layer profile and not for a barrel, a
    uniform profile, or a uniform profile carrying rounding noise of 1e-14."""
    alternating = np.array([1.0, 0.4, 1.0, 0.4, 1.0])
    barrel = np.sin(np.pi * np.linspace(0, 1, 5)) + 0.2
    assert M.paper_pattern(alternating) and not M.paper_pattern(barrel)
    assert not M.paper_pattern(np.full(5, 0.38))
    noisy = 0.3825 + 1e-14 * np.array([1, -1, 1, -1, 1])  # a uniform FEM profile's rounding
    assert not M.paper_pattern(noisy)


def test_metrics_refuse_nan_and_zero_references():
    """rel_l2 raises MetricError for a non-finite value and for a zero reference, and
    correlation raises it for a constant input, each message naming the cause."""
    with pytest.raises(M.MetricError, match="not finite"):
        M.rel_l2(np.array([[np.nan, 0, 0]]), np.ones((1, 3)))
    with pytest.raises(M.MetricError, match="reference is zero"):
        M.rel_l2(np.ones((2, 3)), np.zeros((2, 3)))
    with pytest.raises(M.MetricError, match="constant"):
        M.correlation(np.ones(4), np.arange(4.0))


@pytest.mark.parametrize("argv,word", [(["run", "no-case"], "case"),
                                       (["run", "paper-cube", "--models", "fem9"], "model"),
                                       (["run", "paper-cube", "--meshes", "hex"], "mesh"),
                                       (["run", "paper-cube", "--bcs", "glued"], "boundary condition")])
def test_bad_names_exit_2_listing_valid_ones(argv, word, capsys):
    """`pbcm run` with an unknown case, model, mesh or boundary condition exits 2 with a
    single stderr line saying 'unknown <kind>' and listing the valid names."""
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and f"unknown {word}" in err and "valid:" in err


def test_list(capsys):
    """`pbcm list` exits 0 and its output names the paper-cube case, the
    pbcm-variational+normal model and the unstructured mesh family."""
    assert main(["list"]) == 0
    out = capsys.readouterr().out
    assert "paper-cube" in out and "pbcm-variational+normal" in out and "unstructured" in out


def test_paper_cube_conclusion_groups_the_artefact_by_model():
    """The first line names each model once with where it shows the pattern, says it is the
    paper's 5-layer view that decides nothing, and names the converged FEM's showing of it."""
    from cases.library.narratives import paper_cube as R
    from cases.library.paper_cube import Config
    run = dict(model="msm", mesh="five", bc="sliding", disp_rel_l2_p2=0.1, paper_pattern=True,
               alternation_rel=0.07)
    runs = [run, dict(run, model="pbcm-balanced", alternation_rel=0.03), dict(run, mesh="six")]
    first = R.conclusion(Config(), runs)[0]
    assert first.startswith("In the paper's own 5-layer view (which cannot tell a smooth bump "
                            "from an alternation, so it decides nothing")
    assert first.endswith("the paper's bulge/neck sign pattern with an alternation of at least "
                          "0.01 of the mean lateral displacement shows in msm (on "
                          "five/sliding, six/sliding) and pbcm-balanced (on five/sliding), not "
                          "in the converged FEM.")
    faint = [dict(run, alternation_rel=0.001)]
    assert R.conclusion(Config(), faint)[0].endswith(
        "no model shows the paper's bulge/neck sign pattern with an alternation of at least 0.01 "
        "of the mean lateral displacement, nor does the converged FEM.")
    assert "and in the converged FEM on five/sliding." in R.conclusion(
        Config(), [dict(run, paper_pattern_fem=True)])[0]


def test_rankings_tie_models_within_u_num_of_a_groups_first():
    """A model within the reference's u_num of the first of its group shares its rank, never
    through the previous model only (no chains), and each names the models within u_num of
    it: a, b, c at 0.10, 0.105, 0.115 with u 0.01 give a and b tied and c a group of its own;
    the caveat appears where u_num exceeds a fifth of the smallest error; a model below five
    times u_num is not judged, so the line names no closest among them and the table shares
    their rank; against a closed form there are no ties."""
    from cases.library.narratives import sentences as common
    runs = [{"model": m, "mesh": "five", "bc": "clamped", "err": e, "p2_error_estimate": 0.01}
            for m, e in (("a", 0.10), ("b", 0.105), ("c", 0.115), ("d", 0.30))]
    (table,) = common.ranking(runs, "err", "error")
    assert [r[2] for r in table.rows] == ["a", "b", "c", "d"]
    alone = " (the reference's estimate: a field has no one value to spread over the meshes)"
    within = f"u_val 0.01, which is u_num here{alone}"
    assert [r[-1] for r in table.rows] == [f"tied with b (within {within})",
                                           f"tied with a (within {within})", "", ""]
    assert [r[1] for r in table.rows] == [1, 1, 3, 4]
    line = common.best_and_worst(runs, "err", "Error")
    assert "from a (" in line and "to d (" in line and ": b." in line
    assert "cannot judge" not in line           # 0.01 < 0.10 / 5
    coarse = [dict(r, p2_error_estimate=0.03) for r in runs]
    blind = common.best_and_worst(coarse, "err", "Error")
    assert "not judged below 5 times the reference's u_num (0.15): a (0.1), b (0.105), " \
           "c (0.115); above it, d (median 0.3" in blind and "from" not in blind
    (table,) = common.ranking(coarse, "err", "error")
    assert [r[1] for r in table.rows] == [1, 1, 1, 4]
    some = [dict(r, p2_error_estimate=0.0205) for r in runs]   # 5 u = 0.1025: a alone below
    assert "not judged below 5 times the reference's u_num (0.1): a (0.1)" in \
        common.best_and_worst(some, "err", "Error")
    exact = common.best_and_worst(coarse, "err", "Error", exact=True)
    assert "Tied" not in exact and "cannot judge" not in exact


def test_ties_widen_to_the_continuums_spread_over_the_meshes():
    """u_num combines the estimate and the continuum's spread over the meshes in quadrature:
    two meshes whose references give 1.0 and 1.1 (spread 0.095 > estimate 0.01) tie errors
    0.10 and 0.15, and the note says the spread set it; where each mesh poses its own
    continuum problem the spread is no uncertainty and the two are not tied."""
    from cases.reporting import rankings
    runs = [{"model": m, "mesh": mesh, "bc": "clamped", "q_rel_err": e, "q_mm": 1.0,
             "q_fem_mm": ref, "p2_error_estimate": 0.01}
            for mesh, ref in (("five", 1.0), ("six", 1.1)) for m, e in (("a", 0.10), ("b", 0.15))]
    u, defect = rankings.uncertainty(runs, "q_rel_err")
    assert u == pytest.approx(np.hypot(0.01, 0.1 / 1.05)) and defect
    (table,) = rankings.ranking(runs, "q_rel_err", "error")
    assert table.rows[1][-1].endswith("tied with a (within u_val 0.096, which is u_num here, "
                                      "mostly the continuum's spread over the meshes)")
    # a field (no continuum value of its own) carries the spread the same reference shows
    # on its scalar values; a scalar whose own values agree reads its own
    field = [dict(r, w_l2=0.1) for r in runs]
    assert rankings.uncertainty(field, "w_l2") == (pytest.approx(0.01), False)
    assert rankings.uncertainty(field, "w_l2", spread_keys=("q_fem_mm",)) == (
        pytest.approx(np.hypot(0.01, 0.1 / 1.05)), True)
    agree = [dict(r, w_rel_err=0.1, w_mm=1.0, w_fem_mm=2.0) for r in runs]
    assert rankings.uncertainty(agree, "w_rel_err", spread_keys=("q_fem_mm",)) == (
        pytest.approx(0.01), False)
    per = rankings.uncertainty(runs, "q_rel_err", per_mesh=True)
    assert per == (pytest.approx(0.01), False)       # each mesh its own problem: no spread
    (own,) = rankings.ranking(runs, "q_rel_err", "error", per_mesh=("clamped",))
    assert "tied" not in own.rows[1][-1]     # 0.05 apart, beyond the estimate alone


def test_rankings_keep_populations_apart_and_count_failed_runs():
    """A patch test (sliding, exact for some) and a clamped cube are never pooled: each bc is
    ranked on its own, each cell 'median [min-max], n of N runs'; a run that gave no value
    counts against its model as infinitely wrong (ranked, never left out), so a model that
    failed half its runs is never named closest, however small its values."""
    from cases.reporting import rankings
    runs = []
    for mesh, (a, b, c) in (("five", (1e-10, 0.02, 0.01)), ("six", (1e-10, 0.04, None))):
        runs += [{"model": "a", "mesh": mesh, "bc": "sliding", "err": a},
                 {"model": "b", "mesh": mesh, "bc": "clamped", "err": b},
                 {"model": "c", "mesh": mesh, "bc": "clamped", "err": c},
                 {"model": "a", "mesh": mesh, "bc": "clamped", "err": 0.06}]
    (table,) = rankings.ranking(runs, "err", "error")
    assert table.rows[0] == ["sliding", 1, "a", "< 1e-08", "< 1e-08", "2 of 2", ""]
    clamped = [r for r in table.rows if r[0] == "clamped"]
    assert clamped[0] == ["clamped", 1, "b", "0.03", "0.02-0.04", "2 of 2", ""]
    assert clamped[1][1:4] == [2, "a", "0.06"]
    assert clamped[2] == ["clamped", 3, "c", "failed at the median", "0.01-0.01", "1 of 2",
                          "1 failed, counted against it"]
    line = rankings.best_and_worst(runs, "err", "Error")
    assert "[clamped] Error against its reference (total error" in line
    assert "from b (" in line and "to c (" in line
    assert "Failed runs, counted against their model: c (1 of 2)" in line
    assert line.index("[sliding]") < line.index("a alone (") < line.index("[clamped]")


def test_a_quantity_fem_p1_itself_fails_on_is_not_ranked():
    """Where FEM P1 (the twin of either regime) fails at the median of a population, the
    meshes do not resolve the quantity: the line ranks no model and names every failure;
    where it fails in fewer runs the models are ranked as usual."""
    from cases.reporting import rankings
    runs = [{"model": m, "mesh": mesh, "bc": "clamped", "err": v}
            for mesh in ("five", "six", "bcc", "unstructured")
            for m, v in (("a", 0.2), ("b", 0.3), ("fem-linear", None if mesh != "five" else 0.1))]
    line = rankings.best_and_worst(runs, "err", "Error")
    assert ("Error against its reference (total error, the mesh's discretisation error "
            "included: not a ranking of the models, which the model-form error is): not "
            "ranked: FEM P1 itself fails at the median (fem-linear 3 of 4), so these meshes "
            "do not resolve it. Failed runs, counted against their model: fem-linear "
            "(3 of 4).") == line
    one = [dict(r, err=0.1) if r["model"] == "fem-linear" and r["mesh"] == "six" else r
           for r in runs]
    assert "not ranked" not in rankings.best_and_worst(
        [dict(r, err=0.1) if r["model"] == "fem-linear" and r["mesh"] == "bcc" else r
         for r in one], "err", "Error")


def test_failures_name_every_phase_that_found_no_equilibrium():
    """The failures line says which runs found no equilibrium in the linear regime and which
    at the case's load (where a reference of it exists), and claims 'every model found its
    equilibrium' only of the phases where none failed."""
    from cases.reporting import rankings
    ok = {"mesh": "five", "bc": "clamped", "static_failed": None, "finite_failed": None,
          "nh_error_estimate": 0.01}
    runs = [dict(ok, model="a"), dict(ok, model="b", finite_failed="no convergence")]
    line = rankings.failures(runs)
    assert line == ("No converged static solve at the case's load for b on five/clamped. Every "
                    "model's static solve converged in the linear regime on every mesh "
                    "run.")
    assert rankings.failures([dict(ok, model="a")]) == (
        "Every model's static solve converged in the linear regime and at the case's load "
        "on every mesh run.")


def test_errors_over_free_components_leave_out_what_is_prescribed():
    """Two nodes, node 0 prescribed (equal in model and reference): the relative error is the
    free node's alone, worked by hand; without the mask the prescribed value dilutes it."""
    ref = np.array([[3.0, 0.0, 4.0], [0.0, 1.0, 0.0]])
    u = ref + np.array([[0.0, 0.0, 0.0], [0.0, 0.5, 0.0]])
    free = np.array([[False] * 3, [True] * 3])
    assert M.rel_l2(u, ref, free) == pytest.approx(0.5)
    assert M.rel_l2(u, ref) == pytest.approx(0.5 / np.sqrt(26.0))
    assert M.max_rel(u, ref, free) == pytest.approx(0.5)
    assert M.max_rel(u, ref) == pytest.approx(0.1)
    with pytest.raises(M.MetricError, match="mask"):
        M.rel_l2(u, ref, free[:1])


def test_energy_norm_of_a_homogeneous_strain_and_of_rigid_motions():
    """u = eps x on a cube: u.K u = V (lambda tr(eps)^2 + 2 mu eps:eps) (twice the energy,
    closed form); an infinitesimal rotation has zero energy, which holds only with the
    node-major ordering the metric assumes."""
    from model.mesh import cube
    E, nu = 10e3, 0.3
    lam, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
    mesh = cube(3, 0.02, "six")
    K = linear.p1_stiffness(mesh, Material(E, nu))
    eps = np.array([[1.0, 0.3, 0.0], [0.3, -0.5, 0.2], [0.0, 0.2, 0.4]]) * 1e-3
    u = mesh.points @ eps.T
    V = 0.02 ** 3
    assert u.ravel() @ (K @ u.ravel()) == pytest.approx(
        V * (lam * np.trace(eps) ** 2 + 2 * mu * np.sum(eps * eps)), rel=1e-12)
    w = np.array([0.2, -0.1, 0.3]) * 1e-3
    rot = np.cross(w, mesh.points)
    assert M.energy_rel(u + rot, u, K) == pytest.approx(0.0, abs=1e-7)
    assert M.energy_rel(1.1 * u, u, K) == pytest.approx(0.1, rel=1e-12)


def test_stiffer_than_fem_is_said_run_by_run():
    """A statement of direction (stiffer or softer than FEM) is made run by run, never of a
    median that hides a run going the other way."""
    from cases.reporting import rankings
    runs = [{"model": "msm", "mesh": "five", "bc": "clamped", "ratio": 1.2},
            {"model": "msm", "mesh": "six", "bc": "clamped", "ratio": 0.63},
            {"model": "fem", "mesh": "five", "bc": "clamped", "ratio": 1.01},
            {"model": "fem", "mesh": "six", "bc": "clamped", "ratio": 1.02},
            {"model": "soft", "mesh": "five", "bc": "clamped", "ratio": 0.9},
            {"model": "soft", "mesh": "six", "bc": "clamped", "ratio": None}]
    line = rankings.per_run(runs, lambda r: None if r["ratio"] is None else r["ratio"] > 1,
                            "Stiffer than FEM")
    assert line == ("Stiffer than FEM in every run: fem; in some runs: msm (on five/clamped, "
                    "1 of 2); in none: soft.")


def test_a_fluttering_run_is_unstable_whatever_step_it_ran_at():
    """Growth above half the damping is flutter even when the run came to rest at its step
    (pbcm-balanced on four mesh/bc pairs rested at dt and blew up at dt/4)."""
    from cases.library.paper_cube import FLUTTER, dynamic_verdict
    rested = {"growth_rate_1_s": 30.0, "dyn_failed": None, "dyn_at_rest": True}
    assert dynamic_verdict(rested, damping=50.0) == FLUTTER
    assert dynamic_verdict(dict(rested, growth_rate_1_s=24.9), 50.0) == "at rest"
    assert dynamic_verdict(dict(rested, growth_rate_1_s=0.0, dyn_failed="x"), 50.0) == "blew up"


def test_the_sliding_cube_is_a_patch_test_passed_by_fem_alone(quick):
    """The homogeneous sliding cube: linear FEM is exact to the solver, the geometrically
    nonlinear baselines are off only by the linear regime's own nonlinearity (strains of
    1e-4: about 5e-5), well below the tolerance, and the particle readings' consistency
    errors are above it; the report says which pass."""
    from cases.measuring.metrics import PATCH_TOL
    runs = {(r["mesh"], r["model"]): r for r in
            json.loads((quick / "metrics.json").read_text())["runs"] if r["bc"] == "sliding"}
    for mesh in ("five", "six"):
        assert runs[(mesh, "fem-linear")]["disp_rel_l2_p2"] < 1e-8
        assert 1e-6 < runs[(mesh, "fem-neohookean")]["disp_rel_l2_p2"] < PATCH_TOL / 10
    assert runs[("six", "pbcm-variational")]["disp_rel_l2_p2"] > 10 * PATCH_TOL
    md = (quick / "report.md").read_text()
    assert "passed by fem-corotated, fem-linear, fem-neohookean; failed by" in md


def test_a_wide_table_is_split_and_each_part_keeps_the_row_names():
    """A table wider than MAX_COLUMNS is split into parts of at most MAX_COLUMNS columns that
    each repeat the row-naming columns (one by default, two with keys=2); _inline_html
    renders bold, links report.md as report.html and escapes angle brackets."""
    from cases.reporting.document import MAX_COLUMNS, Document, _inline_html
    d = Document("t")
    d.table(["model"] + [f"m{k}" for k in range(20)], [["a"] + list(range(20))])
    parts = [b for b in d.blocks if b[0] == "table"]
    assert [len(b[1]) for b in parts] == [10, 10, 3]
    assert all(b[1][0] == "model" and b[2][0][0] == "a" for b in parts)
    assert parts[2][1] == ["model", "m18", "m19"] and parts[2][2] == [["a", 18, 19]]
    d2 = Document("t")
    d2.table(["case", "metric"] + list("abcdefghij"), [["c", "m"] + list(range(10))], keys=2)
    assert [b[1][:2] for b in d2.blocks] == [["case", "metric"]] * 2
    assert max(len(b[1]) for b in d2.blocks) <= MAX_COLUMNS
    assert _inline_html("**A** [b](x/report.md) <c>") == (
        "<strong>A</strong> <a href='x/report.html'>b</a> &lt;c&gt;")


def test_linearisation_error_is_fem_linear_against_neohookean_p1_per_base():
    """fem-linear's linearisation error at the case's load is its displacement against
    neo-Hookean P1 on the same mesh (its model-form error there), one boundary condition at
    a time, beside its total against the reference (which holds P1's discretisation error
    too), never the difference of two norms."""
    from cases.reporting.rankings import _linearisation
    runs = [{"mesh": m, "bc": bc, "model": model, "disp_rel_l2_nh": v, "disp_rel_l2_nh_p1": p}
            for m, bc, model, v, p in (("five", "clamped", "fem-linear", 0.1565, 0.01),
                                       ("five", "clamped", "fem-neohookean", 0.1563, 0.0),
                                       ("six", "clamped", "fem-linear", 0.40, 0.02),
                                       ("six", "clamped", "fem-neohookean", 0.39, 0.0),
                                       ("five", "sliding", "fem-linear", 0.0252, 0.0252),
                                       ("five", "sliding", "fem-neohookean", 1e-5, 0.0))]
    clamped, sliding = _linearisation(runs)
    assert clamped.startswith("[clamped]")
    assert "displacement field's distance to neo-Hookean P1 on the same mesh (a field norm; the index's linearisation error is the case's quantity instead) " \
           "median 0.015 [0.01-0.02], 2 of 2 runs" in clamped
    assert "total against the neo-Hookean reference median 0.278 [0.157-0.4]" in clamped
    assert sliding.startswith("[sliding]") and "0.0252" in sliding


def test_the_sliding_bases_dynamics_are_not_scored(quick):
    """The sliding base is held laterally at two corner nodes, so the push excites a motion
    no stiffness resists: its transient comparisons and rest times are n/a for every model,
    while the clamped base's are scored."""
    from cases.library.paper_cube import SCORED_DYNAMICS
    runs = json.loads((quick / "metrics.json").read_text())["runs"]
    sliding = [r for r in runs if r["bc"] == "sliding"]
    clamped = [r for r in runs if r["bc"] == "clamped" and r["model"] == "fem-linear"]
    assert sliding and all(r[k] is None for r in sliding for k in SCORED_DYNAMICS)
    assert clamped and all(r["reaction_time_rel_l2"] is not None for r in clamped)


def test_a_profiles_shape_is_read_from_its_second_differences():
    """A barrel (one bulge falling to both ends), a waist, a period-2 alternation and a
    uniform profile are named as such, so that a 5-layer score never calls a barrel an
    alternation."""
    from cases.library.narratives.paper_cube import shape
    assert shape([0.3319, 0.4375, 0.4571, 0.4375, 0.3319]) == "a barrel"
    assert shape([0.28, 0.2199, 0.2187, 0.2199, 0.28]) == "a waist"
    assert shape([0.1452, 0.1233, 0.1452, 0.1233, 0.1452]) == "alternating"
    assert shape([0.38] * 5) == "uniform"
    assert shape([0.1, 0.2, 0.3, 0.3, 0.1]) == "uneven"


def test_a_line_says_failed_at_the_median_with_the_runs_that_gave_a_number():
    """Where more of a model's runs failed than gave a number, its line gives no median: it
    says 'failed at the median' and lists the numbers the other runs gave."""
    from cases.reporting import rankings
    runs = [{"model": m, "mesh": mesh, "bc": "clamped", "err": e, "p2_error_estimate": 0.01}
            for mesh, (a, b) in (("five", (0.1, 0.226)), ("six", (0.1, None)),
                                 ("bcc", (0.1, None)), ("unstructured", (0.1, None)))
            for m, e in (("a", a), ("b", b))]
    line = rankings.best_and_worst(runs, "err", "Error")
    assert "to b (failed at the median: 1 of 4 runs gave 0.226)" in line
    assert "b (3 of 4)" in line


def test_the_modal_table_counts_the_clamped_runs_it_reports():
    """The paper cube's modal column is the clamped base's: its failed runs (a mode unpaired)
    are counted over the clamped runs alone, never with the sliding base's, whose modal
    problem is not scored."""
    from types import SimpleNamespace
    from cases.library.narratives.paper_cube import _dynamics
    runs = [{"model": "a", "mesh": m, "bc": bc, "dyn_verdict": "at rest", "dyn_failed": None,
             "dyn_failed_dt4": None, "rigid_modes_free": 6, "growth_rate_1_s": 0.0,
             "reaction_time_rel_l2": 0.1, "modal_rel_err": 0.2,
             "modes_unpaired_held": lost if bc == "clamped" else None}
            for m, lost in (("five", 0), ("six", 2)) for bc in ("clamped", "sliding")]
    cfg = SimpleNamespace(damping=50.0, models=["a"], transient_element="P2")
    (table,) = [t for t in _dynamics(runs, cfg) if not isinstance(t, str)]
    assert table.rows == [["a", "0.1 to 0.1", "0.2; 1 of 2 runs failed (unpaired modes)"]]


def test_the_sliding_bases_blow_ups_are_said_apart_from_the_scored_clamped_ones():
    """The paper cube's blow-ups are counted on the clamped base, the one scored; the sliding
    base's (an ill-posed modal problem) are reported apart and never pooled with them."""
    from cases.library.narratives.paper_cube import _blow_ups
    runs = [{"model": "a", "bc": "clamped", "dyn_failed": None},
            {"model": "a", "bc": "sliding", "dyn_failed": "blew up"},
            {"model": "b", "bc": "clamped", "dyn_failed": "blew up"},
            {"model": "b", "bc": "sliding", "dyn_failed": None}]
    assert _blow_ups(runs) == ("Dynamic runs on the clamped base blow up for b (1 of 1 runs); "
                               "on the sliding base (ill-posed: reported, not scored) blow up "
                               "for a (1 of 1 runs).")
