"""The convergence study: the fit recovers e_inf and p of synthetic sequences and
says the right verdict; the Pareto front; the reference evaluated off its nodes; and the quick
study end to end: its metrics, its ties to the effective tensors, its gate and its progress."""
import json
import math
from pathlib import Path

import numpy as np
import pytest

from conftest import floats_in

from cases.cli import main
from cases.reporting.costs import step_cost_us
from cases.studies.convergence.cost import pareto
from cases.studies.convergence.extrapolation import EXACT, extrapolate, fit, observed_order
from model.material import Material
from model.mesh import cube
from reference import linear

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize("e_inf, C, p", [(0.0, 0.3, 1.0), (0.0, 0.05, 2.0), (0.12, 0.4, 1.5),
                                         (0.05, 0.01, 3.0)])
def test_three_levels_recover_the_limit_and_order_exactly(e_inf, C, p):
    """On three levels of e_inf + C h^p the observed order and the fit recover p and e_inf
    exactly, the uncertainty is 1.25 times the Richardson correction, and the verdict is floor or
    converges accordingly."""
    h = [8.0, 4.0, 2.0]
    e = [e_inf + C * x**p for x in h]
    assert observed_order(h, e) == pytest.approx(p, rel=1e-9)
    f = fit(h, e)
    assert f.order == pytest.approx(p, rel=1e-9)
    assert f.e_inf == pytest.approx(e_inf, abs=1e-12)
    # Roache's GCI: 1.25 x the Richardson correction
    assert f.e_inf_err == pytest.approx(1.25 * abs(C) * 2.0**p, rel=1e-9)
    assert f.verdict == ("floor" if e_inf > f.e_inf_err else "converges")


def test_four_levels_uneven_ratio_fit_all_of_them():
    """Four levels at uneven refinement ratios of 0.05 + 0.02 h^1.3 fit to the limit 0.05 and
    order 1.3 on all four levels, verdict floor."""
    h = [8.0, 4.0, 2.0, 4.0 / 3.0]
    e = [0.05 + 0.02 * x**1.3 for x in h]
    f = fit(h, e)
    assert f.e_inf == pytest.approx(0.05, abs=1e-9) and f.order == pytest.approx(1.3)
    assert f.verdict == "floor" and f.levels == 4


def test_verdicts_of_the_shapes_a_model_shows():
    """Halving errors converge, nearly flat ones are a floor, doubling ones diverge with no
    limit, rises after falls are not asymptotic, and round-off-level errors are exact. Two levels
    assume first order with Roache's factor 3, extrapolate without an asymptotic range keeps the
    last value, and NaN raises ValueError."""
    assert fit([8, 4, 2], [0.2, 0.1, 0.05]).verdict == "converges"
    assert fit([8, 4, 2], [0.2, 0.19, 0.185]).verdict == "floor"
    assert fit([8, 4, 2], [0.2, 0.4, 0.8]).verdict == "diverges"
    assert fit([8, 4, 2], [0.2, 0.4, 0.8]).e_inf is None        # no limit to print
    # a dip then a rise shows no trend: not asymptotic, never diverging
    assert fit([8, 4, 2, 4 / 3], [0.20, 0.21, 0.12, 0.225]).verdict == "not asymptotic"
    # a rise at the finest level three times the fall before it is no floor
    assert fit([8, 4, 2, 4 / 3], [0.70, 0.666, 0.649, 0.698], u=3e-5).verdict == \
        "not asymptotic"
    # a finest refinement that raises the error by half is no floor
    rising = fit([8, 4, 2, 4 / 3], [0.30, 0.25, 0.23, 0.345])
    assert rising.verdict == "not asymptotic" and rising.e_inf is None
    assert fit([8, 4, 2], [3e-10, 1e-10, 2e-10]).verdict == "exact"
    assert fit([8, 4], [EXACT * 2, EXACT * 1.5]).verdict != "exact"
    # two levels: first order assumed, Roache's factor 3
    f = fit([8, 4], [0.2, 0.18])
    assert f.e_inf == pytest.approx(0.16) and f.e_inf_err == pytest.approx(0.06)
    assert f.verdict == "floor" and f.order == pytest.approx(math.log2(0.2 / 0.18))
    assert fit([8, 4], [0.2, 0.1]).verdict == "converges"
    # no asymptotic range: the limit lies within the last changes
    limit, err, p = extrapolate([8, 4, 2], [0.2, 0.1, 0.15])
    assert p is None and limit == 0.15 and err == pytest.approx(1.25 * 0.1)
    with pytest.raises(ValueError, match="finite"):
        fit([8, 4], [0.1, float("nan")])


H4 = [8.0, 4.0, 2.0, 4.0 / 3.0]     # the study's four levels


