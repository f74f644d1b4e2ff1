"""Classical RK4 on (x, v), as in the paper: a = (f_int + f_ext - zeta m v) / m.

Prescribed components follow their path exactly: position from ``bc_of_t``, velocity from its
``velocity`` method when it has one (model.bc.Ramp), else by a central difference of it.
"""
from dataclasses import dataclass
import math

import numpy as np

import warnings

from numba import literal_unroll, njit
from numba.core.errors import NumbaExperimentalFeatureWarning

from .bc import Ramp, path
from .errors import BlowUpError, DegenerateTetError, ModelError
from .geometry import min_signed_volume
from .step_cache import step_for


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

# the terms' kernels reach the compiled step as first-class functions in a tuple, a feature
# numba still calls experimental; it is what lets any composition of terms run compiled.
# Functions taking them are not cached on disk: numba's cache index does not key dispatcher
# types reliably across processes (a KeyError on loading was seen), so they compile once per
# process and composition.
warnings.filterwarnings("ignore", category=NumbaExperimentalFeatureWarning)


@njit
def add_forces(kernels, x, out):
    """out += the sum of every term's forces at x; returns (term, element) of the first
    degenerate element a kernel found, or (-1, -1)."""
    term, bad, i = -1, -1, 0
    for k in literal_unroll(kernels):
        b = k[0](x, *k[1], out)
        if b >= 0 and term < 0:
            term, bad = i, b
        i += 1
    return term, bad


@njit
def total_forces(kernels, x, out):
    """out = the sum of every term's forces at x (see :func:`add_forces`)."""
    out[:] = 0.0
    return add_forces(kernels, x, out)


@njit(cache=True)
def _stage(f, vs_in, vs_out, xs, x, v, inv_mass, damping, f_ext, c, w, acc_x, acc_v, first):
    """One pass over the flat (3n,) arrays after a stage's forces ``f`` (f_ext included) at
    stage velocity ``vs_in``: its acceleration a = f / m - zeta vs is added to the RK4 sums
    (acc_x += w vs, acc_v += w a; started from x, v when ``first``), the next stage set
    (xs = x + c vs, vs_out = v + c a) and f restarted at f_ext (zero when f_ext is empty).
    Flat and element by element, so that it runs in SIMD lanes; the prescribed components
    are fixed after (:func:`_prescribe`). ``vs_out`` must not be ``vs_in``: LLVM checks at run
    time that the arrays do not overlap before it takes the SIMD loop, and in place they do
    (then it takes the scalar loop)."""
    ext = f_ext.shape[0] > 0
    for j in range(f.shape[0]):
        vj = vs_in[j]
        aj = f[j] * inv_mass[j] - damping * vj
        if first:
            acc_x[j] = x[j] + w * vj
            acc_v[j] = v[j] + w * aj
        else:
            acc_x[j] += w * vj
            acc_v[j] += w * aj
        xs[j] = x[j] + c * vj
        vs_out[j] = v[j] + c * aj
        f[j] = f_ext[j] if ext else 0.0


@njit(cache=True)
def _start_forces(f, f_ext):
    """f = f_ext: the force accumulator of a stage starts at the external forces (the
    kernels add theirs); an empty f_ext stands for zero."""
    if f_ext.shape[0] == 0:
        f[:] = 0.0
    else:
        f[:] = f_ext


@njit(cache=True)
def _update(x, v, acc_x, acc_v, vs, f, inv_mass, damping, w, f_ext):
    """The end of an RK4 step on the flat (3n,) state: the last stage (forces ``f`` at
    velocity ``vs``) completes the sums, x = acc_x + w vs, v = acc_v + w a, and f restarts at
    f_ext for the next step."""
    ext = f_ext.shape[0] > 0
    for j in range(f.shape[0]):
        vj = vs[j]
        x[j] = acc_x[j] + w * vj
        v[j] = acc_v[j] + w * (f[j] * inv_mass[j] - damping * vj)
        f[j] = f_ext[j] if ext else 0.0


