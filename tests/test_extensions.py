"""Normal-stress extensions ranked on the model-form error (pbcm run extensions) and parameter
identification (pbcm fit)."""
import json

import numpy as np
import pytest

from cases.cli import main
from cases.studies.extensions import STUDY
from cases.studies.extensions import report as R
from cases.studies.extensions.study import BASE, CANDIDATES, YARDSTICK, short
from cases.registry import CASES
from cases.running.runner import reaction_along, reference
from model import build
from model.terms.shear import Shear

TET = CANDIDATES[1]


def test_candidates_are_the_paper_model_plus_one_normal_form_each():
    """The candidates are the paper model plus exactly one normal-stress form each (edge, tet,
    corotated, sbd), and the tet candidate is variational shear plus volume plus normal_tet, with
    automatic constants."""
    assert [short(c) for c in CANDIDATES] == ["+normal_edge", "+normal_tet",
                                              "+normal_corotated", "+normal_sbd"]
    assert TET == "shear(reading=variational, c=auto) + volume + normal_tet(c=auto)"


def _doc(case_errors, alternation, tensors, discretisation=None):
    """A metrics document with the given per-case model-form errors {case: {model: e}} and
    FEM P1's discretisation error {case: d} (default: the yardstick's entry)."""
    models = [BASE, "m1", "m2", YARDSTICK]
    disc = discretisation or {c: es[YARDSTICK] for c, es in case_errors.items()}
    runs = [{"case": c, "mesh": "five", "bc": "clamped", "model": m, "error": e,
             "discretisation": disc[c], "failed": None,
             "alternation_rel": alternation.get(m) if c == "paper-cube" else None}
            for c, es in case_errors.items() for m, e in es.items()]
    data = {"case_runs": runs, "fits": [], "cost_vs_fem_linear": dict.fromkeys(models, 1.0),
            "elasticity": [{"model": m, "mesh": lat, "moduli_rel_err": d}
                           for m, ds in tensors.items() for lat, d in ds.items()]}
    return models, data


def test_rankings_failures_and_verdicts_worked_by_hand():
    """On a hand-worked document the geometric means of the error ratios to the paper model are 0.5
    for m1 and 1 for m2; the paper model fails on one case error, one floor and one C_eff (never
    on the alternation); and each candidate is judged to fix, worsen or not change each failure.
    The conclusion names no best, since the leave-one-population-out ranges overlap."""
    errs = {"paper-cube": {BASE: 0.2, "m1": 0.05, "m2": 0.4, YARDSTICK: 0.1},
            "cantilever": {BASE: 0.1, "m1": 0.1, "m2": 0.05, YARDSTICK: 0.1}}
    tensors = {BASE: {"six": 0.04}, "m1": {"six": 0.035}, "m2": {"six": 0.005},
               YARDSTICK: {"six": 0.0}}
    models, data = _doc(errs, {BASE: 0.05, "m1": 0.005, "m2": -0.08, YARDSTICK: 0.0}, tensors)
    data["fits"] = [{"case": "cantilever", "mesh": "six", "bc": "clamped", "model": m,
                     "verdict": v, "e_inf": e} for m, v, e in [
                         (BASE, "floor", 0.1), ("m1", "converges", 0.001), ("m2", "floor", 0.2),
                         (YARDSTICK, "converges", 0.0)]]
    rank = R.rankings(data, models)
    assert rank["floors"][BASE]["floor"] == 1 and rank["floors"]["m1"]["floor"] == 0
    # geometric means of the ratios to the base: m1 sqrt(0.25 * 1) = 0.5, m2 sqrt(2 * 0.5) = 1
    assert rank["overall"]["m1"] == pytest.approx(0.5)
    assert rank["overall"]["m2"] == pytest.approx(1.0)
    assert R.order(rank["overall"])[0] == "m1"
    fs = R.failures(rank)
    # paper-cube 0.2 > 1.5 x FEM P1's discretisation error 0.1; cantilever 0.1 is not; the
    # floor of the cantilever on six; C_eff 0.04; the paper cube's alternation (its 5-layer
    # view, which decides nothing) is no criterion
    assert [f["kind"] for f in fs] == ["case", "floor", "tensor"]
    _, table = R.fixes(rank, models)
    assert [v for _, _, v in table["m1"]] == ["fixes", "fixes", "no change"]
    assert [v for _, _, v in table["m2"]] == ["worsens", "worsens", "fixes"]
    doc = {"parameters": {"models": models}, "rankings": rank}
    text = " ".join(R.conclusion(doc))
    # leaving one population out: m1 is 0.25 (cantilever left) or 1 (paper cube left), m2
    # 0.5 or 2: the ranges overlap, so no best is named
    assert "among the normal-stress extensions not resolved between m1, m2" in text
    assert "m1 0.5 [0.25-1], m2 1 [0.5-2]; m1 not resolved from the paper model" in text
    assert "m1 fixes 2 of them: paper-cube/clamped model-form error" in text \
        and "0.2 -> 0.05" in text
    assert "m2 fixes 1 of them: C_eff on six 0.04 -> 0.005 and worsens" in text