@pytest.mark.parametrize("p", [1.0, 2.0, 0.5, 0.7])
@pytest.mark.parametrize("u", [0.0, 1e-4])
def test_a_power_law_falling_sequence_is_never_a_floor(p, u):
    """e = C h^p falls to zero at every level: 'converges', on three levels and on four."""
    for h in (H4, H4[:3]):
        f = fit(h, [0.01 * x**p for x in h], u=u)
        assert f.verdict == "converges", (p, h, f)


def test_the_referees_sequence_still_falls_so_it_is_no_floor():
    """FEM P1's torsion error on 'six' (0.0101, 0.0059, 0.0040, 0.0028) falls at every level
    by far more than its reference's estimate (2.7e-5): its finest changes do not shrink as a
    power of h: a sequence still falling is not a floor, and without an observed order it has
    neither a limit nor a rate: 'not asymptotic', never 'converges'."""
    from cases.studies.convergence.extrapolation import still_falling
    e = [0.0101, 0.0059, 0.0040, 0.0028]
    falling, q = still_falling(H4, e, 2.7e-5)
    assert falling and q == pytest.approx(math.log(0.0059 / 0.0028) / math.log(3.0))
    f = fit(H4, e, u=2.7e-5)
    assert f.verdict == "not asymptotic" and "still falling" in f.why and f.e_inf is None


@pytest.mark.parametrize("c, C, p", [(0.1, 0.02, 1.0), (0.1, 0.01, 2.0), (0.05, 0.002, 1.5)])
def test_a_constant_plus_a_decaying_part_is_a_floor_at_the_constant(c, C, p):
    """A constant plus a decaying power C h^p is a floor at the constant with order p (to 1e-6)
    and an uncertainty below the constant."""
    f = fit(H4, [c + C * x**p for x in H4])
    assert f.verdict == "floor" and f.e_inf == pytest.approx(c, rel=1e-6)
    assert f.order == pytest.approx(p, rel=1e-6) and f.e_inf_err < c


@pytest.mark.parametrize("seed", range(8))
def test_noise_around_a_constant_is_a_floor_at_it(seed):
    """0.1 with 1 % noise: with the noise as the values' uncertainty every draw is a floor
    at 0.1 within its +-; without it, a draw that rises somewhere at the finest levels or
    falls at an order below ORDER_MIN is one too."""
    rng = np.random.default_rng(seed)
    e = list(0.1 + 0.001 * rng.uniform(-1, 1, len(H4)))
    f = fit(H4, e, u=0.002)
    assert f.verdict == "floor" and abs(f.e_inf - 0.1) <= f.e_inf_err, (e, f)
    assert fit(H4, e).verdict == "floor"
    # noise and a stopped sequence the study measured: msm+volume's torsion on 'six'
    assert fit(H4, [0.0574, 0.0593, 0.058, 0.0572], u=2.7e-5).verdict == "floor"


def test_two_levels_are_not_decided_in_the_report():
    """Two levels observe no order: the report says 'not decided (two levels)' for a fit's
    converges, floor or diverges there (the finer levels overturn them), never for 'exact'."""
    from cases.studies.convergence.report import decided, verdict_cell
    two = {"verdict": "floor", "levels": 2}
    assert not decided(two) and verdict_cell(two, 0.3, 0.0) == "not decided (two levels)"
    assert decided({"verdict": "exact", "levels": 2})
    assert decided({"verdict": "floor", "levels": 3})
    assert verdict_cell({"verdict": "diverges", "levels": 2, "cancellation": "x"}, 0.3, 0.0) \
        == "not decided (two levels), cancellation"


def test_a_reference_above_a_fifth_of_an_error_leaves_it_not_resolved():
    """A reference whose estimate is more than a fifth of the smallest
    error it judges cannot judge it: 'not resolved', in the margin sentence and the tables,
    and the verdict is left out of the headline's counts."""
    from cases.studies.convergence.report import _reference_margin, unresolved, verdict_cell
    runs = [{"case": "c", "bc": "b", "mesh": "five", "model": m, "h_mm": h, "disp_rel_l2": e}
            for m, es in (("near", (0.08, 0.03, 0.015)), ("far", (0.4, 0.3, 0.25)))
            for h, e in zip((8.0, 4.0, 2.0), es)]
    fits = [{"case": "c", "bc": "b", "mesh": "five", "model": m, "verdict": "converges",
             "levels": 3} for m in ("near", "far")]
    data = {"runs": runs, "fits": fits,
            "references": [{"case": "c", "bc": "b", "error_estimate": 0.004}]}
    said = _reference_margin(data)
    assert "with care" not in said
    assert "c b: smallest error 0.015, 3.75x the reference's estimate (not resolved: its " \
        "estimate 0.004 is more than a fifth of the smallest error, so it cannot judge the " \
        "1 of 6 runs with an error below 0.02, nor a fit whose finest error is)" in said
    assert unresolved(data) == {("c", "b", "five", "near")}
    assert verdict_cell(fits[0], 0.015, 0.02) == "converges, not resolved"
    assert verdict_cell(fits[1], 0.25, 0.02) == "converges"
    data["references"][0]["error_estimate"] = 0.002     # 7.5x: resolved
    assert "not resolved" not in _reference_margin(data) and not unresolved(data)


