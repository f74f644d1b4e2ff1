"""The error model every verdict reads: its decomposition on values whose answer is known, the
validation uncertainty against a hand value, and the rankings' counting of failed runs."""
import json
import math

import pytest

from cases.measuring import error_model as E
from cases.reporting import scorecard


def test_p1_against_itself_has_no_model_form_error():
    """FEM P1 compared with itself has model-form error 0, and its total is its
    discretisation error."""
    p = E.decompose(0.8, 0.8, 1.0)
    assert p.model_form == 0.0
    assert p.total == p.discretisation == pytest.approx(-0.2, abs=1e-15)


def test_scalar_parts_sum_to_the_total():
    """For a scalar, model-form + discretisation = total, each relative to the continuum
    (the paper cube's case: a model at 0.73 of P1, P1 at 1.23 of the continuum)."""
    p = E.decompose(0.73 * 1.23, 1.23, 1.0)
    assert p.model_form == pytest.approx(0.73 * 1.23 - 1.23)
    assert p.discretisation == pytest.approx(0.23)
    assert p.total == pytest.approx(p.model_form + p.discretisation, abs=1e-15)
    assert p.total == pytest.approx(0.73 * 1.23 - 1, abs=1e-15)
    # a negative quantity (a compressive force) is measured relative to its magnitude
    q = E.decompose(-1.1, -1.2, -1.0)
    assert (q.model_form, q.discretisation) == pytest.approx((0.1, -0.2))


def test_sequence_parts_are_their_largest_components():
    """A quantity over load steps: each part is its largest-magnitude component, signed."""
    p = E.decompose([1.0, 2.5], [1.1, 2.0], [1.0, 2.0])
    assert p.model_form == pytest.approx(0.25)          # step 2: 0.5 / 2
    assert p.discretisation == pytest.approx(0.1)        # step 1
    assert p.total == pytest.approx(0.25)


@pytest.mark.parametrize("args, words", [
    ((1.0, 1.0, 0.0), "zero"), ((float("nan"), 1.0, 1.0), "not finite"),
    (([1.0, 2.0], [1.0], [1.0, 2.0]), "shape")])
def test_what_cannot_be_decomposed_is_refused(args, words):
    """A zero continuum value, a NaN (a failed solve) or mismatched steps are errors, never
    a number."""
    with pytest.raises(E.ErrorModelError, match=words):
        E.decompose(*args)


def test_u_val_combines_in_quadrature():
    """u_val = sqrt(u_num^2 + u_input^2 + u_D^2), by hand: 0.3, 0.4, 1.2 give 1.3."""
    assert E.u_val(0.3, 0.4, 1.2) == pytest.approx(1.3, abs=1e-15)
    assert E.u_val(0.5) == 0.5
    with pytest.raises(E.ErrorModelError, match="non-negative"):
        E.u_val(-0.1)


def test_u_num_is_the_larger_of_estimate_and_spread():
    """u_num combines the reference's estimate and its spread over the meshes of one problem
    in quadrature; a spread larger than the estimate is flagged as a defect."""
    assert E.u_num(0.01, [1.0, 1.05, 0.98]) == (pytest.approx((0.01**2 + 0.07**2) ** 0.5), True)
    assert E.u_num(0.1, [1.0, 1.05, 0.98]) == (pytest.approx((0.1**2 + 0.07**2) ** 0.5), False)
    assert E.u_num(0.02, [1.0]) == (0.02, False)


def test_a_failed_run_scores_against_its_model_only():
    """A model with a failed run is scored over every run, the failure infinitely wrong; the
    population stays in the other models' comparison."""
    rows = E.standings({"a": [0.1, 0.1, None, 0.1], "b": [0.2] * 4, "c": [0.1, None, None, 0.1]},
                       u=0.0)
    by = {s.model: (rank, s) for rank, s, _ in rows}
    assert by["a"][0] == 1 and by["a"][1].failed == 1 and by["a"][1].score == 0.1
    assert by["b"][0] == 2 and by["b"][1].score == 0.2
    assert by["c"][0] == 3 and math.isinf(by["c"][1].score) and by["c"][1].failed == 2


def test_differences_below_u_are_ties():
    """Two models closer than the comparison's uncertainty share a rank and are named tied."""
    rows = E.standings({"a": [0.10], "b": [0.12], "c": [0.3]}, u=0.05)
    assert [(r, s.model, t) for r, s, t in rows] == [(1, "a", ("b",)), (1, "b", ("a",)),
                                                     (3, "c", ())]


def test_ties_are_pairwise_never_chained_nor_split():
    """A model within u of the group's first shares its rank; one just beyond starts a group
    of its own yet is still named tied with its neighbour within u, never with the first."""
    rows = E.standings({"a": [0.10], "b": [0.14], "c": [0.16]}, u=0.05)
    assert [(r, s.model, t) for r, s, t in rows] == [(1, "a", ("b",)), (1, "b", ("a", "c")),
                                                     (3, "c", ("b",))]


def test_geometric_mean_floors_and_fails():
    """A score below its population's uncertainty counts as that uncertainty; a failed
    population makes the mean infinite."""
    assert E.geometric_mean([1e-12, 0.4], [0.1, 0.0]) == pytest.approx(0.2)
    assert math.isinf(E.geometric_mean([0.1, math.inf], [0.0, 0.0]))


def _case_folder(tmp_path, case, runs, quick=False):
    (tmp_path / case).mkdir()
    (tmp_path / case / "metrics.json").write_text(json.dumps({
        "parameters": {"models": ["fem-linear", "fem-corotated", "a", "b"], "quick": quick},
        "runs": runs}))


def test_scorecard_decomposes_counts_failures_and_names_identity(tmp_path):
    """On a synthetic torsion case: P1 and the law that coincides with it are identity checks
    (never ranked); a model equal to P1 has model-form error 0 and its total is P1's
    discretisation error; a model's failed run
    counts against it while the population stays; a model with a failed median is last."""
    from cases.reporting.index import conclusion, index_documents, populations

    def run(mesh, model, q):
        return {"mesh": mesh, "bc": "clamped", "model": model, "torque_nm": q,
                "torque_fem_nm": 1.0, "p2_error_estimate": 0.001}
    runs = []
    for mesh, p1 in (("five", 1.2), ("six", 1.4)):
        runs += [run(mesh, "fem-linear", p1), run(mesh, "fem-corotated", p1),
                 run(mesh, "a", 0.9 * p1), run(mesh, "b", None if mesh == "six" else p1)]
    _case_folder(tmp_path, "torsion", runs)
    pops, _ = populations(tmp_path, ["torsion"])
    (p,) = pops
    assert p.parts["fem-corotated"][0].model_form == 0.0
    assert p.parts["fem-corotated"][0].total == pytest.approx(0.2)
    assert p.parts["a"][1].model_form == pytest.approx(-0.14)
    assert p.discretisation() == pytest.approx([0.2, 0.4])
    assert p.u_continuum == 0.001     # the estimate: the continuum values do not spread
    ranks = {s.model: (r, s) for r, s, _ in p.standings()}
    assert "fem-linear" not in ranks
    assert ranks["b"][1].failed == 1 and math.isinf(ranks["b"][1].score)
    lines = conclusion(pops, ["fem-linear", "fem-corotated", "a", "b"], quick=False)
    assert "fem-corotated" not in ranks and "fem-corotated" not in lines[0]   # identity
    assert "1. a (mean rank 1, geometric " \
        "mean 0.13 [0.12-0.14 leaving one mesh family out])" in lines[0]
    assert "2. b (mean rank 2, geometric mean failed (1 of 1 populations failed at the " \
        "median), 1 failed run)" in lines[0]
    assert "b in torsion/clamped (1 of 2)" in lines[-1]
    md, _ = index_documents(tmp_path, ["torsion"])
    assert "FEM P1 itself (0 by construction)" in md
    assert "0.13 [0.12-0.14] 2/2" in md                    # a's model-form error
    assert "0.3 [0.2-0.4]" in md                           # the shared discretisation error


def test_quick_scorecard_decides_nothing(tmp_path):
    """A quick run's overall ranking says it is not decided and names the command."""
    from cases.reporting.index import conclusion, populations
    runs = [{"mesh": "five", "bc": "clamped", "model": m, "torque_nm": q,
             "torque_fem_nm": 1.0} for m, q in (("fem-linear", 1.2), ("a", 1.0))]
    _case_folder(tmp_path, "torsion", runs, quick=True)
    pops, _ = populations(tmp_path, ["torsion"])
    assert "quick: not decided (run `pbcm report`" in conclusion(pops, ["fem-linear", "a"],
                                                                   quick=True)[0]