@njit(cache=True)
def _top_speed(v):
    """(every speed finite, the largest squared speed of a node). A non-finite position
    implies a non-finite velocity within the same step (a stage velocity is v plus a multiple
    of the previous stage's acceleration, whose multiple enters the sum of v), so the
    velocities alone are checked."""
    top, finite = 0.0, True
    for i in range(v.shape[0]):
        sp = v[i, 0] * v[i, 0] + v[i, 1] * v[i, 1] + v[i, 2] * v[i, 2]
        if not sp < np.inf:     # inf or NaN
            finite = False
        elif sp > top:
            top = sp
    return finite, top


@njit(cache=True)
def _prescribe(x, v, t, X, start, moving, t_ramp, pi, pk):
    """The ramp's prescribed components (pi[c], pk[c]) at time t (model.bc.Ramp.arrays and
    .velocity)."""
    s = min(max(t / t_ramp, 0.0), 1.0)
    moving_now = 0.0 <= t < t_ramp
    for c in range(pi.shape[0]):
        i, k = pi[c], pk[c]
        x[i, k] = X[i, k] + (start[i, k] + s * moving[i, k])
        v[i, k] = moving[i, k] / t_ramp if moving_now else 0.0


# the step's scratch arrays, each (n, 3): forces, stage position, two stage velocities (one
# read, one written), the two sums
STEP_BUFFERS = 6