def test_the_full_report_follows_the_rulebook():
    """The committed full report (`pbcm run convergence --rewrite` from its runs): FEM P1's
    torsion on 'six' is no floor, and the paper cube's clamped reference is 'not resolved'."""
    md = (ROOT / "reports" / "convergence" / "report.md").read_text()
    assert "with care" not in md
    assert "paper-cube clamped: smallest error 0.01, 2.53x the reference's estimate (not " \
        "resolved: " in md
    row = next(line for line in md.splitlines() if line.startswith("| six | FEM P1 | 0.0101"))
    assert "| not asymptotic |" in row and "floor" not in row
    assert "converging on every fit where a limit is decided: FEM P1," in md
    # the reference (estimate 0.004) cannot judge who reaches 0.02 on the clamped cube
    cube = next(line for line in md.splitlines() if line.startswith("| paper-cube clamped |"))
    assert cube.endswith("| not judged (the reference's estimate 0.004 is above a fifth of "
                         "the target) |")
    assert "exact, cancellation" not in md and "| 0 +- 3 |" not in md


def test_pareto_front_keeps_only_the_points_no_one_beats():
    """The Pareto front holds, in increasing cost, the points no other beats in both cost and
    error, and with a tolerance an error gain no larger than it does not join the front."""
    pts = [(1.0, 0.5), (2.0, 0.2), (2.0, 0.3), (3.0, 0.25), (4.0, 0.1), (0.5, 0.9)]
    assert pareto(pts) == [5, 0, 1, 4]
    # a gain within what the reference resolves beats nothing: 0.2 after 0.5 does, 0.1 after
    # 0.2 does not at a tolerance of 0.15
    assert pareto(pts, tol=0.15) == [5, 0, 1]


def test_a_target_the_reference_cannot_judge_has_no_cheapest_run():
    """Below five times the reference's estimate no run is said to reach a target (its error
    is not known to that precision): (None, None), never a pick."""
    from cases.studies.convergence.cost import cheapest
    pts = [{"model": "a", "mesh": "five", "h_mm": 2.0, "cost_us": 1.0, "disp_rel_l2": 0.01}]
    assert cheapest(pts, 0.02, u=0.005) == (None, None)
    assert cheapest(pts, 0.02, u=0.003)[0] is pts[0]


def test_step_cost_interpolates_the_bench_in_log_log():
    """The step cost of a model between bench sizes is interpolated in log-log, outside them it
    takes the nearest size, and a model the bench lacks has no cost."""
    bench = {"rows": [
        {"model": "fem-linear", "tets": 100, "us_per_step": 10.0, "step_vs_fem-linear": 1.0},
        {"model": "fem-linear", "tets": 10000, "us_per_step": 1000.0, "step_vs_fem-linear": 1.0},
        {"model": "m", "tets": 100, "us_per_step": 40.0, "step_vs_fem-linear": 4.0},
        {"model": "m", "tets": 10000, "us_per_step": 2000.0, "step_vs_fem-linear": 2.0}]}
    assert step_cost_us(bench, "m", 1000) == pytest.approx(100.0 * math.sqrt(8.0))
    assert step_cost_us(bench, "m", 10) == pytest.approx(40.0)   # the nearest size outside
    assert step_cost_us(bench, "other", 1000) is None


def test_reference_is_evaluated_off_its_nodes_by_its_basis():
    """A P2 solution of an affine boundary motion is that affine field everywhere: probed at
    the nodes of another mesh it is exact; at its own nodes the probe is its nodal values."""
    m = cube(3, 0.032, "five")
    A = np.array([[1e-3, 2e-4, 0.0], [0.0, -5e-4, 3e-4], [1e-4, 0.0, 2e-4]])
    bc = {int(i): tuple(A @ m.points[i]) for i in range(m.n_nodes)
          if np.isclose(m.points[i], 0).any() or np.isclose(m.points[i], 0.032).any()}
    r = linear.solve(m, Material(10e3, 0.3), bc, element="P2")
    assert np.allclose(r.at(m.points), r.u, atol=1e-15)
    other = cube(4, 0.032, "unstructured").points
    assert np.allclose(r.at(other), other @ A.T, atol=1e-12)


# ---------------------------------------------------------------------- the quick study
@pytest.fixture
def study(quick_convergence):
    return quick_convergence


