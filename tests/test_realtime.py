"""The real-time study: the largest mesh each model runs in real time (from the bench), its
errors there, the ranking with ties, and the quick run a preview."""
import json

import pytest

from cases.cli import main
from cases.studies.realtime import report as R


def _run(model, tets, factor, total, form=0.01, accuracy=True):
    return {"mesh": f"five-{tets}", "tets": tets, "bc": "clamped", "model": model,
            "realtime_factor": factor, "accuracy": accuracy, "failed": None,
            "disp_rel_l2": total, "disp_form_rel_l2": form, "load_steps": 1}


def test_the_reach_is_the_largest_size_measured_at_one_cpu_second_per_simulated_second():
    """A model's real-time reach is its run at the largest size whose real-time factor is at
    most 1; a model never measured, or never at real time, has none."""
    runs = [_run("msm", 320, 0.01, 0.3), _run("msm", 1080, 0.9, 0.25),
            _run("msm", 10985, 3.0, 0.2), _run("pbcm-corner", 320, 2.0, 0.08),
            _run("fem-linear", 320, None, 0.09)]
    got = R.reach(runs)
    assert got["msm"]["tets"] == 1080
    assert got["pbcm-corner"] is None and got["fem-linear"] is None


def test_the_most_accurate_model_at_real_time_is_ranked_by_its_error_bound_with_ties():
    """Models at their reach are ranked by their error bound (model-form error plus FEM P1's
    distance from the continuum on that mesh), never by a distance that cancels FEM P1's
    error; two bounds closer than u_val (the reference's estimate) share the first rank and
    both are named in the answer, with the machine; a model closer to the continuum than to
    FEM P1 by more than u_val is named as cancelling FEM P1's error."""
    data = {"runs": [_run("msm", 1080, 0.5, 0.30, 0.30),
                     _run("fem-neohookean", 1080, 0.3, 0.052, 0.0),
                     _run("fem-linear", 1080, 0.2, 0.054, 0.003),
                     _run("pbcm-corner", 1080, 0.6, 0.030, 0.09),
                     _run("fem-corotated", 10985, 0.9, 0.02, 0.012),
                     _run("fem-neohookean", 10985, 3.0, 0.018, 0.0)],
            "error_estimate": 0.005, "machine": {"cpu": "X", "cores": 2}}
    v = R.verdict(data)
    assert v["bounds"]["pbcm-corner"] == pytest.approx(0.142)
    assert v["bounds"]["fem-corotated"] == pytest.approx(0.030)
    assert v["best"] == ["fem-corotated"]
    assert v["cancels"] == ["pbcm-corner"]
    said = R.answer_line(data, v, quick=False)
    assert said.startswith("At real time on this machine (X, 2 cores, one used), the most "
                           "accurate model is fem-corotated, with 10985 tetrahedra, error bound "
                           "0.03")
    tied = {**data, "runs": data["runs"][:3]}
    v = R.verdict(tied)
    assert sorted(v["best"]) == ["fem-linear", "fem-neohookean"]
    assert "(tied within u_val)" in R.answer_line(tied, v, quick=False)
    assert R.answer_line(data, v, quick=True).startswith("Quick: not decided")


def test_no_model_measured_at_real_time_is_not_decided():
    """Without any model measured at real time (no bench, or every factor above 1) the
    answer is 'not decided' and says what to run."""
    data = {"runs": [_run("msm", 1080, None, 0.3)], "error_estimate": 0.005, "machine": None}
    v = R.verdict(data)
    assert not v["decided"]
    assert R.answer_line(data, v, quick=False).startswith("Not decided: no model was measured")


def test_the_quick_run_is_a_preview_with_every_size_and_no_ranking(tmp_path):
    """`pbcm run realtime --quick` writes metrics.json and a report that says 'quick: not
    decided' and ranks nothing; every run of its sizes has finite errors against FEM P1 (0
    for FEM P1 itself) and the continuum, and the implicit presets read their twin's."""
    out = tmp_path / "realtime"
    assert main(["run", "realtime", "--quick", "--out", str(out)]) == 0
    doc = json.loads((out / "metrics.json").read_text())
    md = (out / "report.md").read_text()
    assert "Quick: not decided" in md and "| rank |" not in md
    runs = {(r["model"], r["tets"]): r for r in doc["runs"]}
    assert {t for _, t in runs} == {320, 1080}
    for (m, t), r in runs.items():
        assert r["disp_rel_l2"] > 0 and r["disp_form_rel_l2"] >= 0, (m, t)
    assert runs[("fem-neohookean", 320)]["disp_form_rel_l2"] == 0
    twin = runs[("fem-corotated", 1080)]
    imp = runs[("fem-corotated-implicit-frame", 1080)]
    assert imp["disp_rel_l2"] == twin["disp_rel_l2"]
    assert {g["model"] for g in doc["gate_runs"]} == {m for m, _ in runs}
