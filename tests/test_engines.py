"""The engines study's verdicts on runs whose answers are known: where an iterative solver's
answer converges, where it matches FEM P1, the rows the gate reads, and a report without the
engines extra."""
import pytest

from cases.studies.engines import STUDY
from cases.studies.engines.report import convergence, findings, gate_rows
from cases.studies.engines.study import solver_of
from model.simulators.newton import spec

LADDER = {"newton-xpbd": (2, 8, 32), "newton-vbd": (10, 40)}


def row(model, value, mesh="five", case="paper-cube", regime="linear regime", failed=None,
        continuum=1.0, p1=1.0):
    solver, n = solver_of(model)
    return {"case": case, "regime": regime, "quantity": "reaction", "mesh": mesh, "bc": "clamped",
            "model": model, "solver": solver, "iterations": n, "value_rel": None if failed else value / abs(continuum),
            "estimate": 1e-4,
            "model_form": None if failed else (value - p1) / abs(continuum),
            "discretisation": (p1 - continuum) / abs(continuum),
            "total": None if failed else (value - continuum) / abs(continuum), "failed": failed}


def test_model_names_and_solvers_round_trip():
    """An engine model's name carries its iteration count; the default count is the plain
    name."""
    assert spec("newton-xpbd", 2) == "newton-xpbd"
    assert spec("newton-xpbd", 8) == "newton-xpbd(iterations=8)"
    assert solver_of("newton-xpbd(iterations=8)") == ("newton-xpbd", 8)
    assert solver_of("newton-vbd") == ("newton-vbd", 10)
    assert solver_of("newton-semi-implicit") == ("newton-semi-implicit", None)
    assert solver_of("fem-linear") == (None, None)


def test_convergence_is_the_count_from_which_the_answer_stays_within_one_percent():
    """Values 1.5, 1.105, 1.1 at 2, 8, 32 iterations: converged from 8 (within 1 % of its own
    answer at the top); 1.5, 1.2, 1.1: only at the top, not shown converged; a failed run at
    the top decides nothing."""
    data = {"runs": [row("newton-xpbd", 1.5), row("newton-xpbd(iterations=8)", 1.105),
                     row("newton-xpbd(iterations=32)", 1.1)]}
    assert convergence(data, "paper-cube", "linear regime", "newton-xpbd",
                       LADDER["newton-xpbd"]) == (8, None)
    data["runs"][1] = row("newton-xpbd(iterations=8)", 1.2)
    n, why = convergence(data, "paper-cube", "linear regime", "newton-xpbd",
                         LADDER["newton-xpbd"])
    assert n == 32 and "not shown converged" in why
    data["runs"][2] = row("newton-xpbd(iterations=32)", 1.0, failed="not at rest")
    assert convergence(data, "paper-cube", "linear regime", "newton-xpbd",
                       LADDER["newton-xpbd"])[0] is None


def test_a_solver_matches_fem_p1_where_its_model_form_error_is_within_five_percent_on_every_mesh():
    """At 10 iterations 0.03 on one mesh and 0.08 on the other: no match; at 40 iterations
    0.01 and 0.04 on both: a match at 40 only; the default's errors are reported with their
    failures counted."""
    data = {"runs": [row("newton-vbd", 1.03), row("newton-vbd", 1.08, mesh="six"),
                     row("newton-vbd(iterations=40)", 1.01),
                     row("newton-vbd(iterations=40)", 1.04, mesh="six")]}
    f = findings(data, {"newton-vbd": LADDER["newton-vbd"]})["newton-vbd"]["cases"]
    c = f["paper-cube/linear regime"]
    assert c["matches_p1_at"] == [40]
    assert c["model_form"] == pytest.approx([0.03, 0.08])
    assert c["converged_at"] == 40 and "not shown converged" in c["converged_why"]


def test_the_gate_reads_every_engine_run_by_case_bc_and_regime():
    """One gate row per engine run (not FEM P1's), keyed so that cases and regimes do not
    collide, holding |model-form error|, None for a failed run."""
    runs = [row("newton-vbd", 0.9), row("newton-vbd", 1.0, regime="at the load",
                                         failed="not at rest"), row("fem-linear", 1.0)]
    rows = gate_rows({"runs": runs})
    assert [(r["bc"], r["engine_error"]) for r in rows] == [
        ("paper-cube/clamped/linear regime", pytest.approx(0.1)),
        ("paper-cube/clamped/at the load", None)]