def test_an_unpaired_mode_is_failed_and_ranked_first():
    """A modal run's unpaired P1 modes are failed modes: the run's largest error is then
    undefined, so it is a failed run (no number, in every median, mean and pick); counted per
    model and ranked on before the error of the paired ones (a model pairing every mode
    ranks above one that pairs fewer, whatever their errors)."""
    q = E.Norm("mf", "tot", "modes", unpaired="lost")
    run = {"mesh": "five", "bc": "free"}
    runs = [dict(run, model="fem-linear", mf=0.0, tot=0.05, lost=0),
            dict(run, model="a", mf=0.02, tot=0.06, lost=3),
            dict(run, model="b", mf=0.3, tot=0.3, lost=0)]

    class Declared:
        @staticmethod
        def decompositions():
            return (q,)
    (p,) = scorecard.populations({"modes": runs}, {"modes": Declared}, {"modes": False},
                                 {"modes": set()}, {"modes": "est"})
    assert p.unpaired == {"fem-linear": 0, "a": 3, "b": 0}
    assert p.parts["fem-linear"][0].discretisation == 0.05
    assert p.parts["a"] == [None] and p.parts["b"][0].model_form == 0.3
    assert [(r, s.model) for r, s, _ in p.standings()] == [(1, "b"), (2, "a")]
    assert math.isinf(next(s for _, s, _ in p.standings() if s.model == "a").score)


def test_a_medians_spread_is_half_the_range_of_its_leave_one_mesh_out_medians():
    """Over runs 1..5 the medians with one run left out are 3.5, 3.5, 3, 2.5, 2.5: the spread
    is 0.5; fewer than three runs, or a median that failed, have none."""
    st = E.Standing("a", (1.0, 2.0, 3.0, 4.0, 5.0), 5)
    assert st.spread == pytest.approx(0.5)
    assert E.Standing("a", (1.0, 9.0), 2).spread == 0.0
    assert E.Standing("a", (1.0,), 3).spread == 0.0          # two of three failed


def test_medians_within_their_spread_over_the_meshes_share_a_rank_unresolved_not_tied():
    """Two medians 0.01 apart share a rank when the meshes move them more than that (a
    difference the unit of analysis does not resolve), said as not resolved, never as tied;
    within u_val they are tied; ranked apart when every mesh agrees."""
    noisy = E.standings({"a": [0.10, 0.20, 0.30], "b": [0.11, 0.21, 0.31]}, u=0.0)
    assert [(r, s.model, t) for r, s, t in noisy] == [(1, "a", ("b",)), (1, "b", ("a",))]
    assert [(t.tied, t.unresolved) for _, _, t in noisy] == [((), ("b",)), ((), ("a",))]
    close = E.standings({"a": [0.10, 0.20, 0.30], "b": [0.11, 0.21, 0.31]}, u=0.02)
    assert [(t.tied, t.unresolved) for _, _, t in close] == [(("b",), ()), (("a",), ())]
    steady = E.standings({"a": [0.20, 0.20, 0.20], "b": [0.21, 0.21, 0.21]}, u=0.0)
    assert [(r, s.model, t) for r, s, t in steady] == [(1, "a", ()), (2, "b", ())]
    assert "not resolved from b" in scorecard.unordered_text(noisy[0][2])
    assert "tied with b" in scorecard.unordered_text(close[0][2])


def test_the_quantity_at_the_load_is_the_linear_regimes_on_the_finite_solve():
    """A linear-regime Scalar has its twin at the load: the same quantity under the load's
    run key, against neo-Hookean P1 and the neo-Hookean continuum, posed where that reference
    exists; a quantity already at the load, or a set of modes, has none; the catalogue
    declares both derived keys."""
    from cases.measuring import catalogue
    q = E.at_load(E.Scalar("torque_nm", "torque_fem_nm", "torque"))
    assert (q.key, q.continuum, q.p1, q.posed) == (
        "torque_at_load_nm", "torque_at_load_fem_nm", E.P1_FINITE, "nh_error_estimate")
    assert E.at_load(E.Scalar("f_n", "f_fem_n", "f", p1=E.P1_FINITE)) is None
    assert E.at_load(E.Norm("mf", "tot", "modes")) is None
    assert catalogue.metric("torque_at_load_nm").unit == "N m"
    assert catalogue.metric("torque_at_load_fem_nm").label.startswith("NH torque")


def test_a_continuum_posed_per_mesh_has_no_spread_in_its_u_num():
    """Where each mesh poses its own continuum problem (a closed form read at its nodes), the
    continuum values' spread over the meshes is not u_num: the estimate alone is."""
    runs = _torsion_runs({("five", "fem-linear"): 1.0, ("six", "fem-linear"): 1.0})
    runs[1]["torque_fem_nm"] = 1.2

    class Declared:
        per_mesh_continuum = ()

        @staticmethod
        def decompositions():
            return (E.Scalar("torque_nm", "torque_fem_nm", "torque"),)

    def u(per_mesh):
        Declared.per_mesh_continuum = ("clamped",) if per_mesh else ()
        (p,) = scorecard.populations({"t": runs}, {"t": Declared}, {"t": False},
                                     {"t": set()}, {"t": "p2_error_estimate"})
        return p.u_continuum, p.per_mesh
    assert u(True) == (pytest.approx(0.001), True)
    assert u(False)[0] > 0.1


def _torsion_runs(values):
    """Runs of a synthetic torsion case: ``values`` {(mesh, model): torque} against a
    continuum torque of 1 on every mesh."""
    return [{"mesh": mesh, "bc": "clamped", "model": model, "torque_nm": q,
             "torque_fem_nm": 1.0, "p2_error_estimate": 0.001}
            for (mesh, model), q in values.items()]


def _three_models(tmp_path, torques):
    """The populations of a synthetic torsion case: fem-linear at 1 and models a, b, c at
    ``torques`` {mesh: (a, b, c)} against a continuum of 1; and the models."""
    from cases.reporting.index import populations
    v = {}
    for mesh, (a, b, c) in torques.items():
        v.update({(mesh, "fem-linear"): 1.0, (mesh, "a"): a, (mesh, "b"): b, (mesh, "c"): c})
    _case_folder(tmp_path, "torsion", _torsion_runs(v))
    pops, _ = populations(tmp_path, ["torsion"])
    return pops, ["fem-linear", "a", "b", "c"]


def test_a_failure_where_the_ranking_leaves_the_numbers_out_still_ranks_its_model(tmp_path):
    """A population the ranking leaves out for its numbers (here locking-prone) still counts
    a failure that fails a model's median, as a ranked population would: there the models
    that did not fail share the first rank and the failing model follows, so its mean rank
    moves while no score comes from it; a failure that leaves the median to the numbers, or
    none, changes no rank, and every failed run is still counted."""
    from dataclasses import replace
    pops, models = _three_models(tmp_path, {"five": (1.1, 1.3, 2.0), "six": (1.1, 1.3, 2.0)})
    (p,) = pops
    before = scorecard.overall(pops, models)
    clean = replace(p, case="cantilever", locking=True)
    assert not scorecard.counts_failures(clean)
    assert scorecard.overall(pops + [clean], models) == before
    broken = replace(clean, parts={**p.parts, "a": [None, p.parts["a"][1]]})
    assert scorecard.counts_failures(broken)
    assert [scorecard.failure_rank(broken, m) for m in "abc"] == [3, 1, 1]
    after = scorecard.overall(pops + [broken], models)
    assert after["a"][0] == (before["a"][0] + 3) / 2
    assert after["b"][0] == (before["b"][0] + 1) / 2
    assert after["a"][1] == before["a"][1]
    assert scorecard.failed_text(after["a"]) == "1 failed run where the numbers are left out"
    assert [m for _, m, _, _ in scorecard.ranked(after)][0] == "b"
    # a patch test is the consistency limit's subject: its failures are not ranked here
    assert not scorecard.counts_failures(replace(broken, locking=False, patch_test=True))
    # as in a ranked population, a failure ranks only where it fails the median: one of three
    # runs leaves a median the numbers would decide, two of three do not
    (tmp_path / "three").mkdir()
    three, _ = _three_models(tmp_path / "three", {"five": (1.1, 1.3, 2.0),
                                                  "six": (1.1, 1.3, 2.0),
                                                  "bcc": (1.1, 1.3, 2.0)})
    q = replace(three[0], case="cantilever", locking=True)
    one = replace(q, parts={**q.parts, "a": [None, *q.parts["a"][1:]]})
    two = replace(q, parts={**q.parts, "a": [None, None, q.parts["a"][2]]})
    assert not scorecard.counts_failures(one) and scorecard.counts_failures(two)
    assert scorecard.overall(three + [one], models)["a"][0] == \
        scorecard.overall(three, models)["a"][0]
    assert scorecard.failed_text(scorecard.overall(three + [one], models)["a"]) == \
        "1 failed run where the numbers are left out: counted only"


