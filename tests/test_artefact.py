"""The artefact study: the pattern classifier, the factor contrasts and the two answers
(computed on cells written here, whose answer is known), and the quick study against its
gold with the controls that must hold whatever the models do."""
import pytest
import json
from pathlib import Path


from cases.studies.artefact import analysis

ROOT = Path(__file__).resolve().parents[1]


def cell(mesh, split, model, alt, bc="sliding", load="paper", n=5, family="particle",
         reading="balanced", constant="calibrated", normal="none", **kw):
    return {"mesh": mesh, "split": split, "nodes_per_side": n, "model": model, "bc": bc,
            "load": load, "family": family, "reading": reading, "constant": constant,
            "normal": normal, "alternation_rel": alt, "failed": None, "paper_size": False, **kw}


def test_the_pattern_has_the_papers_sign_and_a_clear_level():
    assert analysis.pattern(cell("five", "mirrored five", "m", 0.02)) == "paper"
    assert analysis.pattern(cell("five", "mirrored five", "m", -0.02)) == "reversed"
    assert analysis.pattern(cell("five", "mirrored five", "m", 0.009)) == "none"
    assert analysis.pattern(cell("five", "mirrored five", "m", None)) is None
    assert analysis.pattern(cell("five", "mirrored five", "m", 0.5, failed="no")) is None


def _world(alternates):
    """Cells on the five and six splits of a model without and with a normal term and msm,
    alternating where ``alternates(split, normal, family)`` says so."""
    out = []
    for mesh, split in (("five", "mirrored five"), ("six", "six (Kuhn)")):
        for model, normal, family in (("b", "none", "particle"),
                                      ("b+n", "normal_edge", "particle"),
                                      ("msm", "edges", "msm")):
            alt = 0.03 if alternates(split, normal, family) else 0.001
            out.append(cell(mesh, split, model, alt, normal=normal, family=family,
                            reading="none" if family == "msm" else "balanced",
                            constant="springs" if family == "msm" else "calibrated"))
    return out


def test_contrasts_count_pairs_that_differ_in_one_factor_only():
    world = _world(lambda split, normal, family: split == "mirrored five")
    rows = {(c["factor"], c["to"]): c for c in analysis.contrasts(world)}
    split = rows[("split", "six (Kuhn)")]
    # three models, each a pair five -> six: all three alternate on five, none on six
    assert (split["pairs"], split["with_pattern_before"], split["switched_off"],
            split["switched_on"]) == (3, 3, 3, 0)
    normal = rows[("normal", "normal_edge")]
    assert (normal["pairs"], normal["with_pattern_before"], normal["switched_off"]) == (2, 1, 0)


def test_the_answer_names_the_mirror_when_only_the_mesh_switches_the_pattern():
    a = analysis.answer(_world(lambda split, normal, family: split == "mirrored five"))
    assert a["cause"].startswith("the mirror symmetry of the five split")
    assert a["mesh_off_rate"] == 1.0 and a["normal_off_rate"] == 0.0
    assert a["five"] == [3, 3] and a["other_splits"] == [0, 3]


def test_the_answer_names_normal_stress_when_a_normal_term_removes_it_everywhere():
    a = analysis.answer(_world(lambda split, normal, family: normal == "none"))
    assert a["cause"].startswith("the missing normal stress")
    assert a["normal_off_rate"] == 1.0 and a["mesh_off_rate"] == 0.0


def test_the_answer_names_neither_when_the_pattern_is_everywhere_and_refinement_removes_it():
    world = _world(lambda split, normal, family: True)
    world += [cell("five-9", "mirrored five", "b", 0.001, n=9)]
    a = analysis.answer(world)
    assert a["cause"] == ("neither the mirror symmetry nor the missing normal stress: a "
                          "mesh-scale discretisation error that refinement removes")
    assert a["refined"] == {"5": [3, 3], "9": [0, 1]}