def test_without_the_engines_extra_the_report_says_so(tmp_path):
    """With no engine installed the study writes a report that says so, with a row per
    solver, and no gate rows."""
    import json
    s = STUDY.settings(quick=True)
    STUDY.write(tmp_path, s, {"installed": False, "engine": None, "runs": []})
    text = (tmp_path / "report.md").read_text()
    assert "not installed" in text and "newton-xpbd" in text
    assert json.loads((tmp_path / "metrics.json").read_text())["gate_runs"] == []


def test_the_quick_engines_run_is_a_preview_that_holds_its_gold(tmp_path, capsys):
    """`pbcm run engines --quick` runs the Newton engine's solvers on Warp's CPU backend on the
    bar, the cube and the cantilever beside FEM P1, says 'quick: not decided', gates one row
    per engine run and passes the committed quick gold."""
    pytest.importorskip("newton")
    import json
    from pathlib import Path
    from cases.cli import main
    out = tmp_path / "m" / "engines"
    assert main(["run", "engines", "--quick", "--out", str(out)]) == 0
    doc = json.loads((out / "metrics.json").read_text())
    assert "Quick: not decided" in (out / "report.md").read_text()
    assert doc["answer"].startswith("quick: not decided")
    engine_runs = [r for r in doc["runs"] if r["solver"]]
    assert len(doc["gate_runs"]) == len(engine_runs) > 0
    capsys.readouterr()
    gold = Path(__file__).resolve().parents[1] / "gold"
    assert main(["check", "--metrics", str(out.parent), "--gold", str(gold)]) == 0, \
        capsys.readouterr().out


def test_the_answer_names_per_case_the_solver_that_matches_fem_p1_and_from_which_count():
    """A solver within 0.05 of FEM P1 in both regimes of a case from 40 iterations on (not at
    10) is named there 'from 40 iterations'; a case where no solver matches reads 'none', with
    each solver's median model-form error there."""
    from cases.studies.engines.report import answer
    runs = []
    for regime in ("linear regime", "at the load"):
        runs += [row("newton-vbd", 1.2, regime=regime), row("newton-vbd(iterations=40)", 1.03,
                                                             regime=regime),
                 row("newton-semi-implicit", 1.3, regime=regime),
                 row("newton-xpbd", 1.0, regime=regime, failed="not at rest"),
                 row("newton-vbd", 1.3, regime=regime, case="cantilever"),
                 row("newton-vbd(iterations=40)", 1.3, regime=regime, case="cantilever")]
    ladder = {"newton-xpbd": (2,), "newton-vbd": (10, 40)}
    text = answer(findings({"runs": runs}, ladder), ladder, quick=False, installed=True)
    assert "the cube (paper-cube): newton-vbd from 40 iterations" in text
    assert "the cantilever (cantilever): none" in text
    # a miss is a number: each solver's median model-form error there at its defaults
    assert "the cantilever (cantilever): none (at their defaults, linear regime: newton-vbd " \
        "0.3)" in text


def test_convergence_is_relative_to_the_solvers_own_answer_not_the_continuums():
    """0.0108 and 0.01 of |Q_c| at the last two counts differ by 8 % of the solver's own answer:
    not converged there, although they differ by less than 1 % of |Q_c|."""
    data = {"runs": [row("newton-xpbd", 0.0108), row("newton-xpbd(iterations=8)", 0.0108),
                     row("newton-xpbd(iterations=32)", 0.01)]}
    n, why = convergence(data, "paper-cube", "linear regime", "newton-xpbd",
                         LADDER["newton-xpbd"])
    assert n == 32 and "not shown converged" in why


def _two_cases():
    runs = []
    for regime in ("linear regime", "at the load"):
        runs += [row("newton-vbd", 1.02, regime=regime),
                 row("newton-vbd(iterations=40)", 1.01, regime=regime),
                 row("newton-vbd", 1.3, regime=regime, case="cantilever"),
                 row("newton-vbd(iterations=40)", 1.04, regime=regime, case="cantilever"),
                 row("newton-xpbd", 1.0, regime=regime, failed="not at rest")]
    return runs


