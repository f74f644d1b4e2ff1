import subprocess
import sys

import meshio
import numpy as np
import pytest

from cases.cli import main
from model.mesh import cube


def test_version(capsys):
    try:
        main(["--version"])
    except SystemExit as exc:
        assert exc.code == 0
    assert capsys.readouterr().out.startswith("pbcm 0.")


def test_mesh_cube(capsys):
    assert main(["mesh", "cube", "--n", "5", "--scheme", "five"]) == 0
    out = capsys.readouterr().out
    assert "nodes               125" in out and "tetrahedra          320" in out
    assert "radius ratio" in out


def test_mesh_file(tmp_path, capsys):
    m = cube(3, 0.032, "six")
    path = tmp_path / "c.msh"
    meshio.write(path, meshio.Mesh(m.points, [("tetra", m.tets)]), file_format="gmsh22",
                 binary=False)
    assert main(["mesh", str(path)]) == 0
    assert f"tetrahedra          {m.n_tets}" in capsys.readouterr().out


def test_bad_input_exits_2_with_one_line(tmp_path, capsys):
    path = tmp_path / "flat.msh"
    meshio.write(path, meshio.Mesh(np.eye(3), [("triangle", np.array([[0, 1, 2]]))]),
                 file_format="gmsh22", binary=False)
    capsys.readouterr()  # meshio's own warnings while writing
    assert main(["mesh", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert "no tetrahedra" in err and len(err.splitlines()) == 1


def test_console_script_is_installed():
    out = subprocess.run([sys.executable, "-m", "cases.cli", "--version"], capture_output=True,
                         text=True)
    assert out.returncode == 0 and "pbcm" in out.stdout


@pytest.mark.parametrize("study, option, value", [("artefact", "--meshes", "six"),
                                                   ("artefact", "--models", "msm"),
                                                   ("truth-cube", "--meshes", "six"),
                                                   ("extensions", "--meshes", "six")])
def test_a_study_refuses_a_selection_it_would_ignore(study, option, value, tmp_path, capsys):
    from cases.cli import main
    out = tmp_path / study
    assert main(["run", study, "--quick", option, value, "--out", str(out)]) == 2
    assert f"{option} does not apply to the {study} study" in capsys.readouterr().err
    assert not out.exists()
