import os
import shutil
import subprocess
import sys
from pathlib import Path

import meshio
import numpy as np
import pytest

from cases.cli import main
from model.mesh import cube


def test_version(capsys):
    """`pbcm --version` exits with status 0 and prints a version line beginning with pbcm 0."""
    assert main(["--version"]) == 0
    assert capsys.readouterr().out.startswith("pbcm 0.")


def test_mesh_cube(capsys):
    """`pbcm mesh cube --n 5 --scheme five` exits 0 and reports 125 nodes, 320 tetrahedra and the
    mesh's radius-ratio quality."""
    assert main(["mesh", "cube", "--n", "5", "--scheme", "five"]) == 0
    out = capsys.readouterr().out
    assert "nodes               125" in out and "tetrahedra          320" in out
    assert "radius ratio" in out


def test_mesh_file(tmp_path, capsys):
    """`pbcm mesh` on a Gmsh 2.2 file exits 0 and reports the number of tetrahedra the file holds.
    """
    m = cube(3, 0.032, "six")
    path = tmp_path / "c.msh"
    meshio.write(path, meshio.Mesh(m.points, [("tetra", m.tets)]), file_format="gmsh22",
                 binary=False)
    assert main(["mesh", str(path)]) == 0
    assert f"tetrahedra          {m.n_tets}" in capsys.readouterr().out


def test_bad_input_exits_2_with_one_line(tmp_path, capsys):
    """`pbcm mesh` on a file holding no tetrahedra (a single triangle) exits with status 2 and a
    one-line error saying the mesh has no tetrahedra."""
    path = tmp_path / "flat.msh"
    meshio.write(path, meshio.Mesh(np.eye(3), [("triangle", np.array([[0, 1, 2]]))]),
                 file_format="gmsh22", binary=False)
    capsys.readouterr()  # meshio's own warnings while writing
    assert main(["mesh", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert "no tetrahedra" in err and len(err.splitlines()) == 1


def test_console_script_is_installed():
    """The installed `pbcm` command and `python -m cases.cli` both answer --version with exit 0
    and a line naming pbcm."""
    exe = shutil.which("pbcm", path=os.pathsep.join([str(Path(sys.executable).parent),
                                                       os.environ.get("PATH", "")]))
    assert exe, "the pbcm console script is not installed (pip install -e .)"
    for argv in ([exe], [sys.executable, "-m", "cases.cli"]):
        out = subprocess.run(argv + ["--version"], capture_output=True, text=True)
        assert out.returncode == 0 and out.stdout.startswith("pbcm "), argv


@pytest.mark.parametrize("study, option, value", [("artefact", "--meshes", "six"),
                                                   ("artefact", "--models", "msm"),
                                                   ("truth-cube", "--meshes", "six"),
                                                   ("extensions", "--meshes", "six")])
def test_a_study_refuses_a_selection_it_would_ignore(study, option, value, tmp_path, capsys):
    """A study run given a selection option the study does not use (--meshes for artefact, truth-
    cube and extensions, --models for artefact) exits 2 with an error saying the option does not
    apply to that study, and creates no output folder."""
    from cases.cli import main
    out = tmp_path / study
    assert main(["run", study, "--quick", option, value, "--out", str(out)]) == 2
    assert f"{option} does not apply to the {study} study" in capsys.readouterr().err
    assert not out.exists()