@njit
def rk4_ramp(kernels, x, v, t0, dt, steps, X, mass, f_ext, damping, mask, start, moving,
             t_ramp, tets, check_volumes, vmax, buf):
    """``steps`` classical RK4 steps from (x, v) at t0, in place, under a ramp (the arithmetic
    of :func:`rk4_step`, summed as the stages come). ``buf`` (STEP_BUFFERS, n, 3) is scratch.
    Stops at the first step that breaks; returns (status, step, a, b, value): status 0 done,
    1 NaN or inf, 2 degenerate element b of term a, 3 tetrahedron b inverted, 4 a particle at
    speed value. ``check_volumes`` is needed where no term checks its tetrahedra (springs
    alone): the volumes are then checked every 8th step and at the last.

    Low storage: one force buffer, one stage position overwritten stage by stage, two stage
    velocities taking turns, and the RK4 sums of x and v accumulated as the stages come, so
    that the node passes stream 6 arrays of 3n doubles beside the state rather than 10 (at
    1e4 tetrahedra the arrays outgrow the L2 cache and a cheap model's step is bound by them).
    The prescribed components are a sparse list."""
    f, xs, vs, vs2 = buf[0], buf[1], buf[2], buf[3]
    n = x.shape[0]
    flat = buf.reshape(STEP_BUFFERS, 3 * n)    # the node passes run on flat views
    ff, fxs, fvs, fvs2, acc_x, acc_v = flat[0], flat[1], flat[2], flat[3], flat[4], flat[5]
    fx, fv = x.reshape(3 * n), v.reshape(3 * n)
    fext = f_ext.reshape(3 * n) if np.any(f_ext != 0.0) else np.empty(0)
    pi, pk = np.nonzero(mask)
    # per component, so that the flat passes need no index arithmetic (a division per node
    # per stage would cost msm a fifth)
    inv_mass = np.empty(3 * n)
    for i in range(n):
        for k in range(3):
            inv_mass[3 * i + k] = 1.0 / mass[i]
    h, w1, w2 = 0.5 * dt, dt / 6.0, dt / 3.0
    _start_forces(ff, fext)
    for step in range(1, steps + 1):
        t = t0 + (step - 1) * dt
        term, bad = add_forces(kernels, x, f)
        if term < 0:
            _stage(ff, fv, fvs, fxs, fx, fv, inv_mass, damping, fext, h, w1, acc_x, acc_v, True)
            _prescribe(xs, vs, t + h, X, start, moving, t_ramp, pi, pk)
            term, bad = add_forces(kernels, xs, f)
        if term < 0:
            _stage(ff, fvs, fvs2, fxs, fx, fv, inv_mass, damping, fext, h, w2, acc_x, acc_v,
                   False)
            _prescribe(xs, vs2, t + h, X, start, moving, t_ramp, pi, pk)
            term, bad = add_forces(kernels, xs, f)
        if term < 0:
            _stage(ff, fvs2, fvs, fxs, fx, fv, inv_mass, damping, fext, dt, w2, acc_x, acc_v,
                   False)
            _prescribe(xs, vs, t + dt, X, start, moving, t_ramp, pi, pk)
            term, bad = add_forces(kernels, xs, f)
        if term >= 0:
            return 2, step, term, bad, 0.0
        # the prescribed components' values are overwritten by _prescribe below
        _update(fx, fv, acc_x, acc_v, fvs, ff, inv_mass, damping, w1, fext)
        _prescribe(x, v, t + dt, X, start, moving, t_ramp, pi, pk)
        finite, top = _top_speed(v)           # the prescribed nodes' speed as prescribed
        if not finite:
            return 1, step, -1, -1, 0.0
        # a model whose kernels do not see tetrahedra (springs) is checked every 8th step and
        # at the last: the check would cost a fifth of such a step, and an inverted spring
        # model goes on smoothly, so a late catch only shifts the step reported
        if check_volumes and (step % 8 == 0 or step == steps):
            vmin, tmin = min_signed_volume(x, tets)
            if vmin <= 0.0:
                return 3, step, -1, tmin, 0.0
        if np.sqrt(top) > vmax:
            return 4, step, -1, -1, np.sqrt(top)
    return 0, steps, -1, -1, 0.0


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
    mask, prescribed = path(bc_of_t, mesh.n_nodes)
    f_ext = np.zeros_like(mesh.points) if f_ext is None else np.asarray(f_ext, dtype=float)
    h_fd = 1e-6 * dt

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
    if isinstance(bc_of_t, Ramp):   # the whole step compiled, forces included
        _, start, moving = bc_of_t.parts(mesh.n_nodes)
        step_fn, kernels = step_for(model.kernels(), rk4_ramp)
        check = not any(t.checks_inversion for t in model.terms)
        buf = np.empty((STEP_BUFFERS,) + x.shape)
        done = 0
        for k in frame_steps[1:]:
            status, at, term, bad, speed = step_fn(
                kernels, x, v, t0 + done * dt, dt, int(k - done), mesh.points, model.mass,
                f_ext, float(damping), mask, start, moving, bc_of_t.t_ramp, mesh.tets, check,
                vmax, buf)
            if status:
                step = done + at
                what = ("NaN or inf in the state" if status == 1 else
                        f"tetrahedron {model.units[term].degenerate_tets(bad)[0]} inverted"
                        if status == 2 else f"tetrahedron {bad} inverted" if status == 3 else
                        f"a particle moves at {speed:.3g} m/s, faster than the P-wave speed "
                        f"{vmax:.3g} m/s")
                raise _blow_up(what, step, t0 + step * dt, dt)
            done = int(k)
            record(done, x)
        if not check:   # the kernels check every stage but the last
            vmin, tmin = min_signed_volume(x, mesh.tets)
            if vmin <= 0.0:
                raise _blow_up(f"tetrahedron {tmin} inverted", steps, t_end, dt)
    else:
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
                raise _blow_up(f"a particle moves at {speed:.3g} m/s, faster than the P-wave "
                               f"speed {vmax:.3g} m/s", k, t + dt, dt)
            if k in frame_steps:
                record(k, x)
    return Trajectory(t=np.array(ts), x=np.array(xs), reaction=np.array(rs), dt=dt, steps=steps,
                      v=v)


def _blow_up(what, step, t, dt):
    return BlowUpError(f"time integration blew up at step {step} (t = {t:.6g} s, dt = {dt:.3g} s):"
                       f" {what}; try dt = {dt / 4:.3g} s, which cures an unstable step but not "
                       "flutter (a non-conservative reading whose linearised growth rate exceeds "
                       "half the damping: there, add damping)", step, t, dt / 4)
