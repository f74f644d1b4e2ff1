"""Running a sweep: every unit not yet finished goes to dask.distributed as one task (a
LocalCluster by default, or the cluster at ``scheduler``), or runs in this process
(``serial``). The parent alone writes files, so remote workers need no shared disk: each
finished run is stored at once (a sweep stopped anywhere resumes where it stopped), and the
table and report are drawn from the stored runs in the spec's order (so they do not depend on
which worker finished first).

A worker that dies mid-task (killed, out of memory) loses its tasks to the scheduler, which
runs them again elsewhere (up to ``distributed.scheduler.allowed-failures`` times, 3 by
default). A task that exhausts them is recorded as failed for this sweep but not stored: a
rerun tries it again.
"""
import logging
import sys
import time
from dataclasses import dataclass, field, replace

from rich.console import Console
from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn, TimeRemainingColumn

from model import PbcmError
from ...workers import available_cores
from .spec import NUMERIC_AXES
from .table import RunStore
from .task import run_unit

PARAMS = ("case", "mesh", "bc", "model") + NUMERIC_AXES
# run entries that are the row's parameters already, or folded into status and error
RUN_SKIP = {"mesh", "bc", "model", "failed", "static_failed"}
CONNECT_TIMEOUT_S = 10


class SchedulerError(PbcmError):
    """The scheduler given cannot be reached: it names the address and what to do."""


@dataclass
class Outcome:
    """What a sweep did: every row in the spec's order, and the counts."""

    rows: list
    computed: int = 0
    found: int = 0
    lost: int = 0          # runs whose task no worker could finish (rerun: tried again)
    dashboard: str = None
    failed: list = field(default_factory=list)


def parameters(unit, registry):
    """The parameter columns of a unit's rows: case, mesh, bc, the values of every numeric
    axis the run used (swept, fixed or the case's default; None where the case has no such
    setting) and the fixed settings. Read off the case's default settings with the unit's
    values laid over them, so that a point whose settings fail still names them all."""
    case = registry[unit.case]
    default = case.settings(quick=unit.settings.get("quick", False))
    setting = {"E": "E", "nu": "nu", "rho": "rho"}      # axis -> the case's settings field
    for axis in ("resolution", "load"):
        knob = getattr(case, axis)
        setting[axis] = None if knob is None else knob.field
    out = {"case": unit.case, "mesh": unit.mesh, "bc": unit.bc}
    out.update({a: None if f is None else unit.settings.get(f, getattr(default, f))
                for a, f in setting.items()})
    out.update({k: v for k, v in unit.settings.items() if k not in setting.values()})
    return out


def row(params, run, key, wall):
    """One table row: the parameters, the run key, status and error, the run's metrics and
    the task's wall time. Status ``failed``: the run has no static result (``error`` says
    why); ``partial``: it has, but a later phase failed (a dynamic run blew up: ``error``
    names the phase); ``ok``: every phase ran."""
    error = run.get("failed") or run.get("static_failed")
    phases = {k: v for k, v in run.items()
              if k.endswith("_failed") and k not in ("failed", "static_failed") and v}
    status = "failed" if error else "partial" if phases else "ok"
    error = error or "; ".join(f"{k}: {v}" for k, v in sorted(phases.items())) or None
    out = {**params, "model": run["model"], "run_key": key, "status": status, "error": error}
    out.update({k: v for k, v in run.items() if k not in RUN_SKIP})
    out["task_wall_s"] = wall
    return out


def plan(spec, registry, store, retry_failed=False):
    """(units, todo): every unit of the spec, and the units with runs still to compute
    (their models narrowed to those)."""
    units = spec.units(registry)
    todo = []
    for u in units:
        missing = []
        for m in u.models:
            stored = store.get(u.run_key(m))
            if stored is None or (retry_failed and stored.get("status") == "failed"):
                missing.append(m)
        if missing:
            todo.append(replace(u, models=tuple(missing)))
    return units, todo


