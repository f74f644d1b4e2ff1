"""A failed model is a row, never a crash: a run that cannot be built (a refused term, a failed
calibration) or whose metric is not finite leaves every report rendered, the case's other runs
and their gate rows intact, and the cause in the report."""
import json

import numpy as np
import pytest

from cases.cli import main
from cases.registry import CASES
from model.errors import ModelError

QUICK = ["--quick", "--meshes", "five", "--workers", "1"]


def _fail_build(monkeypatch, case, model, why):
    cls = type(CASES[case])
    built = cls.build_model

    def build(self, name, mesh, s):
        if name == model:
            raise ModelError(why)
        return built(self, name, mesh, s)
    monkeypatch.setattr(cls, "build_model", build)


@pytest.mark.parametrize("case", ["paper-cube", "cantilever"])
def test_a_model_that_cannot_be_built_is_a_row_with_its_cause(case, tmp_path, monkeypatch):
    """A calibration that fails for one model: the report renders, names the cause under the
    runs that could not start, and the other model's runs and gate rows are all there; a run
    of that model alone renders too."""
    why = "calibration of shear failed: c = 4.8e-09 (a negative deviatoric eigenvalue)"
    _fail_build(monkeypatch, case, "msm", why)
    out = tmp_path / "both"
    assert main(["run", case, *QUICK, "--models", "msm", "fem-linear", "--out", str(out)]) == 0
    data = json.loads((out / "metrics.json").read_text())
    failed = [r for r in data["runs"] if r["model"] == "msm"]
    assert failed and all(why in r["failed"] for r in failed)
    good = [r for r in data["runs"] if r["model"] == "fem-linear"]
    assert good and not any(r.get("failed") for r in good)
    assert all(m in r for r in good for m in data["gated"])      # its gate rows are whole
    md = (out / "report.md").read_text()
    assert "Runs that could not start" in md and why in md
    alone = tmp_path / "alone"
    assert main(["run", case, *QUICK, "--models", "msm", "--out", str(alone)]) == 0
    assert why in (alone / "report.md").read_text()


def test_a_non_finite_metric_fails_its_run_and_says_so(tmp_path, monkeypatch):
    """A quantity that comes out NaN fails that run's phase (its metrics n/a, the cause in
    the report), never a number in a report, and the case's other runs stand."""
    cls = type(CASES["cantilever"])
    measured = cls.quantities

    def quantities(self, mesh, u, reaction, s, bc):
        q = measured(self, mesh, u, reaction, s, bc)
        if not np.allclose(u, 0) and abs(q["tip_deflection_mm"]) > 0 and \
                getattr(self, "_poison", False):
            q["tip_deflection_mm"] = float("nan")
        return q
    monkeypatch.setattr(cls, "quantities", quantities)
    _fail_build(monkeypatch, "cantilever", "none", "unused")
    cls._poison = True
    try:
        out = tmp_path / "nan"
        assert main(["run", "cantilever", *QUICK, "--models", "msm", "--out", str(out)]) == 0
    finally:
        del cls._poison
    runs = json.loads((out / "metrics.json").read_text())["runs"]
    assert all(r["static_failed"] and "not finite" in r["static_failed"] for r in runs)
    md = (out / "report.md").read_text()
    # NaN only inside the stated cause, never as a number in a table or a sentence
    assert md.lower().count("nan") == md.count("not finite (nan)") > 0
    assert "No converged static solve in the linear regime for msm" in md
