"""The artefact study: the signature's classifier, the three hypotheses and the reading
verdict (computed on cells written here, whose answer is known), and the quick study against
its gold with the controls that must hold whatever the models do."""
import pytest
import json
from pathlib import Path


import numpy as np

from cases.studies.artefact import analysis
from cases.studies.artefact.study import SPLITS

ROOT = Path(__file__).resolve().parents[1]


FIVE, SIX, BCC, UNMIRRORED = (SPLITS[k] for k in ("five", "six", "bcc", "five-unmirrored"))


def cell(mesh, split, model, alt, bc="sliding", load="paper", n=5, family="particle",
         reading="balanced", constant="calibrated", normal="none", **kw):
    return {"mesh": mesh, "split": split, "nodes_per_side": n, "model": model, "bc": bc,
            "load": load, "family": family, "reading": reading, "constant": constant,
            "normal": normal, "alternation_rel": alt, "failed": None, **kw}


def test_the_pattern_has_the_papers_sign_and_a_clear_level():
    """+ is the paper's sign, clear from ALTERNATION_CLEAR; undefined or failed is None."""
    assert analysis.pattern(cell("five", FIVE, "m", 0.02)) == "paper"
    assert analysis.pattern(cell("five", FIVE, "m", -0.02)) == "reversed"
    assert analysis.pattern(cell("five", FIVE, "m", 0.009)) == "none"
    assert analysis.pattern(cell("five", FIVE, "m", None)) is None
    assert analysis.pattern(cell("five", FIVE, "m", 0.5, failed="no")) is None


MODELS = (("b", "none", "particle", "calibrated"), ("b+n", "normal_edge", "particle",
                                                    "calibrated"),
          ("msm", "edges", "msm", "springs"), ("fem-linear", "fem", "fem", "none"))


def _world(signature, patch=lambda model, split, n: 0.01):
    """Cells of every split at 5, 9 and 17 nodes per side, both bases, of a reading without
    and with a normal term, msm and the control, with ``signature(model, split, n, bc)`` at
    the paper's push and ``patch`` the sliding patch-test error (linear load, below 17)."""
    out = []
    for kind, split in SPLITS.items():
        for n in (5, 9, 17):
            mesh = kind if n == 5 else f"{kind}-{n}"
            for model, normal, family, constant in MODELS:
                f = dict(normal=normal, family=family, constant=constant, n=n,
                         reading="none" if family != "particle" else "balanced")
                for bc in ("sliding", "clamped"):
                    out.append(cell(mesh, split, model, signature(model, split, n, bc), bc=bc,
                                    **f))
                if n < 17:
                    out.append(cell(mesh, split, model, signature(model, split, n, "sliding"),
                                    load="linear", disp_rel_l2=patch(model, split, n), **f))
    return out


def _mirror_world(model, split, n, bc):
    if model == "fem-linear":
        return 0.0
    if split != FIVE:
        return 0.001
    return (0.33 if model == "msm" else 0.32) / n        # halves with h on the mirror only


def test_the_mirror_holds_where_only_the_mirrored_split_alternates():
    """A signature on the mirrored five split only, from 9 layers, halving with h, FEM P1
    clean: hypothesis (a) holds in every (size, base) unit, the models' own; a term that
    changes nothing (b+n, the same signature as b) is one observation with b."""
    a = analysis.answer(_world(_mirror_world))
    m = a["hypotheses"]["mirror"]
    assert [(u["n"], u["bc"], u["classes"]["own"]) for u in m["units"]] == [
        (9, "clamped", ["b", "msm"]), (9, "sliding", ["b", "msm"]),
        (17, "clamped", ["b", "msm"]), (17, "sliding", ["b", "msm"])]
    assert m["holds"] and m["order_median"] == pytest.approx(np.log2(17 / 9))
    assert a["cause"].startswith("the mirror symmetry of the five split, and beyond it the "
                                 "model's own in b, msm")
    assert "a view, not a verdict" in a["text"]


def test_a_signature_fem_p1_shares_is_the_meshs_not_the_models():
    """Where FEM P1 on the mirrored split has the same signature as the models, they are
    'shared' (the mesh's own period-2 error), never the models' own."""
    def world(model, split, n, bc):
        return 0.32 / n if split == FIVE else 0.001
    m = analysis.answer(_world(world))["hypotheses"]["mirror"]
    assert all(u["classes"]["own"] == [] and u["classes"]["shared"] for u in m["units"])


