"""Running a sweep: every unit not yet finished goes to the one executor as one task (local
worker processes by default, or the Dask cluster at ``scheduler``), or runs in this process
(``serial``). The parent alone writes files, so remote workers need no shared disk: each
finished run is stored at once (a sweep stopped anywhere resumes where it stopped), and the
table and report are drawn from the stored runs in the spec's order (so they do not depend on
which worker finished first).

A worker that dies mid-task (killed, out of memory) does not lose its task: it runs again
on another worker (Dask: up to ``distributed.scheduler.allowed-failures`` times, 3 by default;
local: ``cases.running.workers.RETRIES``). A task that exhausts them is recorded as failed for this sweep but not stored: a
rerun tries it again.
"""
from dataclasses import dataclass, field, replace
from functools import partial

from ...running.progress import Progress
from ...running.store import OFF
from ...running.workers import SchedulerError, executor
from .spec import NUMERIC_AXES
from .table import RunStore
from .task import run_unit

PARAMS = ("case", "mesh", "bc", "model") + NUMERIC_AXES
# run entries that are the row's parameters already, or folded into status and error
RUN_SKIP = {"mesh", "bc", "model", "failed", "static_failed"}


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
        log=True, store=OFF):
    """Run the sweep ``spec`` into the folder ``out``; return its Outcome. The units go to
    the one executor (``cases.running.workers``): local processes, the Dask cluster at
    ``scheduler``, or this process (``serial``); each model's run is taken from ``store`` (the
    run store) where a case or an earlier sweep computed it."""
    table = RunStore(out)
    units, todo = plan(spec, registry, table, retry_failed)
    total = sum(len(u.models) for u in todo)
    lost = {}
    outcome = Outcome(rows=[])
    with Progress("sweep", total, log=log) as bar:
        n = sum(len(u.models) for u in units)
        bar.say(f"sweep: {n} runs: {total} to compute, {n - total} found in {table.folder}")

        def finished(unit, result):
            runs, wall = result
            params = parameters(unit, registry)
            for r in runs:
                key = unit.run_key(r["model"])
                table.put(key, row(params, r, key, wall))
            outcome.computed += len(runs)
            bar.advance(len(runs), f"{unit.case} {unit.mesh}/{unit.bc} "
                        + " ".join(f"{k}={v:g}" for k, v in unit.point.items()))

        ex = None if serial or not todo else executor(scheduler, workers, len(todo))
        if ex is None:
            for u in todo:
                finished(u, run_unit(u, store))
        else:
            with ex:
                outcome.dashboard = ex.dashboard
                if ex.dashboard:
                    bar.say(f"Dask dashboard: {ex.dashboard}")
                for i, error, result in ex.outcomes(partial(run_unit, store=store), todo):
                    if error is None:
                        finished(todo[i], result)
                        continue
                    for m in todo[i].models:   # the task, not the run, failed: no worker
                        lost[todo[i].run_key(m)] = (  # could finish it
                            f"worker: the task could not be finished ({type(error).__name__}: "
                            f"{error}); rerun the sweep to try it again")
    for u in units:
        params = parameters(u, registry)
        for m in u.models:
            key = u.run_key(m)
            r = table.get(key)
            if r is None:
                r = row(params, {"model": m, "failed": lost[key]}, key, None)
                outcome.lost += 1
            outcome.rows.append(r)
    outcome.found = len(outcome.rows) - outcome.computed - outcome.lost
    outcome.failed = [r for r in outcome.rows if r["status"] == "failed"]
    return outcome


__all__ = ["run", "plan", "row", "parameters", "Outcome", "SchedulerError", "PARAMS"]
