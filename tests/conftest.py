import numpy as np
import pytest
from hypothesis import HealthCheck, settings

# derandomized and without a database: the same examples on every run and machine, no files
settings.register_profile("pbcm", derandomize=True, deadline=None, database=None,
                          max_examples=60,
                          suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
settings.load_profile("pbcm")

import os
# the commands' run store stays out of the tests: each test computes what it checks (a test
# that patches the physics in-process would otherwise be served the unpatched results); the
# store's own tests (test_store.py) turn it on in a folder of their own
os.environ["PBCM_NO_CACHE"] = "1"

from model import Material
from model.mesh import TetMesh, cube

MAT = Material(E=10e3, nu=0.45, rho=1000.0)


@pytest.fixture
def mat():
    return MAT


@pytest.fixture
def small_mesh():
    return cube(3, 0.032, "six")


@pytest.fixture
def one_tet():
    pts = np.array([[0.0, 0.0, 0.0], [0.01, 0.001, 0.0], [0.002, 0.012, 0.001],
                    [0.001, 0.002, 0.009]])
    return TetMesh(pts, np.array([[0, 1, 2, 3]]))


def perturbed(mesh, amplitude=1e-3, seed=0):
    """Mesh positions with a random displacement of ``amplitude`` times the mean edge."""
    e = mesh.edges
    h = np.linalg.norm(mesh.points[e[:, 1]] - mesh.points[e[:, 0]], axis=1).mean()
    return mesh.points + amplitude * h * np.random.default_rng(seed).standard_normal(
        mesh.points.shape)


def rotation(axis, angle):
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


@pytest.fixture(scope="session")
def quick(tmp_path_factory):
    """`pbcm run paper-cube --quick`, once per test session (the CI run of the case)."""
    from cases.cli import main
    out = tmp_path_factory.mktemp("quick") / "paper-cube"
    assert main(["run", "paper-cube", "--quick", "--out", str(out)]) == 0
    return out


def floats_in(x):
    """Every float inside nested dicts and lists (a metrics document)."""
    if isinstance(x, dict):
        for v in x.values():
            yield from floats_in(v)
    elif isinstance(x, list):
        for v in x:
            yield from floats_in(v)
    elif isinstance(x, float):
        yield x


@pytest.fixture(scope="session")
def library(tmp_path_factory, quick):
    """Every case of the library run in quick mode into one folder, with the paper cube's
    quick run beside them (as `pbcm report --quick` would write them)."""
    from cases.cli import main
    from cases.registry import CASES
    root = tmp_path_factory.mktemp("library")
    for name in CASES:
        if name != "paper-cube":
            assert main(["run", name, "--quick", "--out", str(root / name)]) == 0
    (root / "paper-cube").symlink_to(quick, target_is_directory=True)
    return root


@pytest.fixture(scope="session")
def quick_artefact(tmp_path_factory):
    """`pbcm run artefact --quick`, once per test session."""
    from cases.cli import main
    out = tmp_path_factory.mktemp("artefact") / "artefact"
    assert main(["run", "artefact", "--quick", "--out", str(out)]) == 0
    return out


@pytest.fixture(scope="session")
def quick_truthcube(tmp_path_factory):
    """`pbcm run truth-cube --quick`, once per test session."""
    from cases.cli import main
    out = tmp_path_factory.mktemp("truthcube") / "truth-cube"
    assert main(["run", "truth-cube", "--quick", "--out", str(out)]) == 0
    return out