def test_normal_stress_holds_where_each_term_removes_the_models_own_signature():
    """A model's own signature on the mirrored split gone with a normal term: (b) holds;
    where no model has its own signature, (b) is not decided."""
    def world(model, split, n, bc):
        return 0.03 if model == "b" and split == FIVE else 0.0
    a = analysis.answer(_world(world))
    ns = a["hypotheses"]["normal_stress"]
    assert ns["decided"] and ns["holds"] and ns["removed"] == ns["pairs"] == 4
    assert "the missing normal stress adds to it" in a["cause"]
    none = analysis.answer(_world(lambda model, split, n, bc: 0.03 if model == "b" else 0.0))
    assert not none["hypotheses"]["normal_stress"]["decided"]
    assert "(b) Missing normal stress: not decided" in none["text"]


def test_consistency_holds_where_the_signature_tracks_the_patch_error():
    """Signatures ordered as the patch-test errors on every conforming mesh: rank
    correlation 1; reversed: -1, and the hypothesis does not hold."""
    sig = {"b": 0.03, "b+n": 0.02, "msm": 0.01, "fem-linear": 0.0}
    world = _world(lambda model, split, n, bc: sig[model],
                   patch=lambda model, split, n: sig[model] / 3)
    cs = analysis.answer(world)["hypotheses"]["consistency"]
    assert cs["holds"] and all(r["rho"] == pytest.approx(1.0) for r in cs["rows"])
    assert {r["mesh"] for r in cs["rows"]} == {"five-9", "six-9", "bcc-9"}  # conforming, linear
    world = _world(lambda model, split, n, bc: sig[model],
                   patch=lambda model, split, n: 1 / (1 + sig[model]))
    assert not analysis.answer(world)["hypotheses"]["consistency"]["holds"]


def test_five_layers_alone_decide_nothing():
    """Without a mesh of 9 or more layers the answer is 'not decided', whatever the 5-layer
    view shows."""
    world = [c for c in _world(_mirror_world) if c["nodes_per_side"] == 5]
    a = analysis.answer(world)
    assert not a["decided"] and a["text"].startswith("Not decided")


def test_the_reading_verdict_says_plainly_when_none_reproduces_the_paper():
    """Each reading's decidable observables on the paper's lattice (the 5-layer pattern
    shown, not scored); where none matches all, the verdict says so and names what each
    lacks, and the damping the flutter criterion assumes."""
    def rows(model, alt, rate):
        return [cell("five", FIVE, model, alt, disp_rel_l2=0.1),
                cell("five", FIVE, model, None, bc="clamped", growth_rate_1_s=rate,
                     flutter=rate > 25, disp_rel_l2=0.2),
                cell("five", FIVE, model, alt, load="linear", disp_rel_l2=0.05)]
    cells = rows("a", 0.02, 0.0) + rows("b", 0.0, 90.0)
    table = analysis.reading_table(cells, {"a": 8.0, "b": 8.0}, ["a", "b"])
    assert [r["score"] for r in table] == [1, 0]       # the 5-layer pattern is not scored
    assert table[0]["pattern"] == [1, 1]
    v = analysis.reading_verdict(table, 50.0)
    assert v["none_reproduces"] and v["text"].startswith(
        "No reading reproduces all the paper's observables: a lacks a step over 10 times "
        "msm's; b lacks")
    assert (v["model"], v["sure"]) == ("a", "weak") and "50 1/s (the paper states none)" \
        in v["text"] and "not scored" in v["text"]
    # where the FEM control alternates on the paper's lattice, no model's pattern is resolved
    fem = cell("five", FIVE, "fem-linear", -0.02, family="fem")
    blind = analysis.reading_table(cells + [fem], {"a": 12.0, "b": 8.0}, ["a", "b"])
    assert blind[0]["pattern"] == [0, 0]


def test_the_quick_study_holds_its_gold_and_its_controls(quick_artefact, capsys):
    """The quick study matches its gold; whatever the models do, the FEM control on a
    conforming mesh never alternates and passes the sliding patch test, on the
    non-conforming unmirrored five split it fails it, msm on the mirrored five split shows
    the paper's sign pattern, and the quick report says it decides nothing."""
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
    assert "**Quick: not decided**" in md
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