def run(spec, registry, out, scheduler=None, workers=None, serial=False, retry_failed=False,
        log=True):
    """Run the sweep ``spec`` into the folder ``out``; return its Outcome."""
    store = RunStore(out)
    units, todo = plan(spec, registry, store, retry_failed)
    total = sum(len(u.models) for u in todo)
    lost = {}
    outcome = Outcome(rows=[])
    console = Console(stderr=True)
    tty = sys.stderr.isatty()
    if log:
        n = sum(len(u.models) for u in units)
        console.print(f"sweep: {n} runs: {total} to compute, {n - total} found in "
                      f"{store.folder}")
    t0, said = time.perf_counter(), [0]
    with Progress(TextColumn("{task.description:<48}"), BarColumn(),
                  TextColumn("{task.completed}/{task.total} runs"), TimeElapsedColumn(),
                  TextColumn("left"), TimeRemainingColumn(), console=console,
                  disable=not (log and tty)) as bar:
        task = bar.add_task("sweep", total=total)

        def finished(unit, result):
            runs, wall = result
            params = parameters(unit, registry)
            for r in runs:
                key = unit.run_key(r["model"])
                store.put(key, row(params, r, key, wall))
            outcome.computed += len(runs)
            bar.update(task, advance=len(runs),
                       description=f"{unit.case} {unit.mesh}/{unit.bc} "
                       + " ".join(f"{k}={v:g}" for k, v in unit.point.items()))
            done = outcome.computed
            if log and not tty and 10 * done // total > said[0]:   # a log: every tenth
                said[0] = 10 * done // total
                spent = time.perf_counter() - t0
                console.print(f"sweep: {done}/{total} runs in {spent:.0f} s, about "
                              f"{spent / done * (total - done):.0f} s left")

        if todo and serial:
            for u in todo:
                finished(u, run_unit(u))
        elif todo:
            with _client(scheduler, workers, log) as client:
                outcome.dashboard = client.dashboard_link
                if log:
                    console.print(f"Dask dashboard: {client.dashboard_link}")
                _distribute(client, todo, finished, lost)
    for u in units:
        params = parameters(u, registry)
        for m in u.models:
            key = u.run_key(m)
            r = store.get(key)
            if r is None:
                r = row(params, {"model": m, "failed": lost[key]}, key, None)
                outcome.lost += 1
            outcome.rows.append(r)
    outcome.found = len(outcome.rows) - outcome.computed - outcome.lost
    outcome.failed = [r for r in outcome.rows if r["status"] == "failed"]
    return outcome


def _distribute(client, todo, finished, lost):
    """Every unit of ``todo`` as a task on ``client``; ``finished(unit, result)`` as each
    comes back. A task no worker could finish (KilledWorker) is noted in ``lost``."""
    from distributed import as_completed
    futures = {}
    for i, u in enumerate(todo):
        key = f"pbcm-sweep-{i}-{u.run_key(u.models[0])}"
        futures[client.submit(run_unit, u, key=key, pure=False)] = u
    try:
        for fut in as_completed(futures):
            u = futures[fut]
            try:
                result = fut.result()
            except Exception as exc:   # the task, not the run, failed: a worker died
                for m in u.models:
                    lost[u.run_key(m)] = (f"worker: the task could not be finished "
                                          f"({type(exc).__name__}: {exc}); rerun the sweep "
                                          "to try it again")
                continue
            finished(u, result)
    finally:
        for fut in futures:
            fut.cancel()


class _client:
    """A dask.distributed Client: on the scheduler at ``address``, or on a LocalCluster of
    ``workers`` processes (one thread each), closed on leaving the block."""

    def __init__(self, address, workers, log):
        self.address, self.workers, self.log = address, workers, log
        self.cluster = self.client = None

    def __enter__(self):
        from distributed import Client, LocalCluster
        if self.address:
            try:
                self.client = Client(self.address, timeout=f"{CONNECT_TIMEOUT_S}s")
            except (OSError, TimeoutError) as exc:
                raise SchedulerError(
                    f"--scheduler {self.address}: no Dask scheduler answers there ({exc}); "
                    "start one with `dask scheduler` and workers with `dask worker "
                    f"{self.address}` (README, 'Sweeps on a cluster')") from None
            return self.client
        self.cluster = LocalCluster(n_workers=self.workers or available_cores(),
                                    threads_per_worker=1, processes=True,
                                    silence_logs=logging.ERROR)
        self.client = Client(self.cluster)
        return self.client

    def __exit__(self, *exc):
        if self.client is not None:
            self.client.close()
        if self.cluster is not None:
            self.cluster.close()


__all__ = ["run", "plan", "row", "parameters", "Outcome", "SchedulerError", "PARAMS"]