def test_quick_study_writes_its_report_and_the_rows_asked_for(study):
    """The quick study writes its report and figures, a row per run and per fit with their
    columns over the four (case, bc), the 8 and 4 mm levels and both meshes, only finite numbers,
    and references converged below 0.01."""
    data = json.loads((study / "metrics.json").read_text())
    for f in ("report.md", "report.html", "pareto.png", "directional_young.png",
              "convergence_paper-cube_clamped.png", "convergence_torsion_clamped.png"):
        assert (study / f).is_file(), f
    for r in data["runs"]:
        assert {"case", "mesh", "bc", "model", "h_mm", "disp_rel_l2",
                "reaction_ratio"} <= set(r)
    for f in data["fits"]:
        assert {"case", "mesh", "bc", "model", "order", "e_inf", "e_inf_err",
                "verdict"} <= set(f)
    assert {(r["case"], r["bc"]) for r in data["runs"]} == {
        ("paper-cube", "clamped"), ("paper-cube", "sliding"), ("cantilever", "clamped"),
        ("torsion", "clamped")}
    assert {r["h_mm"] for r in data["runs"]} == {8.0, 4.0}
    assert {r["mesh"] for r in data["runs"]} == {"five", "six"}
    for v in floats_in(data):
        assert math.isfinite(v)
    md = (study / "report.md").read_text()
    assert "## Effective elasticity" in md and "## Accuracy per cost" in md
    for ref in data["references"]:   # the reference is converged below the errors it judges
        assert ref["error_estimate"] < 0.01


def test_fem_linear_statics_are_fem_p1(study):
    """In the quick study the fem-linear model's static error equals FEM P1's at every case, bc,
    mesh and level, to 1e-6 relative."""
    runs = json.loads((study / "metrics.json").read_text())["runs"]
    p1 = {(r["case"], r["bc"], r["mesh"], r["h_mm"]): r["disp_rel_l2"] for r in runs
          if r["model"] == "FEM P1"}
    for r in runs:
        if r["model"] == "fem-linear":
            key = (r["case"], r["bc"], r["mesh"], r["h_mm"])
            assert r["disp_rel_l2"] == pytest.approx(p1[key], rel=1e-6, abs=1e-9)


def test_sliding_cube_reaction_ratio_is_the_lattice_young_modulus(study):
    """The sliding cube is in uniaxial stress: a model whose lattice answers homogeneously
    (conservative, centrosymmetric patch: 'five') must give a reaction ratio E_y,eff / E."""
    data = json.loads((study / "metrics.json").read_text())
    E = data["parameters"]["E_Pa"]
    eff = {(e["mesh"], e["model"]): e for e in data["elasticity"]}
    for r in data["runs"]:
        if (r["case"], r["bc"], r["mesh"]) == ("paper-cube", "sliding", "five") \
                and r["model"] in ("msm", "msm+volume", "pbcm-variational", "fem-linear"):
            assert r["reaction_ratio"] == pytest.approx(eff[("five", r["model"])]["E_y_pa"] / E,
                                                        rel=0.02), r["model"]


def test_quick_study_passes_the_committed_bounds(study, capsys):
    """The quick study's metrics pass `pbcm check` against the committed gold (new rows allowed)."""
    status = main(["check", "--metrics", str(study), "--gold",
                   str(ROOT / "gold"), "--allow-new"])
    assert status == 0, capsys.readouterr().out[-3000:]


def test_progress_says_the_time_left_on_a_log(capsys):
    """The one progress display (every command's): a log (not a terminal) gets a line at
    every tenth of the work with the time left, and nothing when told not to log."""
    from cases.running.progress import Progress
    with Progress("convergence", 10.0) as t:
        t.advance(4.0, "paper-cube clamped")
        t.advance(0.5, "cantilever clamped")       # within the same tenth: no new line
    err = capsys.readouterr().err
    assert err.count("convergence: 40% after") == 1 and "s left" in err
    assert "45%" not in err
    with Progress("quiet", 1.0, log=False) as t:
        t.advance(1.0)
        t.say("not shown")
    assert capsys.readouterr().err == ""


def test_study_refuses_bcs_before_computing(capsys, monkeypatch):
    """`pbcm run convergence --bcs` exits 2 saying --bcs does not apply to the convergence
    study, before it starts computing."""
    from cases.studies.convergence import Convergence

    def refuse(self, *a, **k):
        raise AssertionError("the study started computing")
    monkeypatch.setattr(Convergence, "run", refuse)
    assert main(["run", "convergence", "--bcs", "clamped"]) == 2
    assert "--bcs does not apply to the convergence study" in capsys.readouterr().err


def test_study_metrics_do_not_depend_on_the_workers(study, tmp_path):
    """The units (a reference per (problem, bc), the runs per family) on two worker processes
    give the same rows, bit for bit, as the serial run, for the models both ran."""
    out = tmp_path / "convergence"
    assert main(["run", "convergence", "--quick", "--out", str(out), "--workers", "2",
                 "--models", "pbcm-corner", "msm"]) == 0
    two = json.loads((out / "metrics.json").read_text())
    one = json.loads((study / "metrics.json").read_text())
    for key in ("runs", "fits", "elasticity"):
        mine = [r for r in one[key] if r["model"] in ("msm", "pbcm-corner", "FEM P1")]
        assert mine == two[key], key