def test_a_failure_where_the_numbers_are_left_out_says_whether_it_ranked(tmp_path):
    """Where the ranking leaves a population's numbers out, a model's failed runs rank it only
    where they fail its median there (2 of 3 runs), and are counted only where they do not (1
    of 3): the count, the summary table's cell and the list of failed runs each say which
    ranked and which are counted only; a failed run in a ranked population is counted apart."""
    from dataclasses import replace
    from cases.reporting.answers import _overall_cell
    from cases.reporting.index import conclusion
    three, models = _three_models(tmp_path, {"five": (1.1, 1.3, 2.0), "six": (1.1, 1.3, 2.0),
                                             "bcc": (1.1, 1.3, 2.0)})
    q = replace(three[0], locking=True)
    a = q.parts["a"]
    two = replace(q, case="cantilever", parts={**q.parts, "a": [None, None, a[2]]})
    one = replace(q, case="self-weight", parts={**q.parts, "a": [None, a[1], a[2]]})
    assert scorecard.failure_ranks(two, "a") and not scorecard.failure_ranks(one, "a")
    pops = three + [two, one]
    means = scorecard.overall(pops, models)
    assert means["a"][5:] == (3, 2)
    assert scorecard.failed_text(means["a"]) == \
        "3 failed runs where the numbers are left out: 2 ranked, 1 counted only"
    assert _overall_cell(means, "a", pops, False, {}).endswith(
        "; where the numbers are left out: 2 of 3 in cantilever/clamped (ranked), 1 of 3 in "
        "self-weight/clamped (counted, below its median: no rank)")
    failed = conclusion(pops, models, False)[-1]
    assert "a in cantilever/clamped (2 of 3, where the numbers are left out: ranked), a in " \
        "self-weight/clamped (1 of 3, where the numbers are left out: counted, below its " \
        "median: no rank)" in failed
    # every failure left out ranks: nothing to tell apart; one in a ranked population besides
    assert scorecard.failed_text(scorecard.overall(three + [two], models)["a"]) == \
        "2 failed runs where the numbers are left out"
    assert scorecard.failed_text((1, 0.1, 1, 0, 1, 3, 2)) == \
        "4 failed runs (3 where the numbers are left out: 2 ranked, 1 counted only)"
    assert scorecard.failed_text((1, 0.1, 1, 0, 1, 2, 2)) == \
        "3 failed runs (2 where the numbers are left out)"


def test_a_discretisation_error_is_read_against_the_continuums_u_val(tmp_path):
    """FEM P1's discretisation error, as the pick names it, is said not resolved from zero
    where the continuum's u_val is as large as it, and beyond what the reference judges where
    that u_val exceeds a fifth of it; below, the plain figure."""
    from dataclasses import replace
    from cases.reporting.answers import _discretisation
    from cases.reporting.index import populations
    _case_folder(tmp_path, "torsion", _torsion_runs({(m, "fem-linear"): 1.2
                                                     for m in ("five", "six")}))
    (p,) = populations(tmp_path, ["torsion"])[0]
    assert _discretisation([p], False).endswith("(median over the meshes, torsion/clamped)")
    assert _discretisation([replace(p, u_continuum=0.05)], False).endswith(
        "torsion/clamped, beyond what its reference judges: the continuum's u_val 0.05 "
        "exceeds a fifth of it)")
    assert _discretisation([replace(p, u_continuum=0.3)], False).endswith(
        "torsion/clamped, not resolved from zero: the continuum's u_val 0.3 there is as large)")


def test_an_order_that_one_mesh_reverses_is_not_resolved(tmp_path):
    """The mesh is the unit of analysis: a ranking that reverses when one mesh family is left
    out names that mesh, one that holds on every subset does not."""
    pops, models = _three_models(tmp_path, {"five": (1.1, 1.3, 2.0), "six": (1.1, 1.3, 2.0),
                                            "bcc": (1.6, 1.2, 2.0)})
    assert [m for _, m, _, _ in scorecard.ranked(scorecard.overall(pops, models))] == \
        ["a", "b", "c"]
    # a: 0.1, 0.1, 0.6; b: 0.3, 0.3, 0.2 -> without five (or six) b's median wins
    assert scorecard.unresolved(pops, models) == {("a", "b"): "five"}


def test_single_runs_are_read_against_their_uncertainty():
    """Errors from one run each say they have no spread over meshes (n = 1), and are read
    against u_val, which for a computed comparison is u_num: differences below it are named
    tied (pair by pair along the order, never chained)."""
    from cases.reporting.answers import _single_runs_u
    assert _single_runs_u([("a", 0.10), ("b", 0.20)], 0.01, "x") == \
        "one run each, so no spread over meshes (n = 1): an order among them holds for this " \
        "mesh only; u_val 0.01, which is u_num here (x; a computed comparison has no " \
        "unmeasured input or data): no two within it"
    said = _single_runs_u([("c", 0.3), ("a", 0.10), ("b", 0.104), ("d", 0.108)], 0.005, "x")
    assert said.endswith("(x; a computed comparison has no unmeasured input or data): tied: "
                         "a, b") and "u_val 0.005" in said
    assert "1e-08" in _single_runs_u([("a", 1e-12), ("b", 2e-12)], 0.0, "x")


def test_a_model_with_more_unpaired_modes_is_not_closer_than_p1():
    """A model whose paired modes are closer to the continuum than P1's but that leaves more
    continuum modes unpaired is not said closer by cancelling; it is named with its count."""
    runs = [dict(r, bc="clamped") for r in _torsion_runs({
        ("five", "fem-linear"): 1.3, ("five", "a"): 1.0, ("five", "b"): 1.35})]
    for r in runs:
        r["lost"] = {"a": 3}.get(r["model"], 0)

    class Lossy(E.Scalar):
        unpaired_total = "lost"
        count = 1
    lines, _ = scorecard.case_findings("torsion", [Lossy("torque_nm", "torque_fem_nm",
                                                       "torque")], runs)
    (line,) = lines
    assert "only by cancelling" not in line
    assert line.endswith("it leaves more continuum modes unpaired than P1 (0): a (3).")


def test_case_findings_name_cancellation_and_the_twins():
    """A case report's opening names the FEM twins with their distance to P1 and those within
    the linear regime's nonlinearity (a tolerance set apart from what it checks), the closest
    and farthest approximation, and a model closer to the continuum than P1 only because its
    error opposes P1's (P1 1.3, the model 1.0 = the continuum: model-form 0.3, total 0)."""
    runs = [dict(r, bc="clamped") for r in _torsion_runs({
        ("five", "fem-linear"): 1.3, ("five", "fem-corotated"): 1.3 + 1e-12,
        ("five", "a"): 1.0, ("five", "b"): 1.35})]
    lines, tables = scorecard.case_findings("torsion", [E.Scalar("torque_nm", "torque_fem_nm",
                                                                "torque")], runs)
    (line,) = lines
    assert "equal to it within the linear regime's nonlinearity 0.001: fem-corotated" in line
    assert "closest b (0.05" in line and "farthest a (0.3" in line
    assert "FEM P1 itself is 0.3 [0.3-0.3] from the continuum" in line
    assert line.endswith("closer to the continuum than P1 only by cancelling its error: a.")
    assert tables[0].rows[-2][2:] == ["fem-linear (FEM P1)", "0 by construction",
                                      "0.3 [0.3-0.3] 1/1"]
    assert tables[0].rows[-1][2] == "fem-corotated (identity check: P1's law here)"
    assert "fem-corotated" not in [r[2] for r in tables[0].rows[:-2]]   # never ranked


def test_truth_cube_u_val_is_per_model_by_hand():
    """Each model's u_val combines the neo-Hookean reference's change (the continuum's, not
    the linear reference's), its own half-range over the unmeasured-input variants and the
    beads' noise; a model within it is named, and models
    closer than the larger u_val are tied."""
    from cases.reporting.answers import validation
    rows = [{"mesh": "10mm", "variant": var, "model": m, "strain": 0.2, "bead_rms_mm": v}
            for m, vals in {"a": (1.0, 1.6), "b": (0.3, 0.3)}.items()
            for var, v in zip(("bonded", "nu=0.49"), vals)]
    truth = {"headline": {"strain": 0.2, "floor_mm": 0.4, "continuum": "nh", "models": {
        "a": {"bead_rms_mm": 1.2}, "b": {"bead_rms_mm": 0.35}}},
        "references": [{"variant": "bonded", "strain": 0.2, "bead_change_mm": 0.0,
                        "model": "nh"},
                       {"variant": "bonded", "strain": 0.2, "bead_change_mm": 9.0,
                        "model": "linear"}],      # not the continuum: not its u_num
        "rows": rows, "parameters": {"models": ["a", "b"], "variants": {
            "bonded": ["bonded", "nominal", 0.499], "nu=0.49": ["bonded", "nominal", 0.49]}}}
    v = validation(truth)
    assert v["u_val"]["a"] == pytest.approx(0.5)          # sqrt(0.3^2 + 0.4^2)
    assert v["u_val"]["b"] == pytest.approx(0.4)
    assert v["within"] == ["b"] and v["tied"] == ["b"]     # 1.2 - 0.35 > 0.5


