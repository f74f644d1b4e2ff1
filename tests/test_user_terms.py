"""User terms and composed models: a term file outside the package, the entry-point
group, the composition grammar, and the worked example of docs/example_term.py."""
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import model.terms
from cases.cli import main
from model import build
from model.compose import label, parse
from model.errors import ModelError

from conftest import perturbed, rotation

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "docs" / "example_term.py"
COMPOSED = "shear(reading=variational, c=auto) + normal_axis(c=auto) + volume"


@pytest.fixture(scope="module")
def example():
    saved = os.environ.get("PBCM_TERMS")
    model.terms.add_user_file(EXAMPLE)
    yield model.terms.TERMS["normal_axis"]
    if saved is None:
        os.environ.pop("PBCM_TERMS", None)
    else:
        os.environ["PBCM_TERMS"] = saved


def test_example_term_is_a_conservative_momentum_conserving_term(example, small_mesh, mat):
    """The example user term's forces equal its NumPy forces and minus the central finite-difference
    gradient of its energy, and sum to zero over the nodes; being a small-strain term, it exerts
    forces under a finite rotation of the rest shape."""
    t = example(small_mesh, mat, c=0.4)
    x = perturbed(small_mesh, 0.05, seed=4)
    f = t.forces(x)
    assert np.allclose(f, t.forces_numpy(x), rtol=0, atol=1e-12 * np.abs(f).max())
    h, g = 1e-7, np.zeros_like(x)
    for i in range(x.shape[0]):
        for k in range(3):
            xp, xm = x.copy(), x.copy()
            xp[i, k] += h
            xm[i, k] -= h
            g[i, k] = (t.energy(xp) - t.energy(xm)) / (2 * h)
    assert np.abs(f + g).max() <= 1e-6 * np.abs(f).max()
    assert np.linalg.norm(f.sum(axis=0)) <= 1e-10 * np.abs(f).sum()
    # small strain: a finite rotation of the rest shape is strained (what co-rotation fixes)
    R = rotation([0, 0, 1], 0.5)
    assert np.abs(t.forces(small_mesh.points @ R.T)).max() > 1e-3 * np.abs(f).max()


def test_example_composes_and_calibrates(example, small_mesh, mat):
    """A model composed of variational shear, the example normal_axis term and volume builds under
    its own label with positive automatic constants for shear and normal_axis, and normal_axis's
    calibrated constant equals normal_sbd's in the same composition to 1e-6."""
    pm = build(COMPOSED, small_mesh, mat)
    assert pm.name == COMPOSED and pm.info["normal_axis_c"] > 0 and pm.info["shear_c"] > 0
    # linearised, it is the material-axis normal strain: the same quadratic form as normal_sbd
    sbd = build(COMPOSED.replace("normal_axis", "normal_sbd"), small_mesh, mat)
    assert pm.info["normal_axis_c"] == pytest.approx(sbd.info["normal_sbd_c"], rel=1e-6)


def test_pbcm_run_with_a_term_file(tmp_path, quick_cantilever):
    """The README's worked example: a user term file, composed on the command line (the
    cantilever's references are the session's, from its quick run)."""
    out = tmp_path / "run"
    assert main(["run", "cantilever", "--quick", "--workers", "1", "--term", str(EXAMPLE),
                 "--models", "pbcm-variational", COMPOSED, "--out", str(out)]) == 0
    runs = json.loads((out / "metrics.json").read_text())["runs"]
    assert [r["model"] for r in runs] == ["pbcm-variational", COMPOSED]
    assert all(np.isfinite(r["disp_rel_l2_p2"]) for r in runs)
    assert (out / "vtu" / "five_clamped_shear.reading=variational.c=auto+normal_axis.c=auto"
            "+volume.vtu").is_file()


def test_a_term_file_reaches_two_worker_processes(tmp_path):
    """--term on two worker processes, which load the file from PBCM_TERMS: one mesh each
    (the modes case, whose references are the cheapest of the library's)."""
    out = tmp_path / "run"
    assert main(["run", "modes", "--quick", "--meshes", "five", "six", "--workers", "2",
                 "--term", str(EXAMPLE), "--models", "pbcm-variational", COMPOSED,
                 "--out", str(out)]) == 0
    runs = json.loads((out / "metrics.json").read_text())["runs"]
    assert {(r["mesh"], r["model"]) for r in runs} == {
        (m, model) for m in ("five", "six") for model in ("pbcm-variational", COMPOSED)}
    assert all(r["failed"] is None and np.isfinite(r["modal_rel_err_median"]) for r in runs)