def test_index_opens_with_the_answers_and_lists_the_study(study, tmp_path, capsys):
    """`pbcm index` rewrites the index from the folders present: the answers first (a quick
    convergence study decides no limit, its irregular patches are said), their table, then the
    studies (this one in quick mode, linked) and the scorecard; a missing case is named, and
    the index answers over the cases found."""
    from cases.registry import CASES
    for name in CASES:
        (tmp_path / name).symlink_to(ROOT / "reports" / name, target_is_directory=True)
    (tmp_path / "convergence").symlink_to(study, target_is_directory=True)
    assert main(["index", "--out", str(tmp_path)]) == 0
    md = (tmp_path / "index.md").read_text()
    first = md.split("\n\n")[1]
    assert first.startswith("**Which reading?** Not computed: run `pbcm run artefact`.")
    # a quick study decides no limit; the irregular patches are the full run's own
    assert "**How far from the continuum?** Quick: not decided (`pbcm run convergence` " \
        "decides, on its finer levels); on the same patches as the full run; the patch " \
        "test with every boundary node prescribed" in md
    assert "The consistency limit" not in md.split("**How far from the continuum?**")[1]
    # the patch test's irregular patches: msm (springs) misses the strain by over 10 %
    irregular = md.split("on the patch named, against the exact linear field; one "
                         "run each, ")[1].split(" ([convergence]")[0].split(
                             "; the patch test is necessary")[0].rsplit("): ", 1)[1]
    worst = {m: v.split(" (")[0] for m, v in (item.split(" ", 1)
                                              for item in irregular.split("), "))}
    assert float(worst["msm"]) > 0.1 and worst["fem-linear"] == "< 1e-08"   # round-off
    assert md.index("**How far") < md.index("| model | model-form error, linear regime") \
        < md.index("## Studies") < md.index("## Scorecard")
    assert "| [convergence](convergence/report.md) |" in md and "| quick |" in md
    # the answers with their uncertainties, ties and what to pick stay within a page
    assert len(md.split("| model | model-form error, linear regime")[0].split()) < 800
    assert (tmp_path / "glossary.md").is_file()
    # a missing library case is a note, not a refusal: the index answers over what it found
    (tmp_path / "torsion").unlink()
    assert main(["index", "--out", str(tmp_path)]) == 0
    assert "note: no folder of torsion" in capsys.readouterr().out
    md = (tmp_path / "index.md").read_text()
    assert md.split("\n\n")[1].startswith("Not run here (no folder): torsion; every answer "
                                           "below is over the cases found: ")
    assert "[torsion/clamped]" not in md


def test_study_bad_arguments_fail_before_computing(tmp_path, capsys, monkeypatch):
    """An --out on a file, nu = 0.5, an unknown mesh and an unknown model each make the quick
    study exit 2 with one error line, before it starts computing."""
    from cases.studies.convergence import Convergence

    def refuse(self, *a, **k):
        raise AssertionError("the study started computing")
    monkeypatch.setattr(Convergence, "run", refuse)
    (tmp_path / "afile").write_text("x")
    for argv in (["--out", str(tmp_path / "afile")], ["--nu", "0.5"], ["--meshes", "hex"],
                 ["--models", "fem-p3"]):
        assert main(["run", "convergence", "--quick", *argv]) == 2
        err = capsys.readouterr().err.strip()
        assert err.startswith("pbcm: error: ") and len(err.splitlines()) == 1, err


def test_fits_that_cannot_lie():
    """The limit of an error is never below zero (a series whose extrapolation is negative
    beyond its uncertainty is 'not asymptotic'), a family that is not self-similar is never
    extrapolated, a stiffness ratio's limit is never at or below zero, and a series whose
    error is not monotone or whose ratio crosses 1 is flagged 'cancellation'."""
    from cases.studies.convergence.extrapolation import cancellation, fit, ratio_limit
    # order 0.74 from 1, 0.5, 0.2: Richardson's correction 0.45 overshoots to -0.25 +- 0.56
    f = fit([8.0, 4.0, 2.0], [1.0, 0.5, 0.2])
    assert f.e_inf == 0.0 and f.e_inf_err == pytest.approx(1.25 * 0.45, rel=1e-2)
    assert f.verdict == "not decided"     # +- 0.56 bounds more than the finest error 0.2
    assert fit([8.0, 4.0, 2.0], [0.1, 0.05, 0.025], nested=False).verdict == "not asymptotic"
    assert fit([8.0, 4.0, 2.0], [0.1, 0.05, 0.025], nested=False).e_inf is None
    below = fit(H4, [0.6, 0.4, 0.2, 0.1])     # extrapolates to -2.8 +- 2.3: no limit printed
    assert below.verdict == "not asymptotic" and below.e_inf is None and "below zero" in below.why
    # a ratio 2.46, 1.24, 0.835, 0.747 (pbcm-variational's cantilever on six) crosses 1
    assert cancellation([0.3, 0.2, 0.1, 0.15]) == "the error is not monotone in h"
    assert cancellation([1.46, 0.24, 0.165, 0.253], [2.46, 1.24, 0.835, 0.747]) \
        == "the error is not monotone in h"
    assert cancellation([1.46, 0.24, 0.165, 0.1], [2.46, 1.24, 0.835, 0.9]) \
        == "the stiffness ratio crosses 1"
    assert cancellation([0.3, 0.2, 0.1], [1.3, 1.2, 1.1]) is None
    limit, why = ratio_limit([8.0, 4.0, 2.0], [0.9, 0.6, 0.35])
    assert limit is None and "not asymptotic" in why
    assert ratio_limit([8.0, 4.0, 2.0], [1.2, 1.1, 1.05])[0] > 0
    assert ratio_limit([8.0, 4.0, 2.0], [1.2, 1.1, 1.05], nested=False)[0] is None