def test_consistency_limits_closer_than_their_uncertainty_are_tied():
    """Limits are tied when they differ by less than sqrt(u_a^2 + u_b^2), pair by pair: a
    model tied with each of two models resolved from each other shares a group with each."""
    from cases.reporting.answers import _limit_ties
    lims = [("a", (0.19, 0.03)), ("b", (0.192, 0.004)), ("c", (0.59, 0.08)), ("d", (0.9, 0.01))]
    assert _limit_ties(lims) == " (tied within their +-: a, b)"
    assert _limit_ties(lims[2:]) == ""
    chain = [("v", (0.19, 0.03)), ("b", (0.25, 0.07)), ("n", (0.32, 0.03))]
    assert _limit_ties(chain) == " (tied within their +-: v, b; b, n)"   # v, n: 0.13 > 0.042


def test_limits_of_different_quantities_that_overlap_are_named_not_ordered():
    """A displacement limit and a stiffness limit are never tied, but where they overlap
    within their uncertainties combined their order is not a finding: the pair is named as
    not ordered; limits of one quantity, or apart, are not."""
    from cases.reporting.answers import _limit_ties, _unordered
    lims = [("n", (0.32, 0.03, "displacement")), ("v", (0.34, 7e-7, "stiffness")),
            ("b", (0.45, 3e-5, "stiffness")), ("m", (0.59, 0.08, "displacement"))]
    assert _limit_ties(lims) == ""
    assert _unordered(lims) == (" (overlapping within their +- but limits of different "
                                "quantities, so not ordered: n (displacement), v (stiffness))")
    assert _unordered([lims[0], ("w", (0.33, 0.01, "displacement"))]) == ""
    assert _unordered(lims[2:]) == ""


def test_consistency_limit_reads_the_stiffness_the_displacement_is_blind_to():
    """On the sliding cube the top displacement is prescribed, so a model can match the shape
    while half as stiff: its consistency limit on a lattice is the larger of its displacement
    limit and its stiffness limit |ratio_inf - 1|, each with its fit's +-, and says which."""
    from cases.reporting.answers import _limit_text, _worst_limit, limits, worst
    fit = {"case": "paper-cube", "bc": "sliding", "model": "m", "verdict": "floor"}
    conv = {"fits": [
        {**fit, "mesh": "five", "e_inf": 0.03, "e_inf_err": 0.002, "ratio_inf": 0.45,
         "ratio_inf_err": 0.001},
        {**fit, "mesh": "six", "e_inf": 0.19, "e_inf_err": 0.004, "ratio_inf": 0.9,
         "ratio_inf_err": 0.02},
        {**fit, "mesh": "bcc", "e_inf": 0.2, "e_inf_err": 0.01, "ratio_inf": None},
        {**fit, "mesh": "unstructured", "verdict": "diverges", "e_inf": None}]}
    lim = limits(conv, "m")
    assert lim["five"] == pytest.approx((0.55, 0.001, "stiffness"))
    assert lim["six"] == pytest.approx((0.19, 0.004, "displacement"))
    assert lim["bcc"] == pytest.approx((0.2, 0.01, "displacement"))
    assert lim["unstructured"] == "diverges"
    assert _limit_text(_worst_limit(lim)) == "0.55 +- 0.001 (stiffness, five)"
    assert worst(lim) == "0.55 +- 0.001 (stiffness, five); diverges on unstructured"


def test_what_to_pick_is_computed_and_names_what_is_not_decided(tmp_path, monkeypatch):
    """The recommendation names FEM P1 as an identity check with the discretisation error every
    model pays, the closest approximation in the linear regime, and 'not decided' at finite
    load where one mesh reverses the order, with the candidates' failures at a case's load;
    a locking-prone population is left out of the ranking and named."""
    from cases.reporting.answers import _cost_of_replacing, recommendation
    from cases.reporting.index import populations
    from cases.library.large_compression import CASE as LARGE
    monkeypatch.setattr(type(LARGE), "locking_prone", ())
    lin = {}
    for mesh in ("five", "six"):
        lin.update({(mesh, "fem-linear"): 1.2, (mesh, "a"): 1.1, (mesh, "b"): 1.5})
    _case_folder(tmp_path, "torsion", _torsion_runs(lin))
    fin = []
    for mesh, (a, b) in {"five": (1.1, 1.3), "six": (1.4, 1.0)}.items():
        for model, f in (("fem-neohookean", 1.2), ("fem-linear", 1.0), ("a", a), ("b", b)):
            failed = (model, mesh) == ("b", "six")
            fin.append({"mesh": mesh, "bc": "clamped", "model": model,
                        "force_steps_n": None if failed else [f],
                        "force_steps_fem_n": [1.0], "nh_error_estimate": 0.01,
                        "finite_failed": "no equilibrium" if failed else None})
    (tmp_path / "large-compression").mkdir()
    (tmp_path / "large-compression" / "metrics.json").write_text(json.dumps({
        "headline_estimate": "nh_error_estimate", "runs": fin,
        "parameters": {"models": ["fem-neohookean", "fem-linear", "a", "b"], "quick": False}}))
    pops, _ = populations(tmp_path, ["torsion", "large-compression"])
    lines = recommendation(tmp_path, ["fem-linear", "fem-neohookean", "a", "b"], pops, False, {})
    assert lines[0] == "**What to pick?**"
    assert lines[1].startswith("- Linear regime: FEM P1 (fem-linear: 0 model-form error by "
                               "construction, an identity check), whose discretisation error "
                               "there is 0.2 [0.2-0.2 over the meshes] (median over the "
                               "meshes, torsion/clamped)")
    assert "the closest approximation is a, model-form error 0.1" in lines[1]
    # at finite load a's model-form errors are 0.1, 0.2 and b's 0.1, 0.2 (six reversed)
    assert "not decided on 1 case/bc population between" in lines[2]
    assert "with failed runs (no converged solve at the load): b (1 failed run)" in lines[2]
    assert recommendation(tmp_path, ["a"], pops, True, {}) == [
        "**What to pick?** Quick: not decided (`pbcm report` decides)."]
    monkeypatch.undo()                 # the case as declared: its bonded cube locks
    locked, _ = populations(tmp_path, ["torsion", "large-compression"])
    assert [p.ranked for p in locked if p.case == "large-compression"] == [False]
    said = _cost_of_replacing(locked, ["a", "b"], False)
    assert "finite load" not in said.split("(the scorecard")[0].split("; numbers left out")[0]
    assert ("numbers left out, locking-prone (FEM P1, the twin, locks there: "
            "its model-form error ranks closeness to a locked mesh): large-compression/clamped "
            "(FEM P1 up to 0.2 from the continuum there)") in said
    # and in b's cell of the summary table, beside its standing
    from cases.reporting.answers import _overall_cell
    from cases.reporting import scorecard
    cell = _overall_cell(scorecard.overall(locked, ["a", "b"], True), "b", locked, True, {})
    assert cell.endswith("failed outside the ranking: 1 of 2 in large-compression/clamped")


def test_no_equilibrium_at_a_linear_cases_load_is_a_failed_run_of_its_load_population(tmp_path):
    """A case with a linear quantity and a neo-Hookean reference has a second population, the
    same quantity at the load against P1 with the neo-Hookean law: a model that found no
    equilibrium there has a failed run in it, counted once as infinitely wrong in that
    population's rank (never moved again after the rest), and its entry counts the failures; a mesh where the reference failed poses no
    comparison and is no model's failure."""
    from cases.reporting.index import populations

    def at_load(r):
        ok = r["model"] != "a"
        mf = {"fem-neohookean": 0.0, "fem-linear": 0.05, "b": 0.2}.get(r["model"])
        # the continuum's torque at the load 1, neo-Hookean P1's 1.1
        return dict(r, nh_error_estimate=0.01, finite_failed=None if ok else "no equilibrium",
                    torque_at_load_nm=1.1 + mf if ok else None, torque_at_load_fem_nm=1.0)
    lin = [at_load(r) for r in _torsion_runs({(mesh, m): 1.2 for mesh in ("five", "six")
                                              for m in ("fem-linear", "fem-neohookean", "a",
                                                        "b")})]
    lin.append(dict(lin[0], model="b", mesh="bcc", finite_failed="no reference",
                    nh_error_estimate=None, torque_at_load_nm=None,
                    torque_at_load_fem_nm=None))
    _case_folder(tmp_path, "torsion", lin)
    pops, _ = populations(tmp_path, ["torsion"])
    assert [p.label for p in pops] == ["torsion/clamped", "torsion/clamped at the load"]
    at = pops[1]
    assert at.finite and at.quantity.p1 == "fem-neohookean"
    assert at.parts["a"] == [None, None] and len(at.parts["b"]) == 2   # bcc: no reference
    assert at.discretisation() == pytest.approx([0.1, 0.1])
    means = scorecard.overall(pops, ["fem-linear", "a", "b"], finite=True)
    assert means["a"][2] == 2 and means["b"][2] == 0
    assert [m for _, m, _, _ in scorecard.ranked(means)] == ["fem-linear", "b", "a"]
    assert scorecard.describe(means["a"]) == (
        "mean rank 3, geometric mean failed (1 of 1 populations failed at the median), 2 "
        "failed runs")