def test_the_reading_verdict_counts_the_papers_observables_and_its_margin():
    def rows(model, alt, rate):
        return [cell("d", "Delaunay-374", model, alt, paper_size=True, disp_rel_l2=0.1),
                cell("d", "Delaunay-374", model, None, bc="clamped", paper_size=True,
                     growth_rate_1_s=rate, flutter=rate > 25, disp_rel_l2=0.2),
                cell("d", "Delaunay-374", model, alt, load="linear", paper_size=True,
                     disp_rel_l2=0.05)]
    cells = rows("a", 0.02, 0.0) + rows("b", 0.0, 90.0)
    table = analysis.reading_table(cells, {"a": 12.0, "b": 8.0}, ["a", "b"])
    assert [r["score"] for r in table] == [3, 0]
    v = analysis.reading_verdict(table)
    assert (v["model"], v["sure"], v["margin"]) == ("a", "clear", 3)
    assert table[0]["sliding_disp_median"] == 0.05 and table[1]["flutter"] == [1, 1]
    # on a mesh where the FEM control alternates too, a model's pattern is not resolved
    fem = cell("d", "Delaunay-374", "fem-linear", -0.02, family="fem", paper_size=True)
    blind = analysis.reading_table(cells + [fem], {"a": 12.0, "b": 8.0}, ["a", "b"])
    assert blind[0]["pattern"] == [0, 0] and blind[0]["score"] == 2
    tie = analysis.reading_verdict(analysis.reading_table(cells, {"a": 8.0, "b": 12.0},
                                                          ["a", "b"]))
    assert tie["sure"] == "weak" and tie["model"] == "a"     # pattern and stability: 2 to 1


def test_the_quick_study_holds_its_gold_and_its_controls(quick_artefact, capsys):
    from cases.cli import main
    status = main(["check", "--metrics", str(quick_artefact.parent), "--gold",
                   str(ROOT / "gold"), "--allow-new"])
    assert status == 0, capsys.readouterr().out
    doc = json.loads((quick_artefact / "metrics.json").read_text())
    cells = doc["cells"]
    # the control: constant-strain FEM on a conforming mesh never alternates, and on the
    # sliding base (a homogeneous answer it reproduces) has no alternation at all
    fem = [c for c in cells if c["model"] == "fem-linear" and c["mesh"] != "delaunay374-7"
           and c["alternation_rel"] is not None]
    assert fem and not any(analysis.alternating(c) for c in fem)
    assert max(abs(c["alternation_rel"]) for c in fem if c["bc"] == "sliding") < 1e-6
    # ... and passes the sliding patch test in the linear regime
    assert max(c["disp_rel_l2"] for c in cells if c["model"] == "fem-linear"
               and c["bc"] == "sliding" and c["load"] == "linear"
               and c["mesh"] != "delaunay374-7") < 1e-8
    # the non-conforming reconstruction fails it even for FEM (its cells do not match)
    dl = next(c for c in cells if c["model"] == "fem-linear" and c["mesh"] == "delaunay374-7"
              and c["bc"] == "sliding" and c["load"] == "linear")
    assert dl["disp_rel_l2"] > 1e-3 and dl["unmatched_faces"] > 0
    # msm on the mirrored five split: the paper's pattern, ends and middle out
    msm = next(c for c in cells if c["model"] == "msm" and c["mesh"] == "five"
               and c["bc"] == "sliding" and c["load"] == "paper")
    p = msm["bulge_profile_mm"]
    assert p[0] > p[1] < p[2] > p[3] < p[4] and msm["alternation_rel"] > 0.01
    # the sliding reference is a homogeneous compression: every layer expands alike
    ref = msm["bulge_profile_fem_mm"]
    assert max(ref) - min(ref) < 1e-9 * max(ref)
    md = (quick_artefact / "report.md").read_text()
    assert doc["answer"]["text"] in md and doc["verdict"]["text"] in md
    assert (quick_artefact / "cells.md").is_file()


class _Stagnating:
    """A model whose Newton converges only with ``needs`` or more load steps."""

    def __init__(self, needs):
        self.needs, self.asked = needs, []

    def solve_static(self, bc, rtol, load_steps):
        from model.errors import ConvergenceError
        self.asked.append(load_steps)
        if load_steps < self.needs:
            raise ConvergenceError(f"stagnated in {load_steps} steps")
        return f"solved in {load_steps}"


def test_a_cell_splits_the_load_where_newton_from_rest_stagnates():
    from cases.studies.artefact.study import LOAD_SPLITS, solve_split
    from model.errors import ConvergenceError
    pm = _Stagnating(2)
    assert solve_split(pm, {}) == ("solved in 2", 2) and pm.asked == [1, 2]
    pm = _Stagnating(1)
    assert solve_split(pm, {}) == ("solved in 1", 1) and pm.asked == [1]
    pm = _Stagnating(LOAD_SPLITS[-1] + 1)       # no split converges: the last one's error
    with pytest.raises(ConvergenceError, match=f"in {LOAD_SPLITS[-1]} steps"):
        solve_split(pm, {})
    assert pm.asked == list(LOAD_SPLITS)