def test_a_cancelling_series_is_never_on_the_cost_front():
    """A run of a cancelling series is marked as such and kept off the cost front, even with the
    lower error at the same cost; the other run makes the front."""
    from cases.studies.convergence.cost import accuracy_per_cost
    runs = [{"case": "c", "bc": "b", "mesh": "six", "model": m, "h_mm": 4.0, "tets": 100,
             "disp_rel_l2": e} for m, e in (("lucky", 0.001), ("honest", 0.01))]
    import cases.studies.convergence.cost as C
    original = C.step_cost_us
    try:
        C.step_cost_us = lambda bench, model, tets: 1.0
        out = accuracy_per_cost(runs, {"any": 1}, 0.0, {("c", "six", "b", "lucky")})
    finally:
        C.step_cost_us = original
    g = out["groups"][0]
    assert [g["points"][i]["model"] for i in g["front"]] == ["honest"]
    assert g["points"][0]["cancellation"] is True


def test_rewrite_draws_the_same_report_from_the_recorded_runs(study, tmp_path):
    """`pbcm run convergence --rewrite` redraws the report from metrics.json alone: the same
    report, the same metrics, without computing."""
    import shutil
    out = tmp_path / "convergence"
    shutil.copytree(study, out)
    (out / "report.md").write_text("stale")
    assert main(["run", "convergence", "--rewrite", "--out", str(out)]) == 0
    assert (out / "report.md").read_text() == (study / "report.md").read_text()
    assert json.loads((out / "metrics.json").read_text())["runs"] == \
        json.loads((study / "metrics.json").read_text())["runs"]


# ---------------------------------------------------------------------- the referee's rules
def _run(mesh, model, h, e, ratio=1.0, case="c", bc="b"):
    return {"case": case, "bc": bc, "mesh": mesh, "model": model, "h_mm": h, "tets": 100,
            "disp_rel_l2": e, "reaction_ratio": ratio}


def test_round_off_is_never_cancellation():
    """Errors at or below round-off (the 'exact' level) wobble without meaning: a series of
    them, or a ratio within round-off of 1, is never 'cancellation', and such a run keeps its
    place on the cost front (the sliding cube: fem-linear at 2.8e-10 beats a dearer run at
    2.5e-5)."""
    from cases.studies.convergence.cost import judge
    from cases.studies.convergence.extrapolation import ROUND_LEVEL, cancellation
    from cases.studies.convergence.study import fits
    assert ROUND_LEVEL >= EXACT
    assert cancellation([2.83e-10, 2.64e-10, 1.73e-10, 3e-10],
                        [1 + 1e-10, 1 - 1e-10, 1 + 2e-10, 1 - 3e-11]) is None
    assert cancellation([2e-5, 3e-5, 1e-5]) is None
    assert cancellation([0.3, 0.2, 0.25]) == "the error is not monotone in h"
    runs = [_run("five", m, h, e) for m, es in (("FEM P1", (2.35e-10, 1.95e-10, 2.14e-10)),
                                                ("cheap", (2.83e-10, 2.64e-10, 1.73e-10)),
                                                ("dear", (2.46e-5, 2.2e-5, 2.07e-5)))
            for h, e in zip((8.0, 4.0, 2.0), es)]
    fitted = fits(runs)
    assert all(f["verdict"] == "exact" and not f["cancellation"] for f in fitted)
    pts = [{"model": m, "mesh": "five", "h_mm": 8.0, "tets": 100, "cost_us": c,
            "disp_rel_l2": e} for m, c, e in (("cheap", 64.2, 2.83e-10), ("dear", 90.8, 2.46e-5))]
    g = judge({"groups": [{"case": "c", "bc": "b", "points": pts}]}, runs, EXACT, set())
    assert [pts[i]["model"] for i in g["groups"][0]["front"]] == ["cheap"]