def test_candidates_whose_ranges_overlap_share_a_rank():
    """In the ranking table a model whose range leaving one population out overlaps its group
    head's shares that rank; a model that failed has none, nor the yardstick (FEM P1 itself)."""
    rank = {"overall": {YARDSTICK: 0.0, "a": 0.5, "b": 0.51, "base": 1.0, "x": None},
            "overall_range": {YARDSTICK: [0, 0], "a": [0.45, 0.58], "b": [0.46, 0.59],
                              "base": [1, 1]}}
    assert R.shared_ranks([YARDSTICK, "a", "b", "base", "x"], rank) == {
        YARDSTICK: "-", "a": "1", "b": "1", "base": "3", "x": "-"}


def test_headline_says_when_no_candidate_beats_the_paper_model():
    """With a single population, where no leave-one-out range exists, the conclusion names no best
    candidate and says that m1 (ratio 2) is farther from FEM P1 than the paper model whichever
    population is taken."""
    errs = {"torsion": {BASE: 0.1, "m1": 0.2, "m2": 0.4, YARDSTICK: 0.1}}
    models, data = _doc(errs, {}, {})
    doc = {"parameters": {"models": models}, "rankings": R.rankings(data, models)}
    # one population: no range leaving one out, so no best is named
    assert R.conclusion(doc)[0].startswith(
        "Over the 1 populations the library averages, among the normal-stress extensions "
        "not resolved between m1, m2 (their ranges leaving one population or one mesh "
        "family out overlap): ")
    assert "m1 2, m2 4; m1 farther from FEM P1 than the paper model whichever population" in \
        R.conclusion(doc)[0]


def test_a_population_with_a_failed_run_stays_and_counts_against_its_model():
    """Every model's geometric mean is over the same populations, a candidate's failure
    among them: the model that failed has no mean, is ranked last and said failed (never a
    mean over the populations it survived); the others keep the population; the failure is
    said as 'fails' on its criterion; a patch test and a locking-prone problem are not
    pooled, and candidates identical everywhere are said to be one observation."""
    errs = {"torsion": {BASE: 0.2, "m1": None, "m2": 0.1, YARDSTICK: 0.1},
            "cantilever": {BASE: 0.1, "m1": 0.05, "m2": 0.2, YARDSTICK: 0.1}}
    models, data = _doc(errs, {}, {})
    data["case_runs"][1]["failed"] = "static: no equilibrium"
    rank = R.rankings(data, models)
    assert rank["overall_over"] == 2 and rank["overall_failed"]["m1"] == 1
    assert rank["overall"]["m1"] is None
    assert rank["overall"]["m2"] == pytest.approx(1.0)
    assert R.order(rank["overall"])[-1] == "m1"
    _, table = R.fixes(rank, models)
    assert table["m1"][0][2] == "fails"
    lead = R.conclusion({"parameters": {"models": models}, "rankings": rank})[0]
    assert "m1 failed (no result on 1 of 2 populations)" in lead and "the best is m2" in lead
    # a locking-prone problem and a patch test are shown, never pooled
    more = {**errs, "large-compression": {BASE: 0.2, "m1": 0.1, "m2": 0.1, YARDSTICK: 0.4},
            "paper-cube": {BASE: 0.1, "m1": 0.1, "m2": 0.1, YARDSTICK: 0.0}}
    _, data = _doc(more, {}, {})
    for r in data["case_runs"]:
        r["bc"] = "sliding" if r["case"] == "paper-cube" else "clamped"
    rank = R.rankings(data, models)
    assert rank["overall_over"] == 2
    assert rank["left_out"] == ["large-compression/clamped", "paper-cube/sliding"]
    # identical on every population: said as one observation
    twin = {c: {**es, "m1": es["m2"]} for c, es in errs.items()}
    _, data = _doc(twin, {}, {})
    lead = R.conclusion({"parameters": {"models": models},
                         "rankings": R.rankings(data, models)})[0]
    assert "Identical on every averaged population (one observation, not several): m1 = m2" in lead