def test_the_first_is_unresolved_only_from_models_that_reach_it_themselves(tmp_path):
    """'Not resolved from' is pair by pair with the first: a model that overtakes the second
    when one mesh is left out, but never the first, is not named against the first."""
    pops, models = _three_models(tmp_path, {"five": (1.01, 1.10, 1.12),
                                            "six": (1.01, 1.10, 1.12),
                                            "bcc": (1.01, 1.15, 1.11)})
    assert [m for _, m, _, _ in scorecard.ranked(scorecard.overall(pops, models))] == \
        ["a", "b", "c"]
    assert scorecard.unresolved(pops, models) == {("b", "c"): "five"}
    assert scorecard.not_resolved_from(pops, models, "a") == {}
    assert scorecard.not_resolved_from(pops, models, "b") == {"c": "five"}


def test_each_case_weighs_one_in_the_overall_ranking(tmp_path):
    """Two boundary conditions of one case are averaged before the cases are: a model first
    on both bcs of one case and last on one other case has the mean rank (1 + 2) / 2, not
    (1 + 1 + 2) / 3, and its geometric mean is over the cases' geometric means."""
    from cases.reporting.index import populations
    runs = []
    for bc in ("clamped", "sliding"):
        runs += [dict(r, bc=bc) for r in _torsion_runs({("five", "fem-linear"): 1.0,
                                                        ("five", "a"): 1.1,
                                                        ("five", "b"): 1.2})]
    _case_folder(tmp_path, "torsion", runs)
    other = [dict(r, torque_nm=None, torque_fem_nm=None, tip_deflection_mm=q,
                  tip_deflection_fem_mm=1.0)
             for r, q in zip(_torsion_runs({("five", m): 1.0 for m in ("fem-linear", "a", "b")}),
                             (1.0, 1.4, 1.2))]
    _case_folder(tmp_path, "cantilever", other)
    pops, _ = populations(tmp_path, ["torsion", "cantilever"])
    a = scorecard.overall(pops, ["fem-linear", "a", "b"])["a"]
    assert a[0] == pytest.approx(1.5) and a[4] == 3
    assert a[1] == pytest.approx((0.1 * 0.4) ** 0.5)


def test_geometric_mean_range_leaves_one_mesh_family_out(tmp_path):
    """The geometric mean's range is its smallest and largest value over the rankings that
    leave one mesh family out: a's model-form errors 0.1 (five), 0.3 (six), 0.2 (bcc) give
    the medians 0.25, 0.15, 0.2 without five, bcc, six."""
    from cases.reporting.index import populations
    v = {}
    for mesh, a in {"five": 1.1, "six": 1.3, "bcc": 1.2}.items():
        v.update({(mesh, "fem-linear"): 1.0, (mesh, "a"): a})
    _case_folder(tmp_path, "torsion", _torsion_runs(v))
    pops, _ = populations(tmp_path, ["torsion"])
    (lo, hi), = scorecard.spread(pops, ["fem-linear", "a"]).values()
    assert (lo, hi) == (pytest.approx(0.15), pytest.approx(0.25))
    assert scorecard.largest(pops, "a") == pytest.approx(0.2)


def test_cost_ratio_is_the_in_round_step_ratio_times_the_stable_steps_with_its_range():
    """A simulated second's cost over fem-linear's is the in-round step ratio (2, rounds 1.5
    to 3) times fem-linear's stable step over the model's (10 / 5 us): 4 [3-6]."""
    from cases.reporting.answers import ratio_text
    from cases.reporting.costs import sim_ratio
    fl = {"model": "fem-linear", "stable_dt_us": 10.0, "cpu_s_per_simulated_s": 1.0}
    row = {"model": "a", "stable_dt_us": 5.0, "cpu_s_per_simulated_s": 3.9,
           "step_vs_fem-linear": 2.0, "step_vs_fem-linear_range": [1.5, 3.0]}
    assert sim_ratio(row, fl) == (4.0, [3.0, 6.0])
    assert ratio_text(row, fl) == "4 [3-6]"
    old = {k: v for k, v in row.items() if not k.endswith("_range")}
    assert sim_ratio(old, fl) == (4.0, None)


def test_a_total_with_unpaired_continuum_modes_ranks_after_one_without():
    """Against the continuum too an unpaired mode is a failed mode: a model whose paired
    frequencies are closest (0.03) but that left 9 continuum modes unpaired ranks after one
    that paired every mode (0.2), in the scorecard's total and in the case's own table."""
    from cases.reporting import rankings
    q = E.Norm("mf", "tot", "modes", unpaired="lost", unpaired_total="lost_c", count=10)
    run = {"mesh": "six", "bc": "free"}
    runs = [dict(run, model="fem-linear", mf=0.0, tot=0.05, lost=0, lost_c=0),
            dict(run, model="a", mf=0.02, tot=0.03, lost=7, lost_c=9),
            dict(run, model="b", mf=0.3, tot=0.2, lost=0, lost_c=0)]

    class Declared:
        @staticmethod
        def decompositions():
            return (q,)
    (p,) = scorecard.populations({"modes": runs}, {"modes": Declared}, {"modes": False},
                                 {"modes": set()}, {"modes": "est"})
    assert p.unpaired_total == {"fem-linear": 0, "a": 9, "b": 0}
    order = [s.model for _, s, _ in p.standings("total")]
    assert order.index("b") < order.index("a")
    (table,) = rankings.ranking(runs, "tot", "error", lost_key="lost_c")
    assert [r[2] for r in table.rows][-1] == "a"
    assert "9 unpaired modes (each run with one failed)" in table.rows[-1][-1]
    assert table.rows[-1][3:6] == ["failed", "", "0 of 1"]     # its run failed, not 0.03
    line = rankings.best_and_worst(runs, "tot", "Error", lost_key="lost_c")
    assert "to a (" in line and "Unpaired modes" in line and "a (9)" in line
    assert "a (1 of 1)" in line          # named among the failed runs


def test_truth_cube_u_input_adds_each_unmeasured_inputs_half_range_in_quadrature():
    """u_input combines the inputs apart: plate 1.6 vs 1.8 (half range 0.1), travel 1.6 vs
    1.6 (0) and nu 1.3 to 2.0 (0.35) give sqrt(0.1^2 + 0.35^2), not the half range 0.35 of
    every variant pooled."""
    from cases.measuring.error_model import input_spread
    variants = {"bonded": ("bonded", "nominal", 0.499), "frictionless": ("free", "nominal", 0.499),
                "fitted": ("bonded", "fitted", 0.499), "nu-": ("bonded", "nominal", 0.49),
                "nu+": ("bonded", "nominal", 0.4999)}
    values = {"bonded": 1.6, "frictionless": 1.8, "fitted": 1.6, "nu-": 1.3, "nu+": 2.0}
    assert input_spread(values, variants) == pytest.approx(math.hypot(0.1, 0.35))


def test_at_the_load_fem_neohookean_is_its_own_twin_and_the_others_are_measured(quick):
    """The model-form error at the load is the linear regime's quantity (the paper cube's
    reaction) measured on the finite-strain solve, against FEM P1 with the neo-Hookean law
    on the same tetrahedra: fem-neohookean, that law on P1, sits on it to the solvers'
    tolerance (an identity check); fem-linear, which lacks the geometric nonlinearity, does
    not; the case report ranks the population 'at the load'."""
    runs = json.loads((quick / "metrics.json").read_text())["runs"]
    at = {(r["mesh"], r["bc"], r["model"]): r["reaction_at_load_n"] for r in runs
          if r.get("reaction_at_load_n") is not None}
    assert at
    # fem-neohookean's run is the twin: its field lies on the reference's own P1 solve
    field = [r["disp_rel_l2_nh_p1"] for r in runs if r["model"] == "fem-neohookean"
             and r.get("disp_rel_l2_nh_p1") is not None]
    assert field and max(field) < 1e-5
    twin = {(mesh, bc): v for (mesh, bc, m), v in at.items() if m == "fem-neohookean"}
    linear = [abs(v / twin[mesh, bc] - 1) for (mesh, bc, m), v in at.items()
              if m == "fem-linear"]
    assert linear and min(linear) > 1e-3
    cont = [r["reaction_at_load_fem_n"] for r in runs if r.get("reaction_at_load_n")]
    assert cont and all(c is not None for c in cont)
    assert "at the load] What replacing FEM P1 costs (reaction at the load" in \
        (quick / "report.md").read_text()


