"""Backward Euler on (x, v), the integrator of most surgical simulators: each step solves

    M (x1 - x0 - dt v0) / dt^2 + zeta M (x1 - x0) / dt = f_int(x1) + f_ext,    v1 = (x1 - x0) / dt

for x1 by Newton's method, each Newton system (M (1/dt^2 + zeta/dt) - df/dx) dx = -R solved by
conjugate gradients (Jacobi-preconditioned, warm-started from the last step's correction) to a
stated tolerance. Unconditionally stable for a conservative model, at the price of numerical
damping that grows with dt: the step of a frame (1/60 s) or of a haptic loop (1 ms) is a
choice, not a stability limit.

Prescribed components follow their path exactly, as in :mod:`model.integrate`.
"""
import math

import numpy as np
from scipy.sparse import diags
from scipy.sparse.linalg import LinearOperator, cg

from .bc import bc_arrays
from .errors import BlowUpError, ConvergenceError, ModelError
from .geometry import min_signed_volume
from .integrate import Trajectory
from .presets import FRAME_S, HAPTIC_S  # noqa: F401 (the steps simulators run at)

NEWTON_RTOL = 1e-8          # |R| over the step's inertial force scale at which Newton stops
CG_RTOL = 1e-10             # each Newton system's relative residual
MAX_NEWTON = 20
SCALE_FLOOR = 1e-6
DX_ROUND_OFF = 1e-13        # a Newton correction below this fraction of the body's size


def backward_euler(model, bc_of_t, t_end, dt, damping=0.0, f_ext=None, frames=101, x0=None,
                   v0=None, t0=0.0, newton_rtol=NEWTON_RTOL, cg_rtol=CG_RTOL,
                   max_newton=MAX_NEWTON, stats=None):
    """Integrate ``model`` from ``t0`` (state ``x0``, ``v0``; the mesh at rest by default) to
    ``t_end`` [s] with backward Euler at the step ``dt`` [s] (shrunk to divide the interval);
    ``bc_of_t(t)`` the boundary-condition mapping at time t (the prescribed components fixed),
    ``damping`` the mass-damping rate zeta [1/s]. ``stats`` (a dict, optional) receives the
    Newton iterations and CG iterations summed over the steps. Raises ConvergenceError where
    Newton does not converge within ``max_newton`` iterations of a step, BlowUpError on an
    inverted tetrahedron."""
    mesh = model.mesh
    if not (t_end > t0 and math.isfinite(t_end)):
        raise ModelError(f"t_end must be a time in seconds after t0 = {t0}, got {t_end!r}")
    if not (dt is not None and dt > 0 and math.isfinite(dt)):
        raise ModelError(f"dt must be a positive time in seconds, got {dt!r}")
    steps = max(1, math.ceil((t_end - t0) / dt - 1e-9))
    dt = (t_end - t0) / steps
    mask, _ = bc_arrays(bc_of_t(t0), mesh.n_nodes)
    free = ~mask.ravel()
    f_ext = np.zeros_like(mesh.points) if f_ext is None else np.asarray(f_ext, dtype=float)
    m3 = np.repeat(model.mass, 3)
    inertia = (1.0 / dt ** 2 + damping / dt) * m3        # the mass term of the Newton matrix

    def prescribed(t):
        m, u = bc_arrays(bc_of_t(t), mesh.n_nodes)
        if not np.array_equal(m, mask):
            raise ModelError(f"bc_of_t({t:g}) prescribes other components than at t = "
                             f"{t0:g}; the set of prescribed components must stay the same")
        return mesh.points[mask] + u[mask]

    x = mesh.points.copy() if x0 is None else np.array(x0, dtype=float)
    v = np.zeros_like(mesh.points) if v0 is None else np.array(v0, dtype=float)
    x[mask] = prescribed(t0)
    frame_steps = set(np.unique(np.linspace(0, steps, max(int(frames), 2)).round().astype(int)))
    ts, xs, rs = [], [], []
    guess = np.zeros(int(free.sum()))
    newton_total = cg_total = 0
    largest = 0.0
    f_old = model.forces(x)       # the forces at the step's start: the last Newton evaluation
    extent = float(np.ptp(mesh.points, axis=0).max())

    def record(k, x):
        ts.append(t0 + k * dt)
        xs.append(x.copy())
        rs.append(np.where(mask, -(model.forces(x) + f_ext), 0.0))

    record(0, x)
    for k in range(1, steps + 1):
        t1 = t0 + k * dt
        x_old, v_old = x, v
        x = x_old + dt * v_old
        x[mask] = prescribed(t1)
        # the scale a residual is read against: the inertial force of the step's motion or the
        # force on the free nodes, never below a millionth of the largest seen (at rest both
        # vanish and the residual is round-off)
        scale = max(float(np.abs(inertia * (x - x_old).ravel()).max()),
                    float(np.abs(f_old + f_ext)[~mask].max(initial=0.0)),
                    SCALE_FLOOR * largest, 1e-300)
        largest = max(largest, scale)
        for it in range(max_newton + 1):
            f_old = model.forces(x)
            r = (inertia.reshape(x.shape) * (x - x_old) - m3.reshape(x.shape) / dt * v_old
                 - f_old - f_ext).ravel()[free]
            if np.abs(r).max() <= newton_rtol * scale:
                break
            if it == max_newton:
                raise ConvergenceError(
                    f"backward Euler: Newton did not converge in {max_newton} iterations at "
                    f"step {k} (t = {t1:.6g} s, dt = {dt:.3g} s): |R| {np.abs(r).max():.3g} "
                    f"over the force scale {scale:.3g}; try a smaller dt")
            A = (diags(inertia) - model.jacobian(x)).tocsr()[free][:, free]
            d = A.diagonal()
            pre = LinearOperator(A.shape, matvec=lambda y, d=d: y / d)
            count = [0]

            def counted(_, count=count):
                count[0] += 1
            dx, info = cg(A, -r, x0=guess, rtol=cg_rtol, atol=0.0, M=pre,
                          maxiter=10 * A.shape[0], callback=counted)
            if info != 0:
                raise ConvergenceError(f"backward Euler: CG did not reach {cg_rtol:g} at step "
                                       f"{k} (t = {t1:.6g} s); the Newton matrix may be "
                                       "indefinite (a non-conservative model)")
            cg_total += count[0]
            newton_total += 1
            guess = dx
            x.reshape(-1)[free] += dx
            if np.abs(dx).max() <= DX_ROUND_OFF * extent:
                break           # a correction at round-off: the residual is as small as it gets
        vmin, tmin = min_signed_volume(x, mesh.tets)
        if not np.isfinite(x).all():
            raise BlowUpError(f"backward Euler: NaN or inf in the state at step {k} "
                              f"(t = {t1:.6g} s)")
        if vmin <= 0.0:
            raise BlowUpError(f"backward Euler: tetrahedron {tmin} inverted at step {k} "
                              f"(t = {t1:.6g} s, dt = {dt:.3g} s); try a smaller dt")
        v = (x - x_old) / dt
        if k in frame_steps:
            record(k, x)
    if stats is not None:
        stats.update({"newton_iterations": newton_total, "cg_iterations": cg_total,
                      "steps": steps})
    return Trajectory(t=np.array(ts), x=np.array(xs), reaction=np.array(rs), dt=dt,
                      steps=steps, v=v)
