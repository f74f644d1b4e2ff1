"""What a worker runs: one Unit of a sweep (a case's (mesh, bc) at one point, with its
models), through the shared case runner. Nothing a run does stops the sweep: any exception
becomes the ``failed`` entry of the runs it touched.
"""
import time

from ...running import runner
from ...registry import CASES
from ...running.store import OFF
from ...running.workers import one_blas_thread


def run_unit(unit, store=OFF):
    """``(runs, wall)``: the runner's run dicts of ``unit`` (one per model, failures
    included; from the run store ``store`` where it has them) and the task's wall time [s]."""
    t0 = time.perf_counter()
    case = CASES[unit.case]
    try:
        s = case.settings(meshes=(unit.mesh,), bcs=(unit.bc,), models=unit.models,
                          **unit.settings)
    except Exception as exc:          # a value the settings refuse (nu = 0.5, E < 0)
        runs = runner.failed_runs(unit.mesh, unit.bc, unit.models, "settings", exc)
    else:
        with one_blas_thread():
            try:
                runs, _ = runner.unit(case, s, unit.mesh, unit.bc, store=store)
            except Exception as exc:  # beyond the runner's findings: recorded all the same
                runs = runner.failed_runs(unit.mesh, unit.bc, unit.models, "error",
                                          f"{type(exc).__name__}: {exc}")
    return runs, time.perf_counter() - t0


__all__ = ["run_unit"]