@pytest.fixture(scope="module")
def small_study(tmp_path_factory):
    """One case and one convergence problem, quick, with the paper model, one candidate and
    the yardstick: every file and the gate rows."""
    out = tmp_path_factory.mktemp("ext")
    s = STUDY.settings(quick=True, models=(BASE, TET, YARDSTICK), cases=("cantilever",),
                       problems=("cantilever",))
    data = STUDY.run(s, log=False, bench=json.loads(
        (R.Path(__file__).resolve().parents[1] / "reports/bench/bench.json").read_text()))
    STUDY.write(out, s, data)
    return out


def test_small_study_writes_rankings_and_gate_rows(small_study):
    """A quick extensions study on the cantilever writes its Markdown and HTML reports and both
    figures, ranks the paper model's overall ratio at 1.0, takes step costs from the bench (the
    candidate above the paper model, both above fem-linear) and records gate rows for the case
    median and for C_eff on six; the candidate's C_eff error on five is below 1e-6, the paper
    model's above."""
    doc = json.loads((small_study / "metrics.json").read_text())
    for f in ("report.md", "report.html", "case_errors.png", "ceff_moduli.png"):
        assert (small_study / f).is_file()
    rank = doc["rankings"]
    assert set(rank["case_errors"]) == {"cantilever/clamped"}
    assert rank["overall"][BASE] == 1.0
    assert rank["cost"][TET] > rank["cost"][BASE] > 1.0      # the bench's ratios
    rows = {(r["mesh"], r["bc"], r["model"]) for r in doc["gate_runs"]}
    assert ("cantilever/clamped", "median", TET) in rows and ("six", "C_eff", TET) in rows
    md = (small_study / "report.md").read_text()
    assert "## Which extension fixes which failure" in md and "+normal_tet" in md
    # the candidate's C_eff on five is the target (calibration), the paper model's is not
    t = rank["tensors"]
    assert t[TET]["five"] < 1e-6 < t[BASE]["five"]


def test_rewrite_draws_the_same_report_from_the_recorded_runs(small_study, tmp_path, capsys):
    """`--rewrite` redraws report.md, metrics.json and both figures byte for byte from the recorded
    runs; a record made at other problem parameters (another nu) is refused with exit 2 and a
    message that they changed, and so is rewriting the record as the cantilever case."""
    import shutil
    copy = tmp_path / "copy"
    shutil.copytree(small_study, copy)
    (copy / "report.md").unlink()
    assert main(["run", "extensions", "--rewrite", "--out", str(copy)]) == 0
    for f in ("report.md", "metrics.json", "case_errors.png", "ceff_moduli.png"):
        assert (copy / f).read_bytes() == (small_study / f).read_bytes(), f
    doc = json.loads((copy / "metrics.json").read_text())
    doc["problem"]["nu"] = 0.3        # recorded at other parameters than the code's
    (copy / "metrics.json").write_text(json.dumps(doc))
    assert main(["run", "extensions", "--rewrite", "--out", str(copy)]) == 2
    assert "problem parameters have changed" in capsys.readouterr().err
    assert main(["run", "cantilever", "--rewrite", "--out", str(copy)]) == 2
    assert "--rewrite applies to a study" in capsys.readouterr().err


