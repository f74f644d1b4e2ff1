"""The artefact study: the metric's check on smooth fields, the thresholds, the decomposition of
the mirrored split's signature into FEM P1's and the model's part, the three hypotheses and the
reading verdict (computed on cells written here, whose answer is known), and the quick study
against its gold with the controls that must hold whatever the models do."""
import json
from pathlib import Path

import numpy as np
import pytest

from cases import metrics as M
from cases.studies.artefact import analysis
from cases.studies.artefact.study import SPLITS, _free_layers

ROOT = Path(__file__).resolve().parents[1]

FIVE, SIX, BCC, UNMIRRORED = (SPLITS[k] for k in ("five", "six", "bcc", "five-unmirrored"))


def reference(n, bc):
    """A continuum layer profile [mm] on ``n`` layers: the sliding cube's uniform expansion, or
    a clamped barrel a little asymmetric (the push comes from the top), as the real ones are."""
    y = np.linspace(0.0, 1.0, n)
    if bc == "sliding":
        return np.full(n, 0.3969)
    return 0.45 * np.sin(np.pi * y) * (1 + 0.01 * (y - 0.5))


def cell(mesh, split, model, alt, bc="sliding", load="paper", n=5, family="particle",
         reading="balanced", constant="calibrated", normal="none", scale=1.0, **kw):
    """One cell whose profile is ``scale`` times the continuum's plus ``alt`` (relative to the
    continuum's mean) times (-1)^k on the free layers; its signature computed by the metric
    (None where it has none, or ``alt`` is None: a failed or undefined cell)."""
    ref = reference(n, bc)
    free = _free_layers(bc, n)
    profile = scale * ref + (alt or 0.0) * np.abs(ref).mean() * (-1.0) ** np.arange(n) * free
    mm, rel_ = M.alternation(profile, ref, free) if alt is not None else (None, None)
    return {"mesh": mesh, "split": split, "nodes_per_side": n, "model": model, "bc": bc,
            "load": load, "family": family, "reading": reading, "constant": constant,
            "normal": normal, "alternation_rel": rel_, "alternation_mm": mm,
            "bulge_profile_mm": profile.tolist(), "bulge_profile_fem_mm": ref.tolist(),
            "failed": None, "tets": 320, **kw}


def test_a_value_within_a_fifth_of_a_threshold_is_at_it():
    """Every threshold (the clear level, the factor 3) names a value within 20 % of it 'at',
    undecided, and reads above and below only outside that band."""
    assert analysis.against(0.0109, 0.01) == "at"
    assert analysis.against(0.0082, 0.01) == "at"
    assert analysis.against(0.0121, 0.01) == "above"
    assert analysis.against(0.0079, 0.01) == "below"
    assert analysis.against(3.33, 3.0) == "at" and analysis.against(3.52, 3.0) == "at"
    assert analysis.against(None, 3.0) is None


def test_the_pattern_is_read_over_the_models_own_lateral_displacement():
    """The clear level applies to the signature over the model's own mean lateral displacement:
    a body with a third of the continuum's lateral displacement and a signature of 0.005 of the
    reference's mean is clear (about 0.015 of its own); + is the paper's sign; within 20 % of
    the level is 'at'; undefined or failed is None."""
    soft = cell("five", FIVE, "m", 0.005, scale=1 / 3)
    # its own mean over 5 layers: 1/3 of the continuum's plus 1/5 of the alternation
    assert analysis.signature_own(soft) == pytest.approx(0.005 / (1 / 3 + 0.001), rel=1e-9)
    assert analysis.lateral_error(soft) == pytest.approx(-2 / 3 + 0.001, rel=1e-9)
    assert analysis.pattern(soft) == "paper"
    assert analysis.pattern(cell("five", FIVE, "m", -0.02)) == "reversed"
    assert analysis.pattern(cell("five", FIVE, "m", 0.005)) == "none"
    assert analysis.pattern(cell("five", FIVE, "m", 0.0105)) == "at"
    assert analysis.pattern(cell("five", FIVE, "m", None)) is None
    assert analysis.pattern(cell("five", FIVE, "m", 0.5, failed="no")) is None


@pytest.mark.parametrize("n, bc, decides", [(9, "sliding", True), (17, "sliding", True),
                                            (9, "clamped", False), (5, "sliding", False)])