def test_a_norms_uncertainty_includes_p1s_own_distance_to_its_twin():
    """The model-form u_val of a field comparison includes how far FEM P1's own run lies
    from the P1 twin the others are measured on (two solvers of one discrete problem): a
    model closer to the first than that is tied with it."""
    q = E.Norm("mf", "tot", "displacement", p1="fem-neohookean")
    run = {"mesh": "five", "bc": "clamped"}
    runs = [dict(run, model="fem-neohookean", mf=3e-6, tot=0.1),
            dict(run, model="a", mf=0.02, tot=0.11), dict(run, model="b", mf=0.020002,
                                                            tot=0.12)]

    class Declared:
        @staticmethod
        def decompositions():
            return (q,)
    (p,) = scorecard.populations({"torsion": runs}, {"torsion": Declared},
                                 {"torsion": False}, {"torsion": set()}, {"torsion": "est"})
    assert p.u_model_form == 3e-6
    (_, a, tied_a), (_, b, _) = p.standings()
    assert (a.model, b.model) == ("a", "b") and tied_a == ("b",)


def test_the_index_names_a_model_whose_forces_do_not_balance(tmp_path):
    """A model whose net internal force or torque exceeds round-off (1e-8 of its forces'
    sum) in some run is named with its largest value and where, even a small 1e-6; models
    that balance both to round-off are not."""
    from cases.reporting.answers import _imbalance
    runs = [{"mesh": "five", "bc": "clamped", "model": "a", "net_force_rel": 0.2},
            {"mesh": "six", "bc": "clamped", "model": "a", "net_force_rel": 0.05},
            {"mesh": "five", "bc": "clamped", "model": "c", "net_force_rel": 1e-6},
            {"mesh": "five", "bc": "clamped", "model": "b", "net_force_rel": 3e-16},
            {"mesh": "six", "bc": "clamped", "model": "d", "net_force_rel": 3e-16,
             "net_torque_rel": 0.017}]
    _case_folder(tmp_path, "torsion", runs)
    said = _imbalance(tmp_path, ["a", "b", "c", "d"])
    assert "net force: a up to 0.2 (torsion/five/clamped)" in said and " b up to" not in said
    assert "c up to 1e-06 (torsion/five/clamped)" in said
    assert "net torque: d up to 0.017 (torsion/six/clamped)" in said
    assert _imbalance(tmp_path, ["b"]) == ""


def test_the_farthest_model_of_a_case_includes_one_that_failed():
    """A case's opening names as farthest the last model of the population, a model whose
    runs failed at the median included, never the last of those that gave a number."""
    runs = _torsion_runs({(mesh, m): q for mesh in ("five", "six")
                          for m, q in (("fem-linear", 1.0), ("a", 1.1), ("b", 1.3))})
    for r in runs:
        if r["model"] == "b":
            r["torque_nm"] = None
    lines, _ = scorecard.case_findings(
        "torsion", [E.Scalar("torque_nm", "torque_fem_nm", "torque")], runs)
    assert "closest a (" in lines[0] and "farthest b (failed, 0 of 2)" in lines[0]


def test_a_mode_unpaired_against_the_continuum_fails_the_total_only():
    """A run whose modes all pair with P1 but one of whose continuum modes is unpaired keeps
    its model-form error and has no total: the total comparison counts it as failed."""
    q = E.Norm("mf", "tot", "modes", unpaired="lost", unpaired_total="lost_c")
    p1 = {"model": "fem-linear", "mf": 0.0, "tot": 0.05, "lost": 0, "lost_c": 0}
    parts = q.parts({"model": "a", "mf": 0.02, "tot": 0.06, "lost": 0, "lost_c": 2}, p1)
    assert (parts.model_form, parts.discretisation, parts.total) == (0.02, 0.05, None)


def test_how_far_names_the_problems_beyond_the_patch_test_where_a_model_diverges():
    """The consistency limit comes from the sliding cube alone; the answer also names, per
    model, the convergence fits of the other problems that diverge or stop at a floor (the
    sliding cube's own fits are not counted twice, nor a two-level fit, nor one the study
    calls not resolved)."""
    from cases.reporting.answers import _beyond_the_patch
    fits = [dict(f, levels=4) for f in (
            {"case": "cantilever", "bc": "clamped", "mesh": "six", "model": "a",
             "verdict": "diverges"},
            {"case": "torsion", "bc": "clamped", "mesh": "six", "model": "a",
             "verdict": "floor"},
            {"case": "paper-cube", "bc": "sliding", "mesh": "six", "model": "a",
             "verdict": "diverges"},
            {"case": "cantilever", "bc": "clamped", "mesh": "six", "model": "b",
             "verdict": "converges"})]
    # two levels observe no order: such a fit is no evidence either way
    fits.append(dict(fits[-1], verdict="diverges", levels=2))
    said = _beyond_the_patch({"fits": fits}, ["a", "b"])
    assert "grows under refinement for a (cantilever on six)" in said
    assert "floor in 1 of those 2 for a" in said and "for b" not in said
    # a fit the convergence study calls not resolved is counted neither way
    loose = _beyond_the_patch({"fits": fits, "not_resolved": [["torsion", "clamped", "six",
                                                               "a"]]}, ["a", "b"])
    assert "floor in" not in loose and "a (cantilever on six)" in loose


def test_the_finest_level_is_said_per_lattice_with_its_own_ties():
    """Where no limit exists, each lattice's finest-level errors are listed under its name,
    only for the models without a limit there, and ties are read within one lattice, never
    across two."""
    from cases.reporting.answers import _finest
    runs = [{"case": "paper-cube", "bc": "sliding", "mesh": mesh, "model": m, "h_mm": h,
             "disp_rel_l2": e}
            for mesh, vals in (("bcc", {"a": 0.09, "b": 0.0900001, "c": 0.3}),
                               ("unstructured", {"a": 0.0900002, "b": 0.5}))
            for m, e in vals.items() for h in (2.0, 4.0)]
    said = _finest({"runs": runs, "references": [{"case": "paper-cube", "bc": "sliding",
                                                  "error_estimate": 1e-6}]},
                   {"a": {"bcc": "not decided", "unstructured": "diverges"},
                    "b": {"bcc": "not decided", "unstructured": "diverges"},
                    "c": {"bcc": (0.1, 0.01), "unstructured": "diverges"}},
                   ["bcc", "unstructured"])
    bcc, unstructured = said.split("; on ")
    assert "c " not in bcc            # c has a limit on bcc: no finest level said there
    assert bcc.startswith("; there, the error at the finest level") and "on bcc: a 0.09" in bcc
    assert "tied: a, b" in bcc
    assert unstructured.startswith("unstructured: a 0.09 (displacement) at 2 mm, b 0.5 "
                                   "(displacement) at 2 mm")
    assert "no two within it" in unstructured
    # the finest error is read as the limit is: the larger of the displacement error and
    # |reaction ratio - 1|
    for r in runs:
        r["reaction_ratio"] = 1.6 if r["model"] == "a" else 1.0
    said = _finest({"runs": runs, "references": []}, {"a": {"unstructured": "diverges"}},
                   ["unstructured"])
    assert "on unstructured: a 0.6 (stiffness) at 2 mm" in said


def test_a_quick_index_table_decides_no_verdict(tmp_path):
    """A quick run's table says 'quick: not decided' for the model-form rankings and whether
    the runs come to rest, never a number the full run could contradict."""
    from cases.reporting.answers import QUICK_CELL, table
    from cases.reporting.index import populations
    _case_folder(tmp_path, "torsion", _torsion_runs({(mesh, m): v for mesh in ("five", "six")
                                                     for m, v in (("fem-linear", 1.2),
                                                                  ("a", 1.1))}))
    pops, _ = populations(tmp_path, ["torsion"])
    _, rows = table(tmp_path, ["a"], pops, quick=True)
    assert rows[0][1:3] == [QUICK_CELL, QUICK_CELL]
    _, full = table(tmp_path, ["a"], pops)
    assert QUICK_CELL not in full[0]