def test_the_pick_is_the_setting_matching_fem_p1_on_most_cases_then_the_cheapest():
    """newton-vbd at 10 iterations matches FEM P1 on the cube only, at 40 on the cube and the
    cantilever: 40 is picked, with its cost and whether that is real time; where 10 matched
    both too and cost less, 10 would be picked; nothing matching: nothing picked."""
    from cases.studies.engines.report import answer, pick
    ladder = {"newton-xpbd": (2,), "newton-vbd": (10, 40)}
    f = findings({"runs": _two_cases()}, ladder)
    costs = {"newton-vbd": {"wall_s_per_simulated_s": 1.7, "wall_range": [1.6, 1.8]},
             "newton-vbd(iterations=40)": {"wall_s_per_simulated_s": 6.3, "wall_range": [6, 7]}}
    assert pick(f, ladder, costs) == ("newton-vbd(iterations=40)", ["paper-cube", "cantilever"])
    text = answer(f, ladder, False, True, None, costs, "320 tetrahedra")
    assert text.startswith("pick newton-vbd(iterations=40)") and "not real time there" in text
    assert "; failed runs (not at rest), every setting: newton-xpbd 2 of 2. Within" in text
    base = {"wall_s_per_simulated_s": 0.0166, "wall_range": [0.0164, 0.0179]}
    assert ("not real time there, against fem-linear's 0.0166 [0.0164-0.0179] (double "
            "precision, pbcm's compiled kernels, serial: unlike treatment") in answer(f, ladder, False, True, None, costs,
                                                            "x", base)
    assert "not on the bar" in text
    runs = [r for r in _two_cases() if not (r["case"] == "cantilever"
                                            and r["model"] == "newton-vbd")]
    runs += [row("newton-vbd", 1.04, regime=rg, case="cantilever")
             for rg in ("linear regime", "at the load")]
    assert pick(findings({"runs": runs}, ladder), ladder, costs)[0] == "newton-vbd"
    none = [row("newton-vbd", 1.5), row("newton-vbd(iterations=40)", 1.5)]
    assert pick(findings({"runs": none}, ladder), ladder, costs) is None
    # FEM P1's distance from the continuum is said unsigned, as the scorecard reads it, with
    # the u_val it is read against
    soft = [dict(r, discretisation=-0.27, u_num=0.003) if r["case"] == "cantilever" else r
            for r in _two_cases()]
    text = answer(findings({"runs": soft}, ladder), ladder, False, True, None, costs, "x")
    assert ("so within 0.05 of FEM P1's own distance from the continuum on those 2 quick "
            "meshes (|Q_P1 - Q_c| / |Q_c|, the median over the meshes: the cube 0 (u_val 0), "
            "the cantilever 0.27 (u_val 0.003), linear regime)") in text


def test_failed_runs_lead_and_are_counted_against_their_solver():
    """A solver with failed runs is named first with how many of its runs failed and where
    every setting failed; without failures there is no such line."""
    from cases.studies.engines.report import failures_line
    ladder = {"newton-xpbd": (2,), "newton-vbd": (10, 40)}
    line = failures_line(findings({"runs": _two_cases()}, ladder))
    assert line.startswith("**Failed runs**") and "newton-xpbd 2 of 2" in line
    assert "the cube, linear regime" in line and "newton-vbd" not in line
    ok = [r for r in _two_cases() if not r["failed"]]
    assert failures_line(findings({"runs": ok}, ladder)) is None


def test_a_distance_below_fem_p1s_own_and_of_the_other_sign_is_cancellation_per_mesh():
    """On each mesh a solver's distance from the continuum smaller than FEM P1's and of the
    other sign is cancellation (-0.06 against 0.209); the same sign, or a larger distance, is
    not; a failed run is not counted."""
    from cases.studies.engines.report import _cancellation
    c = {"total": [-0.06, 0.15], "discretisation": [0.209, 0.2]}
    assert _cancellation(c) == "; cancellation on 1 of 2 meshes"
    assert _cancellation({**c, "total": [0.15, 0.3]}) == ""
    assert _cancellation({**c, "total": [None, 0.15]}) == ""