def test_its_fits_are_the_convergence_studys_rule_on_its_recorded_runs(small_study, tmp_path):
    """The extensions study's convergence fits are derived from its recorded runs by the
    convergence study's own rule, at writing and at --rewrite, so that the two reports give
    the same verdict on the same runs and a rewrite after a change of the rule follows it."""
    import shutil
    from cases.studies.convergence.study import fits
    doc = json.loads((small_study / "metrics.json").read_text())
    assert doc["conv_runs"] and doc["fits"] == json.loads(json.dumps(
        fits(doc["conv_runs"], doc["conv_references"])))
    copy = tmp_path / "copy"
    shutil.copytree(small_study, copy)
    doc["fits"] = [{**f, "verdict": "stale"} for f in doc["fits"]]   # a record of old rules
    (copy / "metrics.json").write_text(json.dumps(doc))
    assert main(["run", "extensions", "--rewrite", "--out", str(copy)]) == 0
    again = json.loads((copy / "metrics.json").read_text())
    assert "stale" not in {f["verdict"] for f in again["fits"]}
    assert again["fits"] == json.loads((small_study / "metrics.json").read_text())["fits"]


def test_fit_recovers_the_closed_form_stiffness_scale(tmp_path):
    """A single-term model under prescribed displacement: positions do not depend on the
    stiffness scale k and the reaction is k times, so the least-squares k is 1 / the reaction
    ratio of the model as built, worked out here from one static solve."""
    case = CASES["paper-cube"]
    s = case.settings(quick=True, models=("msm",), meshes=("five",), bcs=("sliding",))
    mesh = case.mesh("five", s)
    ref = reference(case, mesh, "sliding", s, Shear(mesh, s.material, reading="corner"),
                    extra=False)
    st = case.solve_linear(build("msm", mesh, s.material), mesh, "sliding", s, ref)
    ratio = (reaction_along(st.reaction, case.driven(mesh, "sliding", s)) / ref.scale
             / ref.reaction)
    out = tmp_path / "fit"
    assert main(["fit", "msm", "--cases", "paper-cube", "--meshes", "five", "--bcs",
                 "sliding", "--validate", "--quick", "--out", str(out)]) == 0
    doc = json.loads((out / "fit.json").read_text())
    assert doc["scales"]["springs"] == pytest.approx(1 / ratio, rel=1e-4)
    assert doc["constants_fitted"]["springs.k_scale"] == pytest.approx(1 / ratio, rel=1e-4)
    assert doc["identified"]["springs"]
    assert doc["train_rows"][0]["after"] < doc["train_rows"][0]["before"]
    assert "k_scale" in (out / "report.md").read_text()


@pytest.mark.parametrize("args, said", [
    (["fem-linear", "--cases", "cantilever"], "no term with a constant to fit"),
    (["msm", "--cases", "modes"], "no static displacement"),
    (["msm", "--cases", "cantilever", "--validate", "cantilever"], "both fitted on and left"),
    (["msm", "--cases", "nope"], "unknown case nope"),
])
def test_fit_refuses_before_computing(args, said, tmp_path, capsys):
    """`pbcm fit` exits 2, saying why and creating no output folder, when the model has no constant
    to fit, the case has no static displacement, a case is both fitted on and left out, or the
    case is unknown."""
    assert main(["fit", *args, "--quick", "--out", str(tmp_path / "f")]) == 2
    assert said in capsys.readouterr().err
    assert not (tmp_path / "f").exists()


def test_fit_reports_the_worst_change_on_the_cases_left_out():
    """An rms of 0.0325 -> 0.05 can hide one left-out problem going from 0.0325 to 0.186:
    the worst factor is named beside it; a problem that fails after the fit is the worst."""
    from cases.cli.fitting import worst_change
    rows = [{"problem": "a", "before": 0.0325, "after": 0.186},
            {"problem": "b", "before": 0.2, "after": 0.01}]
    w = worst_change(rows)
    assert w["problem"] == "a" and w["factor"] == pytest.approx(0.186 / 0.0325)
    assert worst_change(rows + [{"problem": "c", "before": 0.1, "after": "failed: x"}])[
        "problem"] == "c"
    assert worst_change([]) is None


def test_the_extensions_run_no_verification_they_do_not_read():
    """The extensions study reads the convergence study's fits and elasticity alone: its
    convergence run leaves out the verification ladder (minutes of a full report), which
    the convergence study itself runs."""
    s = STUDY.settings(quick=True)
    assert s.convergence_settings().verification is False
    from cases.registry import studies
    assert studies()["convergence"].settings(quick=True).verification is True