def test_how_finite_each_load_is_reads_the_linear_laws_error_at_the_load(tmp_path):
    """Each population at finite load is named with the linear law's model-form error there:
    within 0.05 a nearly linear response, the linear regime's observation again, which the
    finite-load ranking does not pool; beyond it a finite one, which it does."""
    from cases.reporting.answers import _how_finite
    from cases.reporting.index import populations

    def at_load(r, lin):
        mf = {"fem-neohookean": 0.0, "fem-linear": lin, "a": 0.2}[r["model"]]
        return dict(r, nh_error_estimate=0.01, finite_failed=None,
                    torque_at_load_nm=1.1 + mf, torque_at_load_fem_nm=1.0)
    runs = [at_load(r, 0.011) for r in _torsion_runs(
        {(mesh, m): 1.2 for mesh in ("five", "six") for m in ("fem-linear", "fem-neohookean",
                                                                "a")})]
    _case_folder(tmp_path, "torsion", runs)
    pops, _ = populations(tmp_path, ["torsion"])
    said = _how_finite(pops, "fem-linear")
    assert ("nearly linear, within 0.05 (not pooled at finite load): torsion/clamped "
            "0.011") in said
    assert [p.ranked for p in pops if p.finite] == [False]
    finite = tmp_path / "finite"
    finite.mkdir()
    _case_folder(finite, "torsion", [at_load(r, 0.08) for r in _torsion_runs(
        {(mesh, m): 1.2 for mesh in ("five", "six") for m in ("fem-linear", "fem-neohookean",
                                                                "a")})])
    pops, _ = populations(finite, ["torsion"])
    assert [p.ranked for p in pops if p.finite] == [True]
    assert "beyond: torsion/clamped 0.08" in _how_finite(pops, "fem-linear")


def test_a_contender_is_said_first_or_level_without_the_mesh_left_out():
    """'Not resolved from' says how the order fails when one mesh is left out: 'level with it'
    where the other model then shares the first rank within the uncertainty without coming
    first."""
    meshes = ("five", "six", "bcc", "unstructured")

    def opening(a, c):
        v = {}
        for k, mesh in enumerate(meshes):
            v.update({(mesh, "fem-linear"): 1.0, (mesh, "a"): 1 + a[k], (mesh, "c"): 1 + c[k]})
        lines, _ = scorecard.case_findings(
            "torsion", [E.Scalar("torque_nm", "torque_fem_nm", "torque")], _torsion_runs(v))
        return lines[0]
    assert "a is not resolved from c (level with it without bcc)" in opening(
        (0.1, 0.1, 0.1, 0.1), (0.105, 0.2, 0.2, 0.104))


def test_a_locking_prone_case_names_no_closest_model():
    """A locking-prone population's opening says its order is closeness to a locked mesh and
    names the model nearest the locked twin, never a 'closest' model."""
    runs = _torsion_runs({("five", "fem-linear"): 1.3, ("five", "a"): 1.0, ("five", "b"): 1.35})
    lines, _ = scorecard.case_findings("torsion", [E.Scalar("torque_nm", "torque_fem_nm",
                                                            "torque")], runs,
                                       locking_prone=("clamped",))
    assert "locking-prone: FEM P1 locks here, so the order below is closeness to a locked " \
        "mesh, not a ranking of the models" in lines[0]
    assert "nearest the locked twin b (" in lines[0] and "closest" not in lines[0].split(
        "FEM P1 itself")[0]


def test_the_scorecard_names_failures_against_the_continuum_too():
    """A run that fails against the continuum alone (a continuum mode left unpaired, its
    model-form number intact) is named among the failed runs of the scorecard's conclusion."""
    from cases.reporting.index import conclusion
    q = E.Norm("mf", "tot", "modes", unpaired="lost", unpaired_total="lost_c", count=10)
    run = {"mesh": "six", "bc": "free"}
    runs = [dict(run, model="fem-linear", mf=0.0, tot=0.05, lost=0, lost_c=0),
            dict(run, model="a", mf=0.02, tot=0.03, lost=0, lost_c=9)]

    class Declared:
        @staticmethod
        def decompositions():
            return (q,)
    pops = scorecard.populations({"modes": runs}, {"modes": Declared}, {"modes": False},
                                 {"modes": set()}, {"modes": "est"})
    last = conclusion(pops, ["fem-linear", "a"], False)[-1]
    assert last.endswith("against the continuum (the total): a in modes/free (1 of 1).")


def test_a_failed_check_outside_the_rankings_is_named_in_the_index():
    """A case's own check that failed (a '<check>_failed' run key no population counts) is
    named in the index with its model, case, mesh and bc, and the runs of the held modal
    check that leave a mode unpaired per case and model; the ranked phases' failures are
    left to the rankings; with none failed the line says none."""
    from cases.reporting.index import failed_checks
    runs = [{"model": "msm", "mesh": "bcc", "bc": "clamped", "homogeneous_failed": "no root",
             "static_failed": "x", "failed": None},
            {"model": "a", "mesh": "six", "bc": "clamped", "homogeneous_failed": None}]
    line = failed_checks({"large-compression": {"runs": runs}})
    assert line.endswith("report): msm on large-compression/bcc/clamped (homogeneous).")
    assert failed_checks({"c": {"runs": runs[1:]}}).endswith(": none.")
    held = [{"model": "a", "mesh": m, "bc": "clamped", "modes_unpaired_held": n}
            for m, n in (("five", 0), ("six", 2), ("bcc", 0))] \
        + [{"model": "a", "mesh": "five", "bc": "sliding", "modes_unpaired_held": None}]
    assert failed_checks({"paper-cube": {"runs": held}}).endswith(
        "report): a on paper-cube, 1 of 3 runs (modes with the top held: a mode unpaired).")


def test_a_studys_failed_run_is_named_in_the_index():
    """A study's run that gave no number (a control of the artefact study, say) is named in
    the index's failure line with its study, mesh, bc and the failure's first clause; a study
    without failures says none."""
    from cases.reporting.index import failed_checks
    cells = [{"model": "pbcm-balanced", "mesh": "six-17", "bc": "sliding",
              "failed": "tetrahedron 3 is inverted; reduce the load step"},
             {"model": "msm", "mesh": "six-17", "bc": "sliding", "failed": None}]
    line = failed_checks({}, {"artefact": ({"cells": cells}, ("cells",))})
    assert line.endswith("studies (no number; each named in its report): pbcm-balanced on "
                         "artefact/six-17/sliding (tetrahedron 3 is inverted).")
    assert failed_checks({}, {"artefact": ({"cells": cells[1:]}, ("cells",))}).endswith(
        "report): none.")


def test_no_model_ranks_above_one_with_a_smaller_median():
    """A model not resolved from the first of an earlier group shares that group's rank only
    if every model with a smaller median between them does: c is not resolved from a, but b,
    between them, is ranked apart from a, so c ranks with b and is still named as not
    resolved from a; models that all failed their median are ordered by how many runs
    failed."""
    rows = E.standings({"a": [0.10, 0.10, 0.30], "b": [0.17] * 3, "c": [0.05, 0.18, 0.40]},
                       u=0.0)
    assert [(r, s.model) for r, s, _ in rows] == [(1, "a"), (2, "b"), (2, "c")]
    assert rows[2][2].unresolved == ("a", "b")
    failed = E.standings({"x": [0.1, None, None], "y": [None, None, None]}, u=0.0)
    assert [s.model for _, s, _ in failed] == ["x", "y"]


def test_a_nearly_linear_load_is_shown_in_a_case_not_ranked_a_second_time():
    """At a load the linear law meets within NEARLY_LINEAR on the case's quantity, the case's
    opening says the population is the linear regime's observation again and names no
    closest model; at a load where it does not, the closest is named."""
    def runs(lin_at_load):
        out = []
        for mesh in ("five", "six"):
            for m, q in (("fem-neohookean", 1.1), ("fem-linear", 1.1 + lin_at_load),
                         ("a", 1.3), ("b", 1.5)):
                out.append({"mesh": mesh, "bc": "clamped", "model": m,
                            "torque_at_load_nm": q, "torque_at_load_fem_nm": 1.0,
                            "nh_error_estimate": 0.001})
        return out
    q = E.Scalar("torque_at_load_nm", "torque_at_load_fem_nm", "torque at the load",
                 p1=E.P1_FINITE, posed="nh_error_estimate")
    near, _ = scorecard.case_findings("torsion", [q], runs(0.01),
                                      estimate_key="nh_error_estimate")
    assert "nearly linear at this load (fem-linear 0.01" in near[0] and "closest" not in near[0]
    far, _ = scorecard.case_findings("torsion", [q], runs(0.2), estimate_key="nh_error_estimate")
    assert "nearly linear" not in far[0] and "closest" in far[0]


