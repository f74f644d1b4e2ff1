import numpy as np
import pytest
from hypothesis import HealthCheck, settings

# derandomized and without a database: the same examples on every run and machine, no files
settings.register_profile("pbcm", derandomize=True, deadline=None, database=None,
                          max_examples=60,
                          suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
settings.load_profile("pbcm")

import os
import shutil
import tempfile
from pathlib import Path

from filelock import FileLock

from cases.running import store as S

# The commands' run store keeps the FEM references only, in a folder of this test session
# (shared by its xdist workers): every model run is computed by the test that checks it (a
# test that patches a model in-process is never served the unpatched run), and a reference,
# which no model changes, is solved once. The store's own tests (test_store.py) turn the
# whole store on in a folder of their own.
os.environ.pop(S.ENV_OFF, None)
os.environ[S.ENV_KINDS] = ",".join(S.REFERENCE_KINDS)


def pytest_configure(config):
    """The session's reference store: made by the controlling process, inherited by the
    xdist workers it starts (and by the worker processes the commands start). Each xdist
    worker keeps to a core of its own, so that a command it runs takes one process (the
    default of --workers is the cores available) and compiles each model's step once per
    session rather than once per command's worker process."""
    worker = getattr(config, "workerinput", None)
    if worker is not None and hasattr(os, "sched_setaffinity"):
        cores = sorted(os.sched_getaffinity(0))
        index = int(worker["workerid"].removeprefix("gw"))
        os.sched_setaffinity(0, {cores[index % len(cores)]})
    if worker is None:
        config._pbcm_store = tempfile.mkdtemp(prefix="pbcm-test-store-")
        os.environ[S.ENV] = config._pbcm_store


def pytest_unconfigure(config):
    folder = getattr(config, "_pbcm_store", None)
    if folder:
        shutil.rmtree(folder, ignore_errors=True)


# tests that run a command on two worker processes of their own: in collection order they
# come last (test_user_terms, test_workers), where one ran alone while the other xdist worker
# had nothing left; run first, they overlap the other worker's work
FIRST = ("tests/test_user_terms.py::test_a_term_file_reaches_two_worker_processes",
         "tests/test_workers.py::test_workers_write_the_metrics_of_one_process")


def pytest_collection_modifyitems(items):
    items.sort(key=lambda item: item.nodeid not in FIRST)     # stable: the rest keep order


def shared(tmp_path_factory, name, make):
    """The folder ``name`` made once per test session by ``make(folder)``, whichever xdist
    worker asks first; the others wait for it and read the same folder."""
    root = tmp_path_factory.getbasetemp()
    if os.environ.get("PYTEST_XDIST_WORKER"):
        root = root.parent
    out = Path(root) / "shared" / name / name      # its parent holds it alone (`pbcm check`)
    out.parent.mkdir(parents=True, exist_ok=True)
    done = out.parent / (name + ".done")
    with FileLock(str(out.parent / (name + ".lock"))):
        if not done.exists():
            shutil.rmtree(out, ignore_errors=True)
            make(out)
            done.touch()
    return out

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


def _run(*args):
    from cases.cli import main

    def make(out):
        assert main(["run", *args, "--out", str(out)]) == 0
    return make


@pytest.fixture(scope="session")
def quick(tmp_path_factory):
    """`pbcm run paper-cube --quick`, once per test session (the CI run of the case)."""
    return shared(tmp_path_factory, "paper-cube", _run("paper-cube", "--quick"))


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
    from cases.registry import CASES

    # each case once per session; the second xdist worker takes them in the reverse order, so
    # that two workers asking at once build the library together
    names = [n for n in CASES if n != "paper-cube"]
    if os.environ.get("PYTEST_XDIST_WORKER", "gw0") != "gw0":
        names.reverse()
    # the same folders as quick_cantilever's and the other fixtures of one case
    runs = {n: shared(tmp_path_factory, n, _run(n, "--quick")) for n in names}

    def make(root):
        root.mkdir(parents=True)
        for name in CASES:
            (root / name).symlink_to(quick if name == "paper-cube" else runs[name],
                                     target_is_directory=True)
    return shared(tmp_path_factory, "library", make)


@pytest.fixture(scope="session")
def quick_cantilever(tmp_path_factory):
    """`pbcm run cantilever --quick`, once per test session (the library's own): a test that
    runs the cantilever again (other models, workers, a cluster) then finds its FEM
    references in the session's store rather than solving them beside another worker."""
    return shared(tmp_path_factory, "cantilever", _run("cantilever", "--quick"))


@pytest.fixture(scope="session")
def quick_artefact(tmp_path_factory):
    """`pbcm run artefact --quick`, once per test session."""
    return shared(tmp_path_factory, "artefact", _run("artefact", "--quick"))


@pytest.fixture(scope="session")
def quick_truthcube(tmp_path_factory):
    """`pbcm run truth-cube --quick`, once per test session."""
    return shared(tmp_path_factory, "truth-cube", _run("truth-cube", "--quick"))


@pytest.fixture(scope="session")
def quick_convergence(tmp_path_factory):
    """`pbcm run convergence --quick` on one worker, once per test session."""
    return shared(tmp_path_factory, "convergence",
                  _run("convergence", "--quick", "--workers", "1"))
