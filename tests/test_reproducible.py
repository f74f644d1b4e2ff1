"""Reports that any machine reproduces: a value at round-off is printed as such and never
decides a tie or a rank; a blow-up is said by its time, not by the step a processor's
arithmetic reached the bound at."""
from cases.reporting.document import rel
from cases.measuring.error_model import ROUND_OFF, standings


def test_round_off_is_printed_as_such_and_ties():
    """Values below round-off print as '< 1e-09'; two models whose errors differ only there
    share a rank."""
    assert rel(3.5e-12) == rel(-2e-9) == f"< {ROUND_OFF:.0e}" == "< 1e-08"
    assert rel(0.0123) == "0.0123" and rel(None) == "n/a"
    (r1, a, _), (r2, b, tie) = standings({"a": [1e-12], "b": [5e-9]}, 0.0)
    assert r1 == r2 == 1 and tie == ("a",)


def test_a_blow_up_is_said_by_its_time_to_two_figures():
    """'blew up at step 12379 (t = 0.2731 s ...' and 'at step 12499 (t = 0.2734 s ...' (two
    processors) read the same."""
    from cases.library.narratives.paper_cube import _blowup
    a = _blowup("time integration blew up at step 12379 (t = 0.2731 s, dt = 2.2e-05 s): x")
    b = _blowup("time integration blew up at step 12499 (t = 0.2734 s, dt = 2.2e-05 s): x")
    assert a == b == "t = 0.27 s"
    assert _blowup(None) == "no"


def test_a_report_is_the_same_byte_for_byte_under_a_1e_15_perturbation(library, tmp_path,
                                                                       monkeypatch):
    """The quick self-weight report regenerated with every mesh coordinate perturbed by 1e-15
    (relative, the size of a processor's rounding) is byte for byte the committed-style one:
    no reference changes its refinement on a tie, no round-off is printed as a number."""
    import numpy as np
    import model.mesh as mesh_module
    from cases.cli import main
    box = mesh_module.box

    def jittered(*args, **kw):
        m = box(*args, **kw)
        noise = np.random.default_rng(1).standard_normal(m.points.shape)
        return type(m)(m.points * (1 + 1e-15 * noise), m.tets, lattice=m.lattice)
    monkeypatch.setattr(mesh_module, "box", jittered)
    out = tmp_path / "self-weight"
    assert main(["run", "self-weight", "--quick", "--workers", "1", "--no-cache",
                 "--out", str(out)]) == 0
    assert (out / "report.md").read_text() == (library / "self-weight" / "report.md").read_text()