def test_the_scorecard_rows_band_each_solver_by_its_worst_mesh_and_count_failures():
    """The index's scorecard gets a row per case and regime with each solver at its
    defaults: within 0.05 of FEM P1 on every mesh band 0, within 0.2 band 1, beyond or a
    failed run band 2; a quick run adds no rows."""
    from cases.studies.engines.report import scorecard
    ladder = {"newton-xpbd": (2,), "newton-vbd": (10, 40)}
    doc = {"installed": True, "parameters": {"quick": False, "meshes": ["five"]},
           "findings": findings({"runs": _two_cases()}, ladder)}
    got = scorecard(doc)
    rows = {label.split(" (")[0]: cells for label, _, cells, _ in got}
    assert all(len(shared) == 2 for *_, shared in got)     # FEM P1 vs continuum, u_val
    assert rows["paper-cube/clamped"]["newton-vbd"][1] == 0
    assert rows["cantilever/clamped"]["newton-vbd"][1] == 2
    assert rows["paper-cube/clamped"]["newton-xpbd"] == ("failed, 0 of 1", 2)
    assert scorecard({**doc, "parameters": {"quick": True, "meshes": ["five"]}}) == []


def test_the_scorecard_marks_the_engines_shared_cells_as_the_studys_own():
    """The engines rows share the cases' columns 'FEM P1 vs continuum' and 'u_val' but hold
    signed values on the study's own quick meshes: each such cell says so (FEM P1 at 1.2 of
    a continuum of 1 on two meshes: 0.2, signed), the metric says its values are signed, and
    the label gives the meshes' sizes where the record holds them."""
    from cases.studies.engines.report import scorecard
    ladder = {"newton-xpbd": (2,), "newton-vbd": (10, 40)}
    runs = [dict(r, u_num=0.003) for m in ("five", "six")
            for r in (row("newton-vbd", 1.21, mesh=m, p1=1.2),
                      row("newton-vbd(iterations=40)", 1.2, mesh=m, p1=1.2))]
    doc = {"installed": True, "parameters": {"quick": False, "meshes": ["five", "six"]},
           "findings": findings({"runs": runs}, ladder),
           "mesh_tets": {"paper-cube": {"five": 320, "six": 384}}}
    (label, metric, _, (p1, u)), = scorecard(doc)
    assert label == ("paper-cube/clamped (engines study, the case's quick meshes five/six, "
                     "320/384 tetrahedra, and references)")
    assert metric == "model-form vs FEM P1 at the engine's defaults, signed"
    assert p1 == "0.2 [0.2 to 0.2], 2 of 2 (engines study, 2 quick meshes, signed)"
    assert u == "0.003 (of FEM P1's distance; engines study, 2 quick meshes)"


def test_the_engines_meshes_are_the_cases_quick_meshes_of_known_size():
    """The study's meshes are the cases' quick meshes, built by each case's own builder from
    the recorded problem: the bar and the cube 4 lattice cells a side (64 cells: 5 and 6
    tetrahedra a cell on the splits five and six, 320 and 384), the cantilever 16 by 4 by 4
    cells (256: 1280 and 1536); the answer and the report say them where they say 'quick
    meshes'."""
    from cases.studies.engines.report import sizes_text
    from cases.studies.engines.study import EngineSettings, mesh_sizes
    tets = mesh_sizes(EngineSettings())
    assert tets == {"self-weight": {"five": 320, "six": 384},
                    "paper-cube": {"five": 320, "six": 384},
                    "cantilever": {"five": 1280, "six": 1536}}
    assert mesh_sizes(EngineSettings(quick=True))["cantilever"] == {"five": 1280}
    assert sizes_text(tets, ["paper-cube", "cantilever"]) == \
        "the cube's 320 and 384 tetrahedra, the cantilever's 1280 and 1536"
    assert sizes_text({}, ["paper-cube"]) == ""