def test_the_metric_check_decides_only_where_smooth_fields_leak_below_the_clear_level(
        n, bc, decides):
    """The metric's check on the layers it reads: the pure (-1)^k pattern reads 1; beside the
    uniform sliding reference the weights absorb degree n - 2 and smooth fields (barrel,
    Gaussians of 2 and 4 layer spacings, end boundary layer) leak below 0.01 of their height
    from 9 layers; beside an asymmetric clamped barrel on 7 free layers they absorb n - 3 and
    a Gaussian of 2 spacings leaks more than 0.01: that unit decides nothing, nor do 5 layers."""
    ref = reference(n, bc)
    got = analysis.leakage(ref, _free_layers(bc, n))
    assert got["alternation_reads"] == pytest.approx(1.0, rel=1e-9)
    assert got["degree"] == got["free"] - (2 if bc == "sliding" else 3)
    assert set(got["leaks"]) == {"barrel", "Gaussian, sd 2 layers", "Gaussian, sd 4 layers",
                                 "end boundary layer"}
    assert (got["worst"] < 0.008) == decides and got["versus_clear"] == (
        "below" if decides else "above")
    cells = [cell(f"five-{n}", FIVE, "fem-linear", 0.0, bc=bc, n=n, family="fem")]
    assert analysis.metric_check(cells)[(n, bc)]["decides"] == (decides and n >= 9)


def test_the_metric_check_of_three_free_layers_has_no_signature():
    """The clamped five-layer cube (three free layers) has no signature: the check says so and
    the unit decides nothing."""
    cells = [cell("five", FIVE, "fem-linear", 0.0, bc="clamped", family="fem")]
    row = analysis.metric_check(cells)[(5, "clamped")]
    assert not row["decides"] and "3 free layers" in row["why"]


def test_the_rank_interval_is_fishers():
    """The 95 % interval of a Spearman correlation: tanh(atanh(rho) -+ 1.96 sqrt(1.06/(n-3)));
    none below 4 points."""
    lo, hi = analysis.rank_interval(0.0, 28)
    assert hi == pytest.approx(np.tanh(1.96 * np.sqrt(1.06 / 25)), rel=1e-9) and lo == -hi
    assert analysis.rank_interval(0.5, 3) is None


MODELS = (("b", "none", "particle", "calibrated"), ("b+n", "normal_edge", "particle",
                                                    "calibrated"),
          ("msm", "edges", "msm", "springs"), ("fem-linear", "fem", "fem", "none"))


def _world(signature, patch=lambda model, split, n: 0.01, models=MODELS):
    """Cells of every split at 5, 9 and 17 nodes per side, both bases, of a reading without
    and with a normal term, msm and the control, with ``signature(model, split, n, bc)`` at
    the paper's push (and at the linear load) and ``patch`` the sliding patch-test error
    (linear load, below 17)."""
    out = []
    for kind, split in SPLITS.items():
        for n in (5, 9, 17):
            mesh = kind if n == 5 else f"{kind}-{n}"
            for model, normal, family, constant in models:
                f = dict(normal=normal, family=family, constant=constant, n=n,
                         reading="none" if family != "particle" else "balanced")
                for bc in ("sliding", "clamped"):
                    out.append(cell(mesh, split, model, signature(model, split, n, bc), bc=bc,
                                    disp_rel_l2=0.1, **f))
                    if n < 17:
                        out.append(cell(mesh, split, model, signature(model, split, n, bc),
                                        bc=bc, load="linear", disp_rel_l2=patch(model, split, n),
                                        **f))
    return out


def _mirror_world(model, split, n, bc):
    if model == "fem-linear":
        return 0.0
    if split != FIVE:
        return 0.001
    return (0.33 if model == "msm" else 0.32) / (n - 1)     # halves with h on the mirror only


def _unit(a, n, bc):
    return next(u for u in a["hypotheses"]["mirror"]["units"] if (u["n"], u["bc"]) == (n, bc))


