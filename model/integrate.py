"""Classical RK4 on (x, v), as in the paper: a = (f_int + f_ext - zeta m v) / m.

Prescribed components follow their path exactly: position from ``bc_of_t``, velocity from its
``velocity`` method when it has one (model.bc.Ramp), else by a central difference of it.
"""
from dataclasses import dataclass
import math

import numpy as np

from .bc import bc_arrays
from .errors import BlowUpError, DegenerateTetError, ModelError
from .geometry import min_signed_volume


@dataclass
class Trajectory:
    """``t`` (k,) frame times, ``x`` (k, n, 3) positions, ``reaction`` (k, n, 3) support forces
    -(f_int + f_ext) on the prescribed components (inertia of the driven nodes excluded),
    ``dt`` the step used, ``steps`` the number of steps, ``v`` the final velocities (to
    continue from)."""

    t: np.ndarray
    x: np.ndarray
    reaction: np.ndarray
    dt: float
    steps: int
    v: np.ndarray


def rk4_step(accel, x, v, t, dt, constrain):
    """One classical RK4 step of x' = v, v' = accel(x, v, t); ``constrain(x, v, t)`` imposes the
    prescribed components in place at each stage time."""
    k1x, k1v = v, accel(x, v, t)
    x2, v2 = x + 0.5 * dt * k1x, v + 0.5 * dt * k1v
    constrain(x2, v2, t + 0.5 * dt)
    k2x, k2v = v2, accel(x2, v2, t + 0.5 * dt)
    x3, v3 = x + 0.5 * dt * k2x, v + 0.5 * dt * k2v
    constrain(x3, v3, t + 0.5 * dt)
    k3x, k3v = v3, accel(x3, v3, t + 0.5 * dt)
    x4, v4 = x + dt * k3x, v + dt * k3v
    constrain(x4, v4, t + dt)
    k4x, k4v = v4, accel(x4, v4, t + dt)
    xn = x + dt / 6.0 * (k1x + 2 * k2x + 2 * k3x + k4x)
    vn = v + dt / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v)
    constrain(xn, vn, t + dt)
    return xn, vn


def simulate(model, bc_of_t, t_end, dt=None, damping=0.0, f_ext=None, frames=101, safety=0.5,
             x0=None, v0=None, t0=0.0):
    """Integrate from ``t0`` (state ``x0``, ``v0``; the mesh at rest by default) to ``t_end``
    [s] with RK4.

    ``bc_of_t(t)`` returns the boundary-condition mapping at time t; the set of prescribed
    components must not change. ``dt`` defaults to ``model.stable_dt(safety)`` and is shrunk
    to divide ``t_end``. ``damping`` is the mass-damping rate zeta [1/s]. Raises BlowUpError
    naming the step, the time and a smaller dt on NaN, an inverted tetrahedron, or a particle
    faster than the P-wave speed.
    """
    mesh, mass = model.mesh, model.mass[:, None]
    if not (t_end > t0 and math.isfinite(t_end)):
        raise ModelError(f"t_end must be a time in seconds after t0 = {t0}, got {t_end!r}")
    dt = model.stable_dt(safety) if dt is None else float(dt)
    if not (dt > 0 and math.isfinite(dt)):
        raise ModelError(f"dt must be a positive time in seconds, got {dt!r}")
    steps = max(1, math.ceil((t_end - t0) / dt - 1e-9))
    dt = (t_end - t0) / steps
    mask, _ = bc_arrays(bc_of_t(0.0), mesh.n_nodes)
    f_ext = np.zeros_like(mesh.points) if f_ext is None else np.asarray(f_ext, dtype=float)
    h_fd = 1e-6 * dt

    if hasattr(bc_of_t, "arrays"):   # e.g. model.bc.Ramp: no mapping rebuilt per stage
        def prescribed(t):
            return bc_of_t.arrays(t, mesh.n_nodes)[1]
    else:
        def prescribed(t):
            m, u = bc_arrays(bc_of_t(t), mesh.n_nodes)
            if not np.array_equal(m, mask):
                raise ModelError(f"bc_of_t({t:g}) prescribes other components than at t = 0; "
                                 "the set of prescribed components must stay the same")
            return u

    if hasattr(bc_of_t, "velocity"):
        def prescribed_velocity(t):
            return bc_of_t.velocity(t, mesh.n_nodes)
    else:
        def prescribed_velocity(t):  # central difference, one-sided at t = 0
            t0 = max(t - h_fd, 0.0)
            return (prescribed(t + h_fd) - prescribed(t0)) / (t + h_fd - t0)

    def constrain(x, v, t):
        x[mask] = mesh.points[mask] + prescribed(t)[mask]
        v[mask] = prescribed_velocity(t)[mask]

    def accel(x, v, t):
        a = (model.forces(x) + f_ext) / mass - damping * v
        a[mask] = 0.0
        return a

    x = mesh.points.copy() if x0 is None else np.array(x0, dtype=float)
    v = np.zeros_like(mesh.points) if v0 is None else np.array(v0, dtype=float)
    constrain(x, v, t0)
    frame_steps = np.unique(np.linspace(0, steps, max(int(frames), 2)).round().astype(int))
    ts, xs, rs = [], [], []
    vmax = model.material.p_wave_speed

    def record(k, x):
        ts.append(t0 + k * dt)
        xs.append(x.copy())
        rs.append(np.where(mask, -(model.forces(x) + f_ext), 0.0))

    record(0, x)
    for k in range(1, steps + 1):
        t = t0 + (k - 1) * dt
        try:
            x, v = rk4_step(accel, x, v, t, dt, constrain)
        except DegenerateTetError as exc:
            raise _blow_up(f"tetrahedron {exc.tets[0]} inverted", k, t + dt, dt) from exc
        if not (np.isfinite(x).all() and np.isfinite(v).all()):
            raise _blow_up("NaN or inf in the state", k, t + dt, dt)
        vmin, tmin = min_signed_volume(x, mesh.tets)
        if vmin <= 0.0:
            raise _blow_up(f"tetrahedron {tmin} inverted", k, t + dt, dt)
        speed = np.sqrt((v * v).sum(axis=1)).max()
        if speed > vmax:
            raise _blow_up(f"a particle moves at {speed:.3g} m/s, faster than the P-wave speed "
                           f"{vmax:.3g} m/s", k, t + dt, dt)
        if k in frame_steps:
            record(k, x)
    return Trajectory(t=np.array(ts), x=np.array(xs), reaction=np.array(rs), dt=dt, steps=steps,
                      v=v)


def _blow_up(what, step, t, dt):
    return BlowUpError(f"time integration blew up at step {step} (t = {t:.6g} s, dt = {dt:.3g} s):"
                       f" {what}; try dt = {dt / 4:.3g} s, which cures an unstable step but not "
                       "flutter (a non-conservative reading whose linearised growth rate exceeds "
                       "half the damping: there, add damping)", step, t, dt / 4)