def test_a_failure_is_a_model_form_error_beyond_fem_p1s_own_distance_from_the_continuum():
    """The paper model fails a case where its model-form error exceeds FEM_FACTOR times FEM
    P1's discretisation error there (the median over the meshes, the same for every model on
    a mesh), whatever the yardstick's own model-form error."""
    errs = {"torsion": {BASE: 0.2, "m1": 0.1, "m2": 0.3, YARDSTICK: 0.0},
            "cantilever": {BASE: 0.2, "m1": 0.1, "m2": 0.3, YARDSTICK: 0.0}}
    models, data = _doc(errs, {}, {}, discretisation={"torsion": 0.1, "cantilever": 0.2})
    rank = R.rankings(data, models)
    assert rank["discretisation"] == {"torsion/clamped": 0.1, "cantilever/clamped": 0.2}
    fs = R.failures(rank)
    assert [(f["key"], f["limit"]) for f in fs] == [("torsion/clamped", pytest.approx(0.15))]
    assert fs[0]["note"] == "FEM P1's discretisation error: 0.1"


def test_each_case_row_is_the_model_form_error_of_the_cases_decomposed_quantity():
    """A case row's error is |model - P1| / |continuum| of the case's declared quantity, the P1
    twin on the same mesh and boundary condition; a run without a twin has no error."""
    from cases.studies.extensions.study import case_rows, with_p1
    case = CASES["large-compression"]
    key, cont, p1 = case.decomposed.key, case.decomposed.continuum, case.decomposed.p1
    runs = [{"mesh": "five", "bc": "clamped", "model": BASE, key: [1.2, 2.4],
             cont: [1.0, 2.0]},
            {"mesh": "five", "bc": "clamped", "model": p1, key: [1.1, 2.0], cont: [1.0, 2.0]},
            {"mesh": "six", "bc": "clamped", "model": BASE, key: [1.0, 2.0], cont: [1.0, 2.0]}]
    rows = case_rows(case, runs)
    assert rows[0]["error"] == pytest.approx(0.2) and rows[0]["discretisation"] == \
        pytest.approx(0.1)
    assert rows[1]["error"] == 0.0
    assert rows[2]["error"] is None and "no FEM P1 twin" in rows[2]["failed"]
    s = with_p1(case, case.settings(quick=True, models=(BASE,)))
    assert s.models == (BASE, p1)


def test_a_model_with_no_error_in_one_population_has_geometric_mean_zero():
    """A model exact in one population (FEM P1 against itself) has geometric mean 0, not the
    mean over the populations where it has an error."""
    errs = {"torsion": {BASE: 0.2, "m1": 0.1, "m2": 0.2, YARDSTICK: 0.0},
            "large-compression": {BASE: 0.2, "m1": 0.1, "m2": 0.2, YARDSTICK: 0.4}}
    models, data = _doc(errs, {}, {})
    assert R.rankings(data, models)["overall"][YARDSTICK] == 0.0


def test_a_floor_within_both_limits_uncertainty_is_no_change():
    """A candidate's floor differs from the paper model's by less than their +- combined:
    'no change', however large the ratio; beyond it, 'worsens'."""
    failure = {"kind": "floor", "key": "p/clamped on six", "base": 0.0778, "base_err": 0.0296,
               "limit": None}
    rank = {"floors": {"m": {"by_fit": {"p/clamped on six": ["floor", 0.107, 0.0245]}},
                       "w": {"by_fit": {"p/clamped on six": ["floor", 0.2, 0.0245]}}}}
    assert R.judge(rank, failure, "m") == (0.107, "no change")
    assert R.judge(rank, failure, "w") == (0.2, "worsens")