def test_an_order_is_broken_into_the_groups_it_resolves():
    """The ranked order is said as groups split only where every model before the split is
    resolved from every model after it (a, c loose puts b between them in the group), and
    an order with no such split says so."""
    from cases.reporting.answers import _resolved_groups
    order = ["a", "b", "c", "d", "e"]
    assert _resolved_groups(order, {("a", "c"), ("d", "e")}) == (
        " (resolved: {a, b, c} before {d, e}; within a group, not every pair resolved)")
    assert _resolved_groups(order, set()) == (
        " (resolved: {a} before {b} before {c} before {d} before {e}; within a group, not "
        "every pair resolved)")
    assert _resolved_groups(order, {("a", "b"), ("c", "b"), ("d", "c"), ("e", "a")}
                            ).startswith(" (no order resolved among them")
    assert _resolved_groups(["a"], set()) == ""


def test_a_contender_whose_cost_range_lies_below_the_firsts_is_the_cheaper_pick():
    """Among the first and the models it is not resolved from, one whose cost per simulated
    second (its range over the bench's rounds) lies wholly below the first's is named the
    cheaper pick; overlapping ranges name none."""
    from cases.reporting.answers import _cheaper_contender
    def row(m, r, lo, hi):
        return {"model": m, "stable_dt_us": 1.0, "cpu_s_per_simulated_s": r,
                "step_vs_fl": r, "step_vs_fl_range": [lo, hi]}
    rows = {"fl": {"model": "fl", "stable_dt_us": 1.0, "cpu_s_per_simulated_s": 1.0},
            "a": row("a", 12, 7.6, 12), "b": row("b", 4.7, 4.4, 4.9), "c": row("c", 8, 7, 9)}
    said = _cheaper_contender("a", ["b", "c"], rows, "fl")
    assert said.startswith("; b, not resolved from it in model-form error, costs 4.7 "
                           "[4.4-4.9] times fl's") and said.endswith("b is the cheaper pick")
    assert _cheaper_contender("a", ["c"], rows, "fl") == ""
    assert _cheaper_contender("a", [], rows, "fl") == ""


class _Pop:
    """A population stub: its case and each model's score (what the paired comparison reads)."""

    def __init__(self, case, scores, finite=False, unordered=()):
        self.case, self.scores, self.finite, self.ranked = case, scores, finite, True
        self.meshes, self.unordered = {}, set(unordered)

    def standings(self):
        from types import SimpleNamespace
        return [(0, SimpleNamespace(model=m, score=s),
                 tuple(o for o in self.scores if o != m and {m, o} <= self.unordered))
                for m, s in self.scores.items()]

    def without(self, mesh):
        return self


def test_a_pair_kept_in_order_when_compared_directly_is_resolved():
    """Two models compared directly (the geometric mean over the cases of their paired
    errors' ratio) are resolved when that ratio stays below 1 whatever case is left out, even
    where their mean ranks level on a subset; one case reversing the ratio leaves them not
    resolved, and a failed population gives no ratio."""
    ahead = [_Pop("p", {"a": 0.1, "b": 0.5}), _Pop("q", {"a": 0.1, "b": 0.5}),
             _Pop("r", {"a": 0.31, "b": 0.3})]
    assert scorecard.paired_ahead(ahead, "a", "b")
    assert not scorecard.paired_ahead(ahead, "b", "a")
    flips = [_Pop("p", {"a": 0.1, "b": 0.5}), _Pop("r", {"a": 0.31, "b": 0.3})]
    assert not scorecard.paired_ahead(flips, "a", "b")      # without p, b is ahead
    failed = ahead + [_Pop("s", {"a": float("inf"), "b": 0.3})]
    assert not scorecard.paired_ahead(failed, "a", "b")


def test_a_pair_no_population_resolves_is_not_resolved_by_pooling():
    """Two models whose ratio stays below 1 whatever is left out, but which every case's
    report leaves tied or not resolved, are not resolved in the index either; one population
    that orders them beyond their uncertainty resolves the pair."""
    tied = [_Pop("p", {"a": 0.1, "b": 0.11}, unordered="ab"),
            _Pop("q", {"a": 0.1, "b": 0.12}, unordered="ab")]
    assert not scorecard.paired_ahead(tied, "a", "b")
    one = [_Pop("p", {"a": 0.1, "b": 0.11}, unordered="ab"), _Pop("q", {"a": 0.1, "b": 0.5})]
    assert scorecard.paired_ahead(one, "a", "b")


def test_a_growing_stiffness_error_bounds_the_limit_and_fems_nonlinearity_is_no_limit():
    """A stiffness error that grows at every refinement (0.682, 0.687, 0.702) has no
    extrapolated limit but bounds the lattice's from below: at least its finest value, +-
    1.25 x its last change; FEM's stiffness at the reference's own level is no limit; a
    stiffness bound beside a displacement with no limit names the displacement's verdict."""
    from cases.reporting.answers import _no_limit, limits
    fit = {"case": "paper-cube", "bc": "sliding", "model": "m"}
    conv = {"fits": [
        {**fit, "mesh": "six", "verdict": "floor", "e_inf": 0.19, "e_inf_err": 0.004,
         "ratio_inf": None, "ratio_why": "not asymptotic: its finest changes grow"},
        {**fit, "mesh": "five", "verdict": "exact", "e_inf": 2e-10, "e_inf_err": 2e-10,
         "ratio_inf": 1.00005, "ratio_inf_err": 1e-9},
        {**fit, "mesh": "bcc", "verdict": "not decided", "e_inf": 0.0, "e_inf_err": 0.18,
         "ratio_inf": 1.04, "ratio_inf_err": 0.013}],
        "runs": [{**fit, "mesh": "six", "h_mm": h, "reaction_ratio": r, "disp_rel_l2": 0.2}
                 for h, r in ((8.0, 0.318), (4.0, 0.3125), (2.0, 0.298))]}
    lim = limits(conv, "m")
    assert lim["six"][0] == pytest.approx(0.702) and lim["six"][2].startswith("stiffness, grow")
    assert lim["six"][1] == pytest.approx(1.25 * (0.702 - 0.6875))
    assert lim["five"] == pytest.approx((2e-10, 2e-10, "displacement"))
    assert lim["bcc"][2] == "stiffness; displacement not decided"
    assert "displacement not decided on bcc (its stiffness 0.04 +- 0.01 there)" in _no_limit(lim)
    # said as a bound, its finest value +- 1.25 x its last change, over how many lattices
    from cases.reporting.answers import _limit_text, _worst_limit
    assert _limit_text(_worst_limit(lim), 3) == (
        "at least 0.7 +- 0.02 (stiffness growing under refinement on six: no limit, its finest "
        "value +- 1.25 x its last change; 3 lattices)")


def test_a_studys_failed_runs_are_named_once_per_model_and_cause():
    """The index names every failed run of a study, one entry per (study, model, cause) with
    the runs it holds (a place once), so that a cause failing a model on every mesh is one
    fact; a study with no failure says none."""
    from cases.reporting.index import failed_checks
    cause = "build: the fit gave c = 0; no term adds"
    runs = [{"model": "m", "mesh": f"mesh{i}", "bc": "clamped", "failed": cause}
            for i in range(8) for _ in range(2)]
    runs += [{"model": "m", "mesh": "mesh0", "bc": "sliding", "failed": "inverted; reduce"},
             {"model": "k", "mesh": "mesh1", "bc": "clamped", "failed": None}]
    line = failed_checks({}, {"study": ({"cells": runs, "names": {"m": "model m"}},
                                        ("cells",))})
    assert ("model m on study, 16 runs in 8 places (mesh0/clamped, mesh1/clamped, mesh2/clamped, "
            "mesh3/clamped, mesh4/clamped, mesh5/clamped and 2 more) (build: the fit gave "
            "c = 0)") in line
    assert "model m on study/mesh0/sliding (inverted)" in line and "k on" not in line
    # one cause whose numbers differ from run to run is one entry, each run named by its case
    rest = [{"model": "k", "case": case, "mesh": "five", "bc": "sliding",
             "failed": f"k(n=8) is not coming to rest: motion not shrinking ({x} a period)"}
            for case, x in (("torsion", 0.011), ("cantilever", 0.0087))]
    line = failed_checks({}, {"study": ({"cells": rest}, ("cells",))})
    assert line.endswith("k on study, 2 runs (torsion/five/sliding, cantilever/five/sliding) "
                         "(k(n=8) is not coming to rest: motion not shrinking).")
    assert failed_checks({}, {"study": ({"cells": []}, ("cells",))}).endswith(
        "Failed runs of the studies (no number; each named in its report): none.")