def test_the_mirror_holds_where_only_the_mirrored_split_alternates():
    """A signature on the mirrored five split only, halving with h, FEM P1 clean: every unit
    that passes the metric's check reads the models' own part with the paper's sign; the
    clamped 9-node unit (7 free layers) is shown but decides nothing; a term that changes
    nothing (b+n, the same signature as b) is one observation with b (n of N); the order in h
    is 1 on the sliding base and not computed on the clamped one."""
    a = analysis.answer(_world(_mirror_world))
    m = a["hypotheses"]["mirror"]
    assert m["deciding"] == [(9, "sliding"), (17, "clamped"), (17, "sliding")]
    for n, bc in m["deciding"]:
        u = _unit(a, n, bc)
        assert analysis.classes(u) == {"own +": ["b", "msm"]}, (n, bc)
        assert (u["distinct"], u["run"]) == (2, 3)
        assert next(r for r in u["rows"] if r["name"] == "b+n")["same_as"] == "b"
    clamped9 = _unit(a, 9, "clamped")
    assert not clamped9["decides"] and all(r["kind"].startswith("not decided")
                                           for r in clamped9["rows"] if not r["same_as"])
    orders = m["orders"]
    assert orders["clamped"]["orders"] == {} and "does not decide" in orders["clamped"]["why"]
    assert orders["sliding"]["orders"] == pytest.approx({"b": 1.0, "msm": 1.0})
    assert orders["sliding"]["of"] == 2
    assert a["by_reading"] == {"b": "+", "msm": "+"}
    assert a["cause"].startswith("conditional on the reading")
    assert "the paper's 5-node cube: not decided" in a["cause"]
    assert a["text"].startswith("On the paper's own 5-node cube: not decided")


def test_the_models_part_is_its_signature_less_fem_p1s_on_the_same_mesh():
    """Where FEM P1 on the mirrored split alternates as much as the models, the models' part
    (model - FEM P1) is 0: 'mesh only', never the models' own; where a model adds to FEM P1's
    its part is the difference, and it is its own."""
    def shared(model, split, n, bc):
        return 0.32 / (n - 1) if split == FIVE else 0.0
    a = analysis.answer(_world(shared))
    for n, bc in a["deciding"]:
        assert set(analysis.classes(_unit(a, n, bc))) == {"mesh only"}, (n, bc)

    def adds(model, split, n, bc):
        base = 0.01 if split == FIVE else 0.0
        return base + (0.02 if model == "msm" and split == FIVE else 0.0)
    u = _unit(analysis.answer(_world(adds)), 17, "sliding")
    msm = next(r for r in u["rows"] if r["name"] == "msm")
    assert msm["part"] == pytest.approx(0.02, rel=1e-6) and msm["kind"] == "own +"
    assert analysis.classes(u)["mesh only"] == ["b"]


def test_a_part_on_every_split_is_not_the_mirrors():
    """A model whose own part is as large on the conforming splits as on the mirrored one is
    'own on every split': resolved, not the mirror's."""
    def everywhere(model, split, n, bc):
        return 0.0 if model == "fem-linear" else 0.02
    a = analysis.answer(_world(everywhere))
    assert set(analysis.classes(_unit(a, 17, "sliding"))) == {"own on every split"}


def test_a_failed_control_fails_the_models_observation_and_names_the_cause():
    """A control cell that failed (an inverted element) makes the model's observation at that
    unit 'failed control (...)' with the cause, never 'same as another model'."""
    world = _world(_mirror_world)
    for c in world:
        if c["model"] == "b" and c["split"] == SIX and c["nodes_per_side"] == 17:
            c.update(failed="tetrahedron 3 (nodes [0, 1, 2, 3]) is inverted or flattened in "
                     "term 'shear'; reduce the load step", alternation_rel=None,
                     alternation_mm=None)
    u = _unit(analysis.answer(world), 17, "sliding")
    b = next(r for r in u["rows"] if r["name"] == "b")
    assert b["kind"].startswith("failed control (six (Kuhn): failed (inverted element: "
                                "tetrahedron 3")
    assert analysis.classes(u)["failed"] == ["b"]


def test_normal_stress_is_tested_only_where_the_term_is_active():
    """A term that changes nothing (the same signature to 1e-6) is 'not tested', never a pair;
    a term that removes a model's own part is counted: (b) holds."""
    def inactive(model, split, n, bc):
        return 0.03 if model in ("b", "b+n") and split == FIVE else 0.0
    ns = analysis.answer(_world(inactive))["hypotheses"]["normal_stress"]
    assert not ns["decided"] and ns["tested"] == 0
    assert any("changes nothing" in why for *_, why in ns["untested"])

    def removes(model, split, n, bc):
        return 0.03 if model == "b" and split == FIVE else 0.0
    a = analysis.answer(_world(removes))
    ns = a["hypotheses"]["normal_stress"]
    assert ns["decided"] and ns["holds"] and ns["removed"] == ns["tested"] == 3
    assert all(p["reduced"] == "above" for p in ns["pairs"])
    assert "3 of 3 pairs" in a["cause"]