def test_the_sliding_cubes_stiffness_is_a_criterion_its_displacement_cannot_see():
    """The sliding cube's top displacement is prescribed, so a model can match its shape while
    soft: the paper model fails on a lattice where |ratio_inf - 1| exceeds the C_eff tolerance
    beyond its fit's +-, and a candidate whose stiffness limit comes within it fixes that."""
    fit = {"case": "paper-cube", "bc": "sliding", "mesh": "six", "verdict": "floor",
           "e_inf": 0.19, "e_inf_err": 0.03}
    data = {"fits": [{**fit, "model": BASE, "ratio_inf": 0.658, "ratio_inf_err": 1e-6},
                     {**fit, "model": "m", "ratio_inf": 0.995, "ratio_inf_err": 1e-3},
                     {**fit, "model": "w", "ratio_inf": 0.5, "ratio_inf_err": 1e-3},
                     {**fit, "model": "n", "ratio_inf": 1.02, "ratio_inf_err": 0.02,
                      "mesh": "five"}]}
    fl = R.floors(data, [BASE, "m", "w", "n"])
    assert fl[BASE]["stiffness"]["paper-cube/sliding on six"] == pytest.approx([0.342, 1e-6])
    rank = {"case_errors": {}, "floors": fl, "tensors": {}}
    (stiff,) = [f for f in R.failures(rank) if f["kind"] == "stiffness"]
    assert stiff["what"] == "stiffness of paper-cube/sliding on six"
    assert R.judge(rank, stiff, "m") == (pytest.approx(0.005), "fixes")
    assert R.judge(rank, stiff, "w") == (pytest.approx(0.5), "worsens")
    # within its +- of the tolerance: no failure (n's 0.02 +- 0.02 on five)
    assert not [f for f in R.failures({**rank, "floors": {BASE: fl["n"]}})
                if f["kind"] == "stiffness"]


def test_a_candidate_failing_where_the_paper_model_passes_is_named():
    """A criterion the paper's model meets and a candidate fails (a stiffness beyond the
    tolerance past its +-, a floor where the paper's model converges, a C_eff beyond the
    tolerance) is named as the candidate's own failure; one within its +- is not."""
    fit = {"case": "paper-cube", "bc": "sliding", "mesh": "bcc", "e_inf": 0.01,
           "e_inf_err": 0.001}
    data = {"fits": [{**fit, "model": BASE, "verdict": "converges", "ratio_inf": 0.9994,
                      "ratio_inf_err": 0.003},
                     {**fit, "model": "e", "verdict": "floor", "ratio_inf": 1.0497,
                      "ratio_inf_err": 0.0265},
                     {**fit, "model": "k", "verdict": "converges", "ratio_inf": 1.03,
                      "ratio_inf_err": 0.025}]}
    rank = {"floors": R.floors(data, [BASE, "e", "k"]),
            "tensors": {BASE: {"five": 0.005}, "e": {"five": 0.02}, "k": {"five": 0.004}}}
    assert R.new_failures(rank, "e") == [
        "stiffness of paper-cube/sliding on bcc 0.0497 +- 0.0265",
        "convergence of paper-cube/sliding on bcc (floor, e_inf 0.01 +- 0.001)",
        "C_eff on five 0.02"]
    assert R.new_failures(rank, "k") == []
    # a pass of the paper's model within its +- of failing is no contrast
    data["fits"][0].update(ratio_inf=0.994, ratio_inf_err=0.031)
    rank["floors"] = R.floors(data, [BASE, "e", "k"])
    assert not [f for f in R.new_failures(rank, "e") if f.startswith("stiffness")]


def test_the_overall_range_also_leaves_one_mesh_family_out():
    """The range of a candidate's geometric mean covers leaving one mesh family out of every
    population (the mesh is the unit of analysis), not only one population: a candidate far
    ahead on one mesh family moves the median when another family is left out."""
    runs = []
    for pop in ("a", "b"):
        for mesh, (base, cand) in {"five": (0.1, 0.01), "six": (0.1, 0.2),
                                   "bcc": (0.1, 0.2)}.items():
            for m, e in ((BASE, base), ("c", cand)):
                runs.append({"case": pop, "bc": "clamped", "mesh": mesh, "model": m,
                             "error": e, "failed": None})
    data = {"case_runs": runs}
    errors = R.case_errors(data, [BASE, "c"])
    assert R.overall(errors, [BASE, "c"])["c"] == pytest.approx(2.0)
    assert R.overall_range(errors, [BASE, "c"])["c"] == pytest.approx([2.0, 2.0])
    lo, hi = R.overall_range(errors, [BASE, "c"], data)["c"]
    assert lo == pytest.approx(1.05) and hi == pytest.approx(2.0)   # six, or five, left out