def test_a_redrawn_engines_report_says_its_meshes_sizes(tmp_path, capsys):
    """Drawn again from the committed record (nothing computed), the engines report records
    the sizes of the meshes it ran on and says them where it says 'quick meshes'."""
    import json
    import shutil
    from pathlib import Path
    from cases.cli import main
    reports = Path(__file__).resolve().parents[1] / "reports" / "engines"
    out = tmp_path / "engines"
    out.mkdir()
    shutil.copy(reports / "metrics.json", out / "metrics.json")
    assert main(["run", "engines", "--rewrite", "--out", str(out)]) == 0
    doc = json.loads((out / "metrics.json").read_text())
    assert doc["mesh_tets"]["cantilever"] == {"five": 1280, "six": 1536}
    assert "the cases' quick meshes, split 'five' and 'six' (two splits of one lattice size, " \
        "the quick run 'five' only; here the bar's 320 and 384 tetrahedra, the cube's 320 " \
        "and 384, the cantilever's 1280 and 1536)" in (out / "report.md").read_text()


def test_a_pick_not_converged_in_iterations_is_provisional_in_the_pick_itself():
    """newton-vbd matches FEM P1 on the cube and the cantilever from 40 iterations, but on the
    cantilever its answer at 40 (1.04) is not within 1 % of its answer at the ladder's top
    (1.0 at 160): the pick itself says it is provisional, and why; where 40 is converged
    (1.0 at 40 and 160) the pick is still provisional for its quick meshes alone, with no
    word of iterations. The quick meshes' sizes are said beside FEM P1's distance."""
    from cases.studies.engines.report import answer
    ladder = {"newton-xpbd": (2,), "newton-vbd": (10, 40, 160)}

    def runs(at40):
        out = []
        for regime in ("linear regime", "at the load"):
            out += [row("newton-vbd", 1.02, regime=regime),
                    row("newton-vbd(iterations=40)", 1.01, regime=regime),
                    row("newton-vbd(iterations=160)", 1.01, regime=regime),
                    row("newton-vbd", 1.3, regime=regime, case="cantilever"),
                    row("newton-vbd(iterations=40)", at40, regime=regime, case="cantilever"),
                    row("newton-vbd(iterations=160)", 1.0, regime=regime, case="cantilever")]
        return out
    tets = {"paper-cube": {"five": 320}, "cantilever": {"five": 1280}}
    text = answer(findings({"runs": runs(1.04)}, ladder), ladder, False, True, tets=tets)
    assert text.startswith(
        "pick newton-vbd(iterations=40), provisional (judged on the cases' quick meshes and "
        "quick references only: no run on their full meshes decides it; not converged in "
        "iterations at 40: not within 1% of its answer at the ladder's top on the cantilever, "
        "linear regime; the cantilever, at the load) (the setting within 0.05 of FEM P1")
    assert "not shown converged" not in text
    assert "on those 2 quick meshes (the cube's 320 tetrahedra, the cantilever's 1280; " \
        "|Q_P1 - Q_c| / |Q_c|" in text
    plain = answer(findings({"runs": runs(1.0)}, ladder), ladder, False, True)
    assert plain.startswith("pick newton-vbd(iterations=40), provisional (judged on the cases' "
                            "quick meshes and quick references only: no run on their full "
                            "meshes decides it) (the setting within 0.05")
    assert "not converged" not in plain


