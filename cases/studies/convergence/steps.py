"""The particle runs' step convergence on the paper cube: each model's RK4 push (the
paper-cube case's clamped ramp, damping and stable step) at the case's step and at its half,
against the same push at an eighth; the error is the displacement at the end of the push,
||x - x_ref|| / ||x_ref - X|| over every node, and the observed order of the halving (RK4's
is 4: tests/test_integration_order.py asserts it on a small cube), None where the half step's
error is at round-off."""
import math

import numpy as np

from model import build
from ...running import stop
from ...framework import FINDINGS
from ...library import paper_cube as pc
from ...running.store import OFF, key

DIVISORS = (1, 2)           # the case's step divided by these
REFERENCE = 8               # the push at the case's step / 8 is the reference
ROUNDOFF = 1e-12            # an error below this is the sum of 1 667 steps' round-off (the
#                             five cube's fem-linear: 6e-14 at every step): no order from it
BC = "clamped"


def push(pm, ramp, dt, damping):
    """The positions at the end of the push, from rest, with ``dt``."""
    return pm.simulate(ramp, ramp.t_ramp, dt=dt, damping=damping, frames=2).x[-1]


def run_model(model, family, cfg, store=OFF):
    """One row: the step the case takes, the errors at each divisor, the orders."""
    k = key(kind="step-convergence", model=model, mesh=family, problem=cfg.problem(),
            divisors=DIVISORS, reference=REFERENCE, bc=BC)
    found = store.get(k)
    if found is not None:
        return found
    mesh = pc.make_mesh(family, cfg.nodes_per_side)
    pm = build(model, mesh, cfg.material)
    ramp = pc.dynamic_bc(mesh, BC, cfg.push_mm)
    steps = math.ceil(ramp.t_ramp / pm.stable_dt(cfg.safety) - 1e-9)   # the case's count
    dt = ramp.t_ramp / steps
    row = {"mesh": family, "model": model, "bc": BC, "dt_s": dt, "steps": steps,
           "failed": None, "failed_divisor": None}
    runs = {}
    try:
        for d in DIVISORS + (REFERENCE,):     # the case's step first: its failure is named
            stop.checkpoint()
            row["failed_divisor"] = d
            runs[d] = push(pm, ramp, dt / d, cfg.damping)
        ref = runs[REFERENCE]
        scale = np.linalg.norm(ref - mesh.points)
        errors = [float(np.linalg.norm(runs[d] - ref) / scale) for d in DIVISORS]
        row.update(dt_errors=errors, dt_error=errors[0], failed_divisor=None,
                   dt_order=_order(errors[-2], errors[-1], DIVISORS[-1] / DIVISORS[-2]))
    except FINDINGS as exc:          # a run that blows up: a finding, with the step it took
        row.update(failed=str(exc), dt_errors=None, dt_error=None, dt_order=None)
    return store.put(k, row)


def _order(coarse, fine, ratio):
    """log(coarse / fine) / log(ratio); None where the finer error is at round-off."""
    if fine <= ROUNDOFF:
        return None
    return float(np.log(coarse / fine) / np.log(ratio))


def units(models, families, E, nu, rho, store=OFF):
    """The table's rows as work units ``(run_model, args, cost)``: every model on every
    family, with the paper-cube case's settings at this material (cost: the pushes at
    the step's divisors, bcc's tetrahedra 2.5 times)."""
    cfg = pc.Config(E=E, nu=nu, rho=rho)
    pushes = sum(DIVISORS) + REFERENCE
    return [(run_model, (m, fam, cfg, store), pushes * (2.5 if fam == "bcc" else 1))
            for fam in families for m in models]


def table(models, families, E, nu, rho, store=OFF):
    """The rows of :func:`units`, computed here."""
    return [fn(*args) for fn, args, _ in units(models, families, E, nu, rho, store)]


__all__ = ["push", "run_model", "units", "table", "DIVISORS", "REFERENCE", "ROUNDOFF"]