def test_a_fit_is_judged_against_fem_p1_by_default_and_the_continuum_on_request():
    """The fit's reference is FEM P1 on the same tetrahedra unless the continuum is asked for:
    its displacement, its reaction along the driven axis and its quantities; the continuum's
    are the converged P2 solution's."""
    from types import SimpleNamespace as NS
    from cases.cli.fitting import AGAINST, FitError, Problem, fit
    p1 = NS(u=np.ones((3, 3)), reaction=np.array([[0.0, -2.0, 0.0]] * 3))
    p2 = NS(u=np.full((3, 3), 2.0))
    case = NS(driven=lambda mesh, bc, s: ([0, 2], 1), qoi_errors=("tip",),
              quantities=lambda mesh, u, r, s, bc: {"tip": float(u.sum())})
    prob = Problem(case, "five", "clamped", None, None,
                   NS(p1=p1, p2=p2, reaction=9.0, quantities={"tip": 18.0}))
    u, reaction, q = prob.target("p1")
    assert u is p1.u and reaction == 4.0 and q == {"tip": 9.0}
    u, reaction, q = prob.target("continuum")
    assert u is p2.u and reaction == 9.0 and q == {"tip": 18.0}
    assert set(AGAINST) == {"p1", "continuum"}
    with pytest.raises(FitError, match="--against 'p2'"):
        fit("msm", [], [], against="p2")


def test_a_left_out_problem_that_is_a_training_problem_again_is_not_counted_as_left_out():
    """A left-out problem with the training problem's nodes and reference displacement up to a
    factor (a case scaling another's load) is one observation: named, never in the left-out
    rms or the worst change; the left-out problems are read one by one (the fit carries where
    every one improves, not where most worsen), and a quick fit says it is a preview."""
    from types import SimpleNamespace as NS
    from cases.cli.fitting import report, same_problem, worst_change
    pts = np.random.default_rng(0).random((5, 3))
    u = np.random.default_rng(1).random((5, 3))

    def prob(u_):
        return NS(mesh=NS(points=pts), ref=NS(p1=NS(u=u_)))
    assert same_problem(prob(u), prob(3 * u)) and not same_problem(prob(u), prob(u + 0.1))
    rows = [{"problem": "x/five/clamped", "before": "the training problem a",
             "after": "the training problem a", "twin": "a"},
            {"problem": "y/five/clamped", "before": 0.2, "after": 0.1}]
    assert worst_change(rows)["problem"] == "y/five/clamped"
    doc = {"model": "m", "train": ["a"], "validate": ["x", "y"], "quick": True,
           "train_rows": [{"problem": "a", "before": 0.3, "after": 0.2}], "validate_rows": rows,
           "evaluations": 3, "optimizer": "ok", "constants_fitted": {}, "constants_auto": {},
           "scales": {}, "scale_rel_se": {}, "identified": {}, "singular_values": [1.0],
           "condition_number": 1.0, "terms": ["shear"], "constants_on": "a mesh",
           "against": "p1"}
    text = report(doc).markdown()
    assert "from 0.2 to 0.1" in text and "x/five/clamped (= a)" in text
    assert ("after over before: median 0.5 [0.5-0.5], better in 1, worse in 0 of 1: the fit "
            "carries to the cases left out" in text)
    assert "Quick settings: a preview" in text
    rows[1]["after"] = 0.3
    doc["quick"] = False
    text = report(doc).markdown()
    assert "worse in 1 of 1: the fit does not carry" in text and "Quick settings" not in text


def test_costs_are_the_benchs_in_round_ratios_at_a_size_it_ran():
    """A candidate's cost is the bench's own in-round step ratio over fem-linear's at the size
    the bench ran closest to 1e4 tetrahedra (the number bench.md prints), never a ratio of two
    interpolated times, with its range over the rounds; the size is the bench's."""
    from cases.studies.extensions.study import cost_ranges, cost_size, costs

    def row(model, tets, ratio):
        return {"model": model, "tets": tets, "step_vs_fem-linear": ratio,
                "us_per_step": 1.0, "step_vs_msm": 3.0 * ratio}
    bench = {"rows": [row("fem-linear", 1080, 1.0), row("fem-linear", 10985, 1.0),
                      row("a", 1080, 30.9), row("a", 10985, 25.7), row("a", 98415, 20.0)]}
    assert costs(bench, ["a", "fem-linear", "b"]) == {"a": 25.7, "fem-linear": 1.0, "b": None}
    bench["rows"][3]["step_vs_fem-linear_range"] = [18.1, 31.6]
    assert cost_ranges(bench, ["a", "fem-linear"]) == {"a": [18.1, 31.6], "fem-linear": None}
    assert cost_size(bench) == 10985 and cost_size({}) is None
