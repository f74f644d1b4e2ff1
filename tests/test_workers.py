"""A case's meshes on worker processes: the same metrics as in one process, in the
declared order, and no worker left behind when the run is stopped."""
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from cases.cli import main
from conftest import _run, shared
from cases.running.workers import Cluster, Workers, WorkerLost, RETRIES

# two units (a mesh each) of the case with the cheapest references, their static solves,
# modal problems and figures: what an executor must hand out and collect in order
UNITS = ["modes", "--quick", "--meshes", "five", "six", "--models", "msm", "fem-linear"]


@pytest.fixture(scope="session")
def one_process(tmp_path_factory):
    """The units in one process, once per session: what every executor must write."""
    return shared(tmp_path_factory, "modes-units-one-process", _run(*UNITS, "--workers", "1"))


def test_workers_write_the_metrics_of_one_process(tmp_path, one_process):
    """Running the units on two worker processes writes a metrics.json byte-identical to the
    one-process run, with the meshes in their declared order (five before six)."""
    assert main(["run", *UNITS, "--workers", "2",
                 "--out", str(tmp_path / "2")]) == 0
    one, two = ((p / "metrics.json").read_bytes() for p in (one_process, tmp_path / "2"))
    assert one == two
    assert one.index(b'"mesh": "five"') < one.index(b'"mesh": "six"')   # declared order


def test_a_dask_cluster_writes_the_metrics_of_one_process(tmp_path, one_process):
    """`--scheduler ADDRESS`: the same units on a Dask cluster, the same bytes."""
    from distributed import LocalCluster
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=":0") as cluster:
        assert main(["run", *UNITS, "--scheduler", cluster.scheduler_address,
                     "--out", str(tmp_path / "dask")]) == 0
    assert (one_process / "metrics.json").read_bytes() == \
        (tmp_path / "dask" / "metrics.json").read_bytes()


def test_scheduler_and_workers_together_are_refused_before_computing(capsys, tmp_path):
    """`pbcm run` given both --scheduler and --workers exits 2, tells the user to drop
    --workers, and creates no output folder."""
    assert main(["run", "cantilever", "--scheduler", "tcp://127.0.0.1:1", "--workers", "2",
                 "--out", str(tmp_path / "c")]) == 2
    assert "drop --workers" in capsys.readouterr().err
    assert not (tmp_path / "c").exists()


def test_an_unreachable_scheduler_is_one_line(capsys, tmp_path, monkeypatch):
    """A --scheduler address where no Dask scheduler answers makes `pbcm run` exit 2 with a
    single stderr line saying so."""
    from cases.running import workers
    monkeypatch.setattr(workers, "CONNECT_TIMEOUT_S", 1)     # nothing answers port 9
    assert main(["run", "cantilever", "--quick", "--scheduler", "tcp://127.0.0.1:9",
                 "--out", str(tmp_path / "c")]) == 2
    err = capsys.readouterr().err
    assert "no Dask scheduler answers there" in err and len(err.strip().splitlines()) == 1


def die_once(item):
    """Kill this worker the first time ``item`` runs here (a marker file says it did)."""
    marker, value = item
    if marker is not None and not os.path.exists(marker):
        open(marker, "w").close()
        os.kill(os.getpid(), signal.SIGKILL)
    return value * 10


def die_always(item):
    os.kill(os.getpid(), signal.SIGKILL)


def test_a_killed_local_workers_unit_runs_again(tmp_path):
    """A unit whose local worker process is killed the first time it runs is given out again,
    so every unit's result comes back."""
    items = [(None, 1), (str(tmp_path / "killed"), 2), (None, 3)]
    with Workers(2) as pool:
        got = sorted(pool.unordered(die_once, items))
    assert got == [10, 20, 30] and (tmp_path / "killed").exists()


def test_a_unit_that_kills_every_worker_is_lost_after_the_retries():
    """A unit that kills its worker every time it runs comes back as a WorkerLost error with
    no result, saying it died RETRIES + 1 times."""
    with Workers(1) as pool:
        outcomes = list(pool.outcomes(die_always, [0]))
    [(i, error, result)] = outcomes
    assert i == 0 and result is None and isinstance(error, WorkerLost)
    assert f"died {RETRIES + 1} times" in str(error)


def test_the_cluster_executor_is_the_same_interface():
    """The Dask Cluster executor (here a one-process LocalCluster) returns every unit's
    result through the same unordered interface as Workers and has a dashboard link."""
    with Cluster(None, 1) as cluster:
        assert sorted(cluster.unordered(die_once, [(None, 4), (None, 5)])) == [40, 50]
        assert cluster.dashboard


@pytest.mark.parametrize("n", [0, -1, 1.5, "2"])
def test_workers_refuse_a_count_that_is_not_a_positive_integer(n):
    """Workers refuses a count of 0, -1, 1.5 or the string '2' with a ValueError asking for
    an integer >= 1."""
    with pytest.raises(ValueError, match="integer >= 1"):
        Workers(n)


def test_workers_flag_is_checked_before_computing(capsys, tmp_path):
    """`pbcm run --workers 0` exits 2, names --workers in its error, and creates no output
    folder."""
    assert main(["run", "cantilever", "--workers", "0", "--out", str(tmp_path / "c")]) == 2
    assert "--workers" in capsys.readouterr().err
    assert not (tmp_path / "c").exists()


def _children(pid):
    """The pids of the processes whose parent is ``pid``."""
    kids = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:     # gone meanwhile
            continue
        if int(fields[1]) == pid:
            kids.append(int(stat.parent.name))
    return kids


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="reads /proc")
@pytest.mark.parametrize("sig,status", [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_a_stopped_run_leaves_no_worker_behind(sig, status, tmp_path):
    """Ctrl-C reaches the whole process group (as from a terminal): the workers stay quiet,
    the parent says one line and takes them down; SIGTERM reaches the parent alone."""
    proc = subprocess.Popen([sys.executable, "-m", "cases.cli", "run", "paper-cube", "--quick",
                             "--workers", "2", "--out", str(tmp_path / "pc")],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True)
    deadline = time.monotonic() + 120
    while len(workers := [p for p in _children(proc.pid)
                          if b"spawn_main" in Path(f"/proc/{p}/cmdline").read_bytes()]) < 2:
        assert proc.poll() is None and time.monotonic() < deadline
        time.sleep(0.05)
    time.sleep(3.0)   # the workers are computing
    if sig == signal.SIGINT:
        os.killpg(proc.pid, sig)
    else:
        proc.send_signal(sig)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == status, err
    lines = [line for line in err.replace("\r", "\n").splitlines()
             if line.strip() and not line.startswith("[")]   # the progress bar aside
    assert len(lines) == 1, err
    for pid in workers:
        with pytest.raises(ProcessLookupError):
            os.kill(pid, 0)
    assert not (tmp_path / "pc").exists()


def _reports_twice(x):
    from cases.running.workers import tick
    tick(x, "half")
    tick(x, "all")
    return x


def test_a_local_pool_passes_a_units_progress_to_the_parent_as_it_runs():
    """What a unit reports while it runs (``tick``) reaches ``on_tick`` in the parent, every
    report of every unit, before its result is handed out."""
    from cases.running.workers import Workers
    seen = []
    with Workers(2) as w:
        for x in w.unordered(_reports_twice, [1, 2, 3], lambda *news: seen.append(news)):
            assert (x, "all") in seen
    assert sorted(seen) == sorted((x, w) for x in (1, 2, 3) for w in ("half", "all"))