def test_consistency_is_signed_with_an_interval_and_untestable_without_a_clear_signature():
    """Signatures ordered as the patch-test errors: the signed rank correlation is 1 on every
    conforming mesh, its interval above 0; reversed: -1, not tracking; where no model has a
    clear signature the mesh is 'not testable'."""
    models = MODELS + tuple((f"m{i}", "none", "particle", "calibrated") for i in range(4))
    sig = {"b": 0.03, "b+n": 0.025, "msm": 0.02, "m0": 0.015, "m1": 0.012, "m2": 0.011,
           "m3": 0.005, "fem-linear": 0.0}
    world = _world(lambda model, split, n, bc: sig[model], models=models,
                   patch=lambda model, split, n: sig[model] / 3)
    cs = analysis.answer(world)["hypotheses"]["consistency"]
    assert cs["holds"] and {r["mesh"] for r in cs["rows"]} == {"five-9", "six-9", "bcc-9"}
    assert all(r["rho"] == pytest.approx(1.0) and r["interval"][0] > 0 for r in cs["rows"])
    world = _world(lambda model, split, n, bc: sig[model], models=models,
                   patch=lambda model, split, n: 1 / (1 + sig[model]))
    cs = analysis.answer(world)["hypotheses"]["consistency"]
    assert not cs["holds"] and all(r["verdict"] == "does not track" for r in cs["rows"])
    small = _world(lambda model, split, n, bc: sig[model] / 10, models=models,
                   patch=lambda model, split, n: sig[model] / 3)
    cs = analysis.answer(small)["hypotheses"]["consistency"]
    assert not cs["testable"] and all(r["verdict"].startswith("not testable")
                                      for r in cs["rows"])


def test_the_linear_load_check_reads_a_load_independent_signature_as_one():
    """Signatures equal at the linear load and at the push: the ratio is 1 on every base, and
    no cell is named as changing with the load."""
    lin = analysis.answer(_world(_mirror_world))["linear"]
    for bc, x in lin.items():
        assert x["median"] == pytest.approx(1.0) and x["changed"] == [], bc


def test_five_layers_alone_decide_nothing():
    """Without a mesh of 9 or more layers the answer is 'not decided', whatever the 5-layer
    view shows."""
    world = [c for c in _world(_mirror_world) if c["nodes_per_side"] == 5]
    a = analysis.answer(world)
    assert not a["decided"] and a["cause"] == "not decided"
    assert "On the paper's own 5-node cube: not decided" in a["text"]
    assert "Not decided: no mesh with 9 or more layers was run" in a["text"]


def test_the_reading_verdict_shows_damped_and_undamped_and_marks_untimed_costs():
    """Each reading's decidable observables on the paper's lattice: flutter against half the
    damping we assume and against round-off without damping; a literal reading's cost is not
    measured (its stored ratio is the calibrated one's); a reading with a normal-stress term is
    shown apart, never the verdict."""
    def rows(model, rate):
        return [cell("five", FIVE, model, 0.0, disp_rel_l2=0.1),
                cell("five", FIVE, model, 0.0, bc="clamped", growth_rate_1_s=rate,
                     disp_rel_l2=0.2),
                cell("five", FIVE, model, 0.0, load="linear", disp_rel_l2=0.05)]
    cells = rows("a", 0.0) + rows("a-literal", 0.0) + rows("b", 5.0) + rows("a+n", 0.0)
    table = analysis.reading_table(cells, {"a": 8.0, "a-literal": 8.0, "b": 8.0, "a+n": 12.0},
                                   ["a", "a-literal", "b"], 50.0, ["a+n"])
    by = {r["model"]: r for r in table}
    assert by["a-literal"]["matches"]["cost"] is None and not by["a-literal"]["timed"]
    assert by["b"]["stable_damped"] and not by["b"]["stable_undamped"]
    assert [by[m]["score"] for m in ("a", "a-literal", "b", "a+n")] == [1, 1, 1, 2]
    assert [by[m]["score_undamped"] for m in ("a", "a-literal", "b")] == [1, 1, 0]
    v = analysis.reading_verdict(table, 50.0)
    assert v["sure"] == "tied" and set(v["tied"]) == {"a", "a-literal", "b"}
    assert v["undamped"]["tied"] == ["a", "a-literal"] and v["undamped"]["margin"] == 1
    assert v["text"].startswith("No reading reproduces all the paper's observables.")
    assert "exceeds 25 1/s" in v["text"] and "not timed: a-literal" in v["text"]
    assert v["with_normal_term"] == ["a+n"]