def test_the_opening_counts_what_the_tables_say():
    """A model said to converge is said so only where a limit is decided; its other fits are
    counted by what the tables say (not asymptotic, not decided, not resolved)."""
    from cases.studies.convergence.report import _converging
    fits = [{"case": "c", "bc": "b", "mesh": mesh, "model": "FEM P1", "verdict": v,
             "levels": 3} for mesh, v in (("five", "converges"), ("six", "not asymptotic"),
                                         ("bcc", "not decided"),
                                         ("unstructured", "not asymptotic"))]
    said = _converging(["FEM P1"], fits, set(), 4)
    assert said.startswith("FEM P1 (converging or exact on 1 of 4;")
    assert "not asymptotic on 2: c b six, c b unstructured" in said
    assert "not decided (uncertainty larger than what it bounds) on 1: c b bcc" in said
    loose = {("c", "b", "five", "FEM P1")}
    assert "not resolved on 1: c b five" in _converging(["FEM P1"], fits, loose, 4)


def test_a_limit_wider_than_the_finest_error_is_not_decided():
    """A limit whose +- exceeds the finest error (times Roache's factor: the band of a clean
    extrapolation to zero) decides nothing: 'not decided', never 'converges' with a number.
    The torsion bar on 'five' with its 8 mm level extrapolated to 0 +- 3."""
    from cases.studies.convergence.extrapolation import FS_THREE, bounds_nothing
    from cases.studies.convergence.report import verdict_cell
    f = fit([8.0, 4.0, 2.0, 4.0 / 3.0], [0.00465, 0.00649, 0.00228, 0.00139], u=2.7e-5)
    assert f.verdict == "not decided", f
    assert f.label() == "not decided (uncertainty larger than what it bounds)"
    assert verdict_cell({"verdict": f.verdict, "levels": 4}, 0.00139, 0.0) == \
        "not decided (uncertainty larger than what it bounds)"
    assert bounds_nothing(3.0, 0.00139) and not bounds_nothing(FS_THREE * 0.1, 0.1)
    # a clean power law to zero is decided: its band is exactly FS x the finest error
    assert fit([8.0, 4.0, 2.0], [0.2, 0.1, 0.05]).verdict == "converges"
    # a sequence that stopped with a band wider than its finest error: not decided
    assert fit([8.0, 4.0, 2.0], [0.01, 0.002, 0.0021]).verdict == "not decided"


def test_a_level_every_model_shares_tests_nothing():
    """A level where every model's error is the same (within SAME_ERROR) while their stiffness
    ratios spread ten times as much tests nothing: it is left out of the fits and the report
    says why; a level where the models differ stays."""
    from cases.studies.convergence.extrapolation import blind_levels
    from cases.studies.convergence.report import blind_text
    from cases.studies.convergence.study import fits
    ratios = {"FEM P1": 2.07, "a": 0.98, "b": 2.29, "c": 1.71}
    runs = [_run("five", m, 8.0, 0.00465 * (1 + 0.005 * i), r, "torsion", "clamped")
            for i, (m, r) in enumerate(ratios.items())]
    runs += [_run("five", m, h, e * (1 + 0.3 * i), 1.0, "torsion", "clamped")
             for i, m in enumerate(ratios) for h, e in ((4.0, 0.0065), (2.0, 0.0023),
                                                       (4.0 / 3.0, 0.0014))]
    assert set(blind_levels(runs)) == {("torsion", "clamped", "five", 8.0)}
    for f in fits(runs):
        assert f["left_out_mm"] == [8.0] and f["levels"] == 3
    said = blind_text({"runs": runs, "fits": fits(runs)}, "torsion", "clamped")
    assert said.startswith("Left out of the fits") and "h = 8 mm on five" in said and "tests nothing" in said
    assert "2 cells across there, 3 x 3 nodes" in said
    # the same errors with the same ratios (FEM twins): the models do not differ, nothing left
    twins = [dict(r, reaction_ratio=1.0) for r in runs]
    assert blind_levels(twins) == {}
    # a preview of two levels keeps it (one level would remain) and says it tests nothing
    two = [r for r in runs if r["h_mm"] >= 4.0]
    assert all(f["left_out_mm"] == [] and f["levels"] == 2 for f in fits(two))
    said = blind_text({"runs": two, "fits": fits(two)}, "torsion", "clamped")
    assert said.startswith("Kept in the fits, as fewer than three levels would remain")


