"""The README's "Adding a case" example, run as written: a new case is a module and a
registry entry, and the shared runner gives it every standard metric."""
import re
import types
from pathlib import Path

import pytest

README = Path(__file__).resolve().parents[1] / "README.md"


def test_readme_worked_example_case_runs_and_matches_uniaxial_stretch(tmp_path):
    """The README's 'Adding a case' code, run as written, defines a case whose quick runs of pbcm-
    variational and msm all succeed, whose FEM stretch is the uniaxial closed form (stress over E
    times 32 mm), whose stretch errors are |stretch / FEM stretch - 1|, and whose report is
    written."""
    text = README.read_text().split("### Adding a case")[1]
    code = re.search(r"```python\n(.*?)```", text, re.S).group(1)
    module = types.ModuleType("plate")
    exec(compile(code, "README.md", "exec"), module.__dict__)
    case = module.CASE
    from cases.reporting.report import write_case
    from cases.running.runner import run
    s = case.settings(quick=True, models=("pbcm-variational", "msm"))
    runs, fields = run(case, s, log=False)
    assert all(r["failed"] is None and r["static_failed"] is None for r in runs)
    # uniaxial stress sigma / E over 32 mm: the FEM stretch is the closed form (by hand)
    fem = runs[0]["stretch_fem_mm"]
    assert fem == pytest.approx(100.0 / 10e3 * 32.0, rel=1e-6)
    for r in runs:
        assert r["stretch_rel_err"] == pytest.approx(abs(r["stretch_mm"] / fem - 1))
    write_case(tmp_path, case, s, runs, fields)
    assert (tmp_path / "report.md").is_file()