def test_the_quick_study_holds_its_gold_and_its_controls(quick_artefact, capsys):
    """The quick study matches its gold; whatever the models do, the FEM control on a
    conforming mesh never alternates and passes the sliding patch test, on the
    non-conforming unmirrored five split it fails it, msm on the mirrored five split shows
    the paper's sign pattern, and the quick report says it decides nothing and shows the
    metric's check."""
    from cases.cli import main
    status = main(["check", "--metrics", str(quick_artefact.parent), "--gold",
                   str(ROOT / "gold"), "--allow-new"])
    assert status == 0, capsys.readouterr().out
    doc = json.loads((quick_artefact / "metrics.json").read_text())
    cells = doc["cells"]
    fem = [c for c in cells if c["model"] == "fem-linear" and not c["unmatched_faces"]
           and c["alternation_rel"] is not None]
    assert fem and not any(analysis.alternating(c) for c in fem)
    assert max(abs(c["alternation_rel"]) for c in fem if c["bc"] == "sliding") < 1e-6
    assert max(c["disp_rel_l2"] for c in cells if c["model"] == "fem-linear"
               and c["bc"] == "sliding" and c["load"] == "linear"
               and not c["unmatched_faces"]) < 1e-8
    un = next(c for c in cells if c["model"] == "fem-linear" and c["mesh"] == "five-unmirrored"
              and c["bc"] == "sliding" and c["load"] == "linear")
    assert un["unmatched_faces"] > 0 and un["disp_rel_l2"] > 1e-3
    msm = next(c for c in cells if c["model"] == "msm" and c["mesh"] == "five"
               and c["bc"] == "sliding" and c["load"] == "paper")
    p = msm["bulge_profile_mm"]
    assert p[0] > p[1] < p[2] > p[3] < p[4] and msm["alternation_rel"] > 0.01
    ref = msm["bulge_profile_fem_mm"]
    assert max(ref) - min(ref) < 1e-9 * max(ref)
    md = (quick_artefact / "report.md").read_text()
    assert "**Quick: not decided**" in md and "## The metric's check" in md
    assert doc["answer"]["text"] in md and doc["verdict"]["text"] in md
    assert (quick_artefact / "cells.md").is_file()


class _Stagnating:
    """A model whose Newton converges only with ``needs`` or more load steps."""

    def __init__(self, needs):
        self.needs, self.asked = needs, []

    def solve_static(self, bc, load_steps, rtol=1e-10):
        from model.errors import ConvergenceError
        self.asked.append(load_steps)
        if load_steps < self.needs:
            raise ConvergenceError(f"stagnated in {load_steps} steps")
        return f"solved in {load_steps}"


def test_a_static_solve_splits_the_load_where_newton_from_rest_stagnates():
    """A static solve (a case's load, an artefact cell) is tried in 1, 2, 4 and 8 equal load
    steps and fails only when every split does, with the last split's error."""
    from cases.framework import LOAD_SPLITS, solve_split
    from model.errors import ConvergenceError
    pm = _Stagnating(2)
    assert solve_split(pm, {}) == ("solved in 2", 2) and pm.asked == [1, 2]
    pm = _Stagnating(1)
    assert solve_split(pm, {}) == ("solved in 1", 1) and pm.asked == [1]
    pm = _Stagnating(LOAD_SPLITS[-1] + 1)       # no split converges: the last one's error
    with pytest.raises(ConvergenceError, match=f"in {LOAD_SPLITS[-1]} steps"):
        solve_split(pm, {})
    assert pm.asked == list(LOAD_SPLITS)