def test_the_dynamic_push_counts_failures_and_says_where_float32_cannot_resolve_rest():
    """The dynamic push's line gives each solver's median reaction error over the meshes with
    a failed run reading 'failed'; the table's note states the rest speed and the smallest
    speed a float32 position resolves over the engine's step."""
    from cases.studies.engines.report import _float32_speeds, dynamic_line, dynamic_summary
    base = {"case": "paper-cube", "element": "P1", "rest_speed_m_s": 1.7e-6, "dt_s": 1e-3,
            "disp_end_push_rel_l2": 0.01, "at_rest": False}
    dyn = [{**base, "mesh": "five", "model": "newton-vbd", "solver": "newton-vbd",
            "reaction_time_rel_l2": 0.05, "failed": None, "float32_speed_m_s": 3.8e-6},
           {**base, "mesh": "six", "model": "newton-vbd", "solver": "newton-vbd",
            "reaction_time_rel_l2": 0.07, "failed": None, "float32_speed_m_s": 3.8e-6},
           {**base, "mesh": "five", "model": "newton-xpbd", "solver": "newton-xpbd",
            "reaction_time_rel_l2": None, "failed": "blew up", "float32_speed_m_s": 7e-6},
           {**base, "mesh": "five", "model": "fem-linear", "solver": None,
            "reaction_time_rel_l2": 0.001, "failed": None, "float32_speed_m_s": None,
            "at_rest": True}]
    line = dynamic_line(dyn)
    assert "newton-vbd 0.06" in line and "newton-xpbd failed" in line and "fem-linear 0.001" in line
    got = dynamic_summary(dyn)
    assert got["newton-xpbd"]["failed"] == ["blew up"] and got["fem-linear"]["at_rest"] == 1
    assert _float32_speeds(dyn) == "3.8e-06 to 7e-06 m/s"
    assert dynamic_line([]) is None
    # against a linear transient, a solver at most 1.1 times the share finite strain adds
    # (FEM P1 with the continuum's law) is not resolved from it; one beyond is
    nh = {**dyn[3], "model": "fem-neohookean", "reaction_time_rel_l2": 0.058}
    line = dynamic_line(dyn + [nh])
    assert "newton-vbd 0.06 (not resolved from the finite-strain share)" in line
    nh["reaction_time_rel_l2"] = 0.05
    assert "not resolved" not in dynamic_line(dyn + [nh])


def test_a_redrawn_report_reads_its_costs_from_the_checkouts_bench(monkeypatch):
    """Drawn again from its record, the engines report takes each engine's cost from the
    checkout's bench (as every other report's cost), not the one recorded by its run."""
    from cases.reporting import costs as bench_costs
    from cases.studies.engines.study import EngineSettings
    s = EngineSettings(quick=True)
    model = s.models()[0]
    tets = bench_costs.sizes(True)[0]
    row = {"model": model, "tets": tets, "timed": True, "wall_s_per_simulated_s": 0.5}
    monkeypatch.setattr(bench_costs, "load", lambda *a: {
        "realtime_rows": [row], "realtime_machine": {"cpu": "X", "cores": 2}})
    got = STUDY.redrawn(s, {"costs": {model: None}, "machine": None}, {})
    assert got["costs"][model] == row and got["machine"] == {"cpu": "X", "cores": 2}
    monkeypatch.setattr(bench_costs, "load", lambda *a: None)
    assert STUDY.redrawn(s, {"costs": {model: None}}, {})["costs"] == {model: None}


def test_the_index_names_where_its_numbers_come_from(tmp_path):
    """The index's studies table says the engines study's full run is on the cases' quick
    meshes (its own meshes, named), never a bare 'full' beside studies that run finer; the
    costs name the bench cube, the time they read and the machine."""
    from pathlib import Path

    from cases.cli import main
    from cases.library.common import bench_mesh
    from cases.registry import CASES
    from cases.reporting.costs import COST_TETS
    from cases.studies.engines.study import MESHES
    reports = Path(__file__).resolve().parents[1] / "reports"
    for name in (*CASES, "engines", "bench"):
        (tmp_path / name).symlink_to(reports / name, target_is_directory=True)
    assert main(["index", "--out", str(tmp_path)]) == 0
    row = next(line for line in (tmp_path / "index.md").read_text().splitlines()
               if line.startswith("| [engines](engines/report.md) |"))
    assert row.endswith(f"| full, on the cases' quick meshes ({', '.join(MESHES)}) |")
    import json
    machine = json.loads((reports / "bench" / "bench.json").read_text())["machine"]
    at_cost = (tmp_path / "index.md").read_text().split("**At what cost?**")[1].split("\n")[0]
    assert f"in serial CPU time on {machine['cpu']} (one of its {machine['cores']} cores" \
        in at_cost
    cost = (tmp_path / "index.md").read_text().split("- Cost at a stated accuracy")[1]
    assert "CPU s per simulated s on the bench's machine (serial CPU time at its own stable RK4 " \
        f"step on the bench's {bench_mesh(COST_TETS).n_tets}-tetrahedron cube" \
        in cost.split("\n")[0]