def test_torsion_at_8_mm_on_five_is_every_models_rigid_turn():
    """Why the torsion bar's 8 mm level on 'five' tests nothing: the section is two cells
    across and the equilibrium is each section's rigid turn without warping, FEM P1's to
    round-off and msm's (the softest in Poisson's ratio) within 1e-3."""
    from model import build
    from cases.running.runner import free_components
    from cases.studies.convergence.problems import PROBLEMS
    from cases.studies.convergence.study import ConvergenceSettings
    s = ConvergenceSettings()
    p = PROBLEMS["torsion"]
    ps = p.settings(s.E, s.nu)
    mesh = p.mesh("five", 8.0)
    d = p.dirichlet(mesh, "clamped", ps, s.load_scale)
    free = free_components(d, mesh.n_nodes).reshape(-1)
    x = mesh.points
    c = x[:, 1].max() / 2
    turn = np.radians(ps.angle_deg) * s.load_scale * x[:, 0] / x[:, 0].max()
    rigid = np.column_stack([0 * turn, -turn * (x[:, 2] - c), turn * (x[:, 1] - c)])

    def off(u):
        return np.linalg.norm((u - rigid).reshape(-1)[free]) / np.linalg.norm(
            rigid.reshape(-1)[free])
    p1 = linear.solve(mesh, s.material, d, element="P1", solver="direct")
    assert off(p1.u) < 1e-10
    assert off(build("msm", mesh, s.material).solve_static(d, rtol=1e-12).u) < 1e-3


def test_a_target_reached_only_by_cancellation_is_named_not_picked():
    """A run at or below the target on a mesh where FEM P1's error is above it reaches the
    target only by cancellation (its model-form error offsets the discretisation error): it
    is named, never picked, and a run below FEM P1's error beyond the reference's estimate is
    never on the front."""
    from cases.studies.convergence.cost import by_cancellation, cheapest, judge
    runs = [_run("five", "FEM P1", 1.33, 0.0276), _run("five", "soft", 1.33, 0.0094),
            _run("five", "fem", 1.33, 0.0276), _run("bcc", "FEM P1", 2.0, 0.015),
            _run("bcc", "fem", 2.0, 0.015)]
    pts = [{"model": r["model"], "mesh": r["mesh"], "h_mm": r["h_mm"], "tets": 100,
            "cost_us": c, "disp_rel_l2": r["disp_rel_l2"]}
           for r, c in zip(runs[1:], (10.0, 5.0, 0.0, 30.0)) if r["model"] != "FEM P1"]
    g = judge({"groups": [{"case": "c", "bc": "b", "points": pts}]}, runs, EXACT, set(),
              {("c", "b"): 0.00045})["groups"][0]
    soft = next(p for p in g["points"] if p["model"] == "soft")
    assert soft["below_p1"] and soft["p1_error"] == 0.0276 and by_cancellation(soft, 0.02)
    assert not by_cancellation(soft, 0.1)      # FEM P1 reaches 0.1 there: no cancellation
    assert "soft" not in [g["points"][i]["model"] for i in g["front"]]
    best, named = cheapest(g["points"], 0.02)
    assert (best["model"], best["mesh"]) == ("fem", "bcc") and named == [soft]


def test_patch_test_and_consistency_limit_have_distinct_names():
    """'Patch test with every boundary node prescribed' (a strain error) and 'consistency
    limit' (the sliding cube's floor) are two numbers with two names: no heading or sentence
    calls one by the other's name; the study defines a fit's floor, the glossary the
    consistency limit, once."""
    from cases.reporting.document import Document
    from cases.studies.convergence.report import definitions
    from cases.studies.convergence.verification_report import _sliding, patch_section
    terms = [d.split(":")[0] for d in definitions()]
    assert "patch test with every boundary node prescribed (patch error)" in terms
    assert "floor e_inf" in terms and "consistency limit" not in terms
    from cases.reporting.index import TERMS
    assert "consistency limit" in TERMS
    assert not any("consistency error" in d for d in definitions())
    doc = Document("t")
    patch_section(doc, {"patch": [{"mesh": "six", "model": "m", "patch_error": 4.8e-12}]},
                  ["m"])
    md = doc.markdown()
    assert "Patch test with every boundary node prescribed" in md
    assert "consistency error" not in md
    said = _sliding({"runs": [_run("six", "m", 2.0, 0.21, 1.0, "paper-cube", "sliding")]},
                    ["m"])
    assert "is not this test" in said and "consistency limit of the sliding cube" in said


def test_a_stiffness_ratio_whose_changes_grow_has_no_limit():
    """A stiffness ratio whose finest change exceeds the one before (0.318, 0.3125, 0.298) is
    not settling: no limit, 'not asymptotic'; one whose changes shrink is extrapolated."""
    from cases.studies.convergence.extrapolation import ratio_limit
    limit, why = ratio_limit([8.0, 4.0, 2.0], [0.318, 0.3125, 0.298])
    assert limit is None and why.startswith("not asymptotic: its finest changes grow")
    limit, err = ratio_limit([8.0, 4.0, 2.0], [0.7, 0.6, 0.55])
    assert limit == pytest.approx(0.5) and err >= 0