def test_entry_point_group_registers_an_installed_package(tmp_path):
    """A package declaring [project.entry-points."pbcm.terms"] is found without --term."""
    (tmp_path / "mypkg_terms.py").write_text(EXAMPLE.read_text().replace(
        '"normal_axis"', '"from_entry_point"'))
    dist = tmp_path / "mypkg_terms-0.1.dist-info"
    dist.mkdir()
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: mypkg-terms\nVersion: 0.1\n")
    (dist / "entry_points.txt").write_text("[pbcm.terms]\nmine = mypkg_terms\n")
    code = ("import model.terms, model.compose; print('from_entry_point' in "
            "model.terms.registered()); print(model.compose.label('from_entry_point(c=0.5)"
            "+volume'))")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(tmp_path), str(ROOT)])}
    env.pop("PBCM_TERMS", None)
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                         check=True).stdout.split("\n")
    assert out[:2] == ["True", "from_entry_point(c=0.5) + volume"]


def test_composition_grammar():
    """The composition grammar expands presets into their terms, normalises spacing in labels and
    reads numeric parameters; it refuses with a ModelError an unknown parameter or model,
    unbalanced brackets, a repeated term, a parameter with no value, an empty model and an
    unreadable value."""
    assert parse("pbcm-variational + normal_tet(c=0.1)") == [
        ("shear", {"reading": "variational", "c": "auto"}), ("volume", {}),
        ("normal_tet", {"c": 0.1})]
    assert parse("msm+volume") == [("springs", {}), ("volume", {})]       # a whole preset
    assert label("shear( reading = variational,c=auto )+volume") == \
        "shear(reading=variational, c=auto) + volume"
    assert parse("springs(scale=2)") == [("springs", {"scale": 2})]
    for bad, said in [("shear(foo=1)", "has no parameter 'foo'"), ("nope", "unknown model 'nope'"),
                      ("shear(reading=variational", "unbalanced"),
                      ("volume + volume", "appear twice"), ("shear(c)", "needs key=value"),
                      ("", "preset name or terms"), ("shear(c=1/2)", "cannot read the value")]:
        with pytest.raises(ModelError, match=said):
            parse(bad)


@pytest.mark.parametrize("args, said", [
    (["--models", "shear(foo=1) + volume"], "has no parameter 'foo'"),
    (["--term", "no/such/file.py"], "does not exist"),
    (["--models", "normal_axis(c=auto) + volume"], "unknown model 'normal_axis'"),
])
def test_bad_models_and_term_files_fail_before_computing(args, said, tmp_path, capsys):
    """A run whose model has an unknown parameter, whose term file does not exist, or which names a
    user term that no loaded file registers exits 2 with a message saying so and creates no
    output folder."""
    env = os.environ.pop("PBCM_TERMS", None)
    saved = dict(model.terms.TERMS)
    model.terms.TERMS.pop("normal_axis", None)
    try:
        assert main(["run", "paper-cube", "--quick", "--out", str(tmp_path / "x"), *args]) == 2
    finally:
        model.terms.TERMS.update(saved)
        if env is not None:
            os.environ["PBCM_TERMS"] = env
    assert said in capsys.readouterr().err
    assert not (tmp_path / "x").exists()


def test_term_file_that_registers_nothing_or_fails(tmp_path):
    """Loading a term file that registers no term, or one that raises while it is imported, fails
    with a ModelError saying so, naming the raised error in the second case."""
    (tmp_path / "empty.py").write_text("x = 1\n")
    (tmp_path / "broken.py").write_text("raise RuntimeError('boom')\n")
    for f, said in [("empty.py", "registers no term"), ("broken.py", "RuntimeError: boom")]:
        with pytest.raises(ModelError, match=said):
            model.terms.load_file(tmp_path / f)


def test_pbcm_list_names_the_terms_with_their_parameters(capsys):
    """`pbcm list --term FILE` exits 0 and lists the built-in terms and the file's term, each with
    its parameters and their defaults, and the studies."""
    assert main(["list", "--term", str(EXAMPLE)]) == 0
    out = capsys.readouterr().out
    for line in ("normal_tet(c=auto):", "shear(reading=variational, c=auto):", "volume():",
                 "normal_axis(c=auto):", "extensions (study):"):
        assert line in out, line
