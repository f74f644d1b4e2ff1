"""What `pbcm bench` and its real-time family time: a preset's force evaluation and RK4 step
under a push (``Timed``), an implicit preset's step (``ImplicitTimed``), and the model's own
largest stable RK4 step. Times are thread CPU times unless a caller takes the wall clock."""
import time
import tracemalloc

import numpy as np
import numba
from numba import njit
from threadpoolctl import threadpool_limits

from model import build
from model.bc import Ramp
from model.calibrate import calibrate
from model.implicit import backward_euler
from model.integrate import STEP_BUFFERS, rk4_ramp, total_forces
from model.presets import IMPLICIT_STEP

from ..framework import MM
from ..library.common import CUBE_MM

RK4_LIMIT = 2 * np.sqrt(2)  # RK4 is stable for |omega dt| up to 2 sqrt 2 on the imaginary axis
SAMPLE_S = 0.02          # each timing sample runs at least this long (many calls if need be)
DAMPING = 50.0           # the push's mass damping [1/s] (the paper cube's)


@njit   # not cached: it takes the kernels (see model.integrate)
def force_loop(kernels, x, out, reps):
    for _ in range(reps):
        total_forces(kernels, x, out)


def own_stable_step(pm):
    """The model's own largest stable RK4 step [s] on its mesh, undamped: 2 sqrt 2 / omega_max
    with omega_max^2 the largest |eigenvalue| of M^-1 df/dx at rest (lumped mass), so that a
    stiffer model pays for its stiffness in steps per simulated second."""
    from scipy.sparse import diags
    from scipy.sparse.linalg import eigs
    J = pm.jacobian(pm.mesh.points)
    A = diags(1.0 / np.repeat(pm.mass, 3)) @ J
    start = np.random.default_rng(0).standard_normal(A.shape[0])   # the same bits every run
    lam = eigs(A, k=1, which="LM", v0=start, tol=1e-6, return_eigenvectors=False)
    return float(RK4_LIMIT / np.sqrt(np.abs(lam[0])))


class Timed:
    """One preset on one mesh, ready to be timed: its kernels, a state and the step's
    buffers, under ``ramp`` (default the bench's push: 1 % of the side over 1 s, the base
    held) and the constant loads ``f_ext`` (n, 3) [N] (default none)."""

    def __init__(self, name, mesh, mat, ramp=None, f_ext=None):
        tracemalloc.start()
        self.pm = build(name, mesh, mat)
        self.memory = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        t0 = time.perf_counter()
        calibrate(self.pm.terms, mesh, mat, cache=False)
        self.calibration = time.perf_counter() - t0 if any(
            getattr(t, "calibrate", False) for t in self.pm.terms) else 0.0
        self.kernels = self.pm.kernels()
        # the two-thread mode of the kernel units that have one (model.terms._threads)
        threaded = [u.threaded_kernel() for u in self.pm.units]
        self.kernels_2 = None
        if any(threaded) and numba.config.NUMBA_NUM_THREADS >= 2:
            numba.set_num_threads(2)
            self.kernels_2 = tuple(k or u.kernel() for k, u in zip(threaded, self.pm.units))
        ramp = ramp or _push(mesh)
        mask, start, moving = ramp.parts(mesh.n_nodes)
        self.x, self.v = mesh.points.copy(), np.zeros_like(mesh.points)
        self.out = np.zeros_like(mesh.points)
        f_ext = np.zeros_like(mesh.points) if f_ext is None else np.asarray(f_ext, float)
        self.step_args = (mesh.points, self.pm.mass, f_ext, DAMPING, mask,
                          start, moving, ramp.t_ramp, mesh.tets,
                          not any(t.checks_inversion for t in self.pm.terms),
                          self.pm.material.p_wave_speed, np.empty((STEP_BUFFERS,) + mesh.points.shape))
        self.dt = self.pm.stable_dt(0.5)
        self.t = 0.0
        force_loop(self.kernels, self.x, self.out, 1)    # compile outside the timings
        if self.kernels_2 is not None:
            force_loop(self.kernels_2, self.x, self.out, 1)
        self._steps(1)
        self.reps_force = self._reps(lambda n: force_loop(self.kernels, self.x, self.out, n))
        self.reps_step = self._reps(self._steps)

    def _steps(self, n, kernels=None):
        status = rk4_ramp(kernels or self.kernels, self.x, self.v, self.t, self.dt, n, *self.step_args)[0]
        if status:
            raise RuntimeError(f"the benchmark's push blew up for {self.pm.name}")
        self.t += n * self.dt

    @staticmethod
    def _reps(call):
        t0 = time.thread_time()
        call(1)
        one = max(time.thread_time() - t0, 1e-7)
        return max(1, int(SAMPLE_S / one))

    def sample(self):
        """(seconds per force evaluation, seconds per RK4 step) in thread CPU time, and the
        two-thread mode's speed-up of the force evaluation (wall clock, serial and threaded
        back to back; NaN without a two-thread mode)."""
        t0 = time.thread_time_ns()
        force_loop(self.kernels, self.x, self.out, self.reps_force)
        t1 = time.thread_time_ns()
        self._steps(self.reps_step)
        t2 = time.thread_time_ns()
        speedup = float("nan")
        if self.kernels_2 is not None:
            w0 = time.perf_counter()
            force_loop(self.kernels, self.x, self.out, self.reps_force)
            w1 = time.perf_counter()
            force_loop(self.kernels_2, self.x, self.out, self.reps_force)
            speedup = (w1 - w0) / (time.perf_counter() - w1)
        return (t1 - t0) * 1e-9 / self.reps_force, (t2 - t1) * 1e-9 / self.reps_step, speedup


def _push(mesh):
    """The bench's push: the top moved down 1 % of the side in one second, the base held."""
    side = CUBE_MM * MM
    top, bot = mesh.nodes_on_plane("y", side), mesh.nodes_on_plane("y", 0.0)
    return Ramp(top, (0.0, -0.01 * side, 0.0), 1.0, fixed=bot)


class ImplicitTimed:
    """An implicit preset (backward Euler at its own step) on the bench's push, timed one
    step per sample, each sample going on from the last state: thread CPU time per step, and
    the Newton and conjugate-gradient iterations it took; under ``ramp`` (default the bench's
    push) and the constant loads ``f_ext`` (default none)."""

    def __init__(self, name, mesh, mat, ramp=None, f_ext=None):
        self.pm, self.f_ext = build(name, mesh, mat), f_ext
        self.dt, self.ramp = IMPLICIT_STEP[name], ramp or _push(mesh)
        self.x, self.v, self.t = mesh.points.copy(), np.zeros_like(mesh.points), 0.0
        self._step()       # the first step builds the Jacobian's pattern: outside the timings

    def _step(self):
        stats = {}
        # BLAS on one thread: the step is timed as a serial model is (thread CPU time would
        # miss a BLAS helper thread's work), and no BLAS thread left spinning after it takes
        # the second core from the next model's two-thread sample
        with threadpool_limits(limits=1, user_api="blas"):
            run = backward_euler(self.pm, self.ramp, self.t + self.dt, self.dt,
                                 damping=DAMPING, f_ext=self.f_ext, frames=2, x0=self.x,
                                 v0=self.v, t0=self.t, stats=stats)
        self.x, self.v, self.t = run.x[-1], run.v, self.t + self.dt
        return stats

    def sample(self):
        """(seconds per step, Newton iterations, conjugate-gradient iterations)."""
        t0 = time.thread_time_ns()
        stats = self._step()
        return ((time.thread_time_ns() - t0) * 1e-9, stats["newton_iterations"],
                stats["cg_iterations"])
