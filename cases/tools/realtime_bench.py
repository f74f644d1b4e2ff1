"""The bench's real-time family: wall-clock seconds per simulated second of each model under
the paper's push (1.7 mm on the 32 mm cube at 1.7 mm/s, clamped base, mass damping 50 1/s),
on the 'five' cubes from the paper's 125 nodes to above 1e5 tetrahedra, one step of the mesh
at a time, so that the real-time study reads each model's reach from its own measurements.

Explicit models run RK4 at their own largest stable step (``timers.own_stable_step``), serial
and, where the model has one, in its two-thread mode; the implicit presets (backward Euler,
Newton with conjugate gradients) at their own step, on the same push, since their iterations
depend on the load; Newton's solvers (where the engines extra is installed) at their own step
through their adapter (model.simulators.newton). Times are wall clock (a simulator's budget is the wall's), medians over
rounds taken round-robin across the models at one size, with the rounds' range beside them.
A model is timed up the family until it is over real time at two sizes in a row: the
larger ones cannot be its reach (its cost grows with the mesh), and are marked as not timed.

A user's problem has its own family (``Loading``: each mesh, its boundary condition ramped
and its constant loads, and the problem's material), timed the same way.
"""
import time
from dataclasses import dataclass

import numpy as np

from model.presets import IMPLICIT_STEP

from ..framework import DEFAULT_MATERIAL
from ..library.common import bench_mesh, paper_push
from model import build
from model.compose import simulator
from ..reporting.costs import REAL_TIME, best, family_models, kernel_sources, sizes
from ..running import stop
from .timers import DAMPING, ImplicitTimed, Timed, own_stable_step

OVER_IN_A_ROW = 2        # sizes over real time in a row after which a model is not timed up
MIN_SAMPLE_S = 0.05      # each sample runs at least this long (many steps if need be)


def _ramp(mesh):
    return paper_push(mesh, "clamped")


@dataclass
class Loading:
    """One mesh of a family as timed: its prescribed displacements as a ramp (a ``bc_of_t``),
    its constant loads (n, 3) [N] or None, and the material."""

    mesh: object
    ramp: object
    f_ext: object = None
    material: object = DEFAULT_MATERIAL


def problem_family(levels, material, ramp_s):
    """A problem's refinement family as timed (``cases.library.problem.family.Level``s): each
    level's prescribed displacements ramped over ``ramp_s`` in proportion, its loads
    constant."""
    from model.bc import Proportional
    return [Loading(lv.mesh, Proportional(lv.dirichlet, ramp_s), lv.f_ext, material)
            for lv in levels]


def cube_family(quick=False):
    """The bench's family: the paper's push on the 'five' cubes, built one at a time."""
    for tets in sizes(quick):
        mesh = bench_mesh(tets)
        yield Loading(mesh, _ramp(mesh))


class _Explicit:
    """An explicit model on one mesh: its own stable step, and wall-clock seconds per RK4
    step serial and in its two-thread mode (None without one)."""

    def __init__(self, name, ld):
        self.t = Timed(name, ld.mesh, ld.material, ramp=ld.ramp, f_ext=ld.f_ext)
        self.dt = own_stable_step(self.t.pm)
        if self.t.kernels_2 is not None:
            self.t._steps(1, self.t.kernels_2)       # compile outside the timings
        one = self._wall(1, self.t.kernels)
        self.reps = max(1, int(MIN_SAMPLE_S / max(one, 1e-7)))

    def _wall(self, n, kernels):
        w0 = time.perf_counter()
        self.t._steps(n, kernels)
        return (time.perf_counter() - w0) / n

    def sample(self):
        serial = self._wall(self.reps, self.t.kernels)
        two = None if self.t.kernels_2 is None else self._wall(self.reps, self.t.kernels_2)
        return serial / self.dt, (np.nan if two is None else two / self.dt)


class _Implicit:
    """An implicit preset at its own step on one mesh: wall-clock seconds per step, and its
    Newton and CG iterations (each sample goes on from the last state along the push)."""

    def __init__(self, name, ld):
        self.t = ImplicitTimed(name, ld.mesh, ld.material, ramp=ld.ramp, f_ext=ld.f_ext)
        self.dt = self.t.dt

    def sample(self):
        w0 = time.perf_counter()
        stats = self.t._step()
        wall = time.perf_counter() - w0
        return (wall / self.dt, np.nan, stats["newton_iterations"],
                stats["cg_iterations"] / max(stats["newton_iterations"], 1))


class _Engine:
    """A simulator pbcm does not integrate (Newton's solvers) on one mesh at its own step:
    wall-clock seconds per step through its adapter's ``simulate``, the push set around every
    step as in its equilibrium runs, each sample going on from the last state."""

    def __init__(self, name, ld):
        self.sim, self.ramp, self.f_ext = build(name, ld.mesh, ld.material), ld.ramp, ld.f_ext
        self.dt = self.sim.stable_dt()
        self.x = self.v = None
        self.t = 0.0
        self._wall(1)                                   # load the engine's kernels first
        self.reps = max(1, int(MIN_SAMPLE_S / max(self._wall(1), 1e-7)))

    def _wall(self, n):
        w0 = time.perf_counter()
        tr = self.sim.simulate(self.ramp, self.t + n * self.dt, dt=self.dt, damping=DAMPING,
                               f_ext=self.f_ext, frames=2, x0=self.x, v0=self.v, t0=self.t)
        wall = time.perf_counter() - w0
        self.x, self.v, self.t = tr.x[-1], tr.v, self.t + n * self.dt
        return wall / n

    def sample(self):
        return self._wall(self.reps) / self.dt, np.nan


def _timer(name, ld):
    if name in IMPLICIT_STEP:
        return _Implicit(name, ld)
    return (_Engine if simulator(name) else _Explicit)(name, ld)


def _row(name, mesh, timer, got, rounds):
    got = np.array(got, dtype=float)
    serial = got[:, 0]
    row = {"model": name, "tets": mesh.n_tets, "nodes": mesh.n_nodes, "timed": True,
           "dt_us": timer.dt * 1e6, "rounds": rounds,
           "wall_s_per_simulated_s": float(np.median(serial)),
           "wall_range": [float(serial.min()), float(serial.max())],
           "two_thread_wall_s_per_simulated_s": None, "two_thread_range": None,
           "newton_per_step": None, "cg_per_newton": None}
    if not np.all(np.isnan(got[:, 1])):
        row.update(two_thread_wall_s_per_simulated_s=float(np.median(got[:, 1])),
                   two_thread_range=[float(got[:, 1].min()), float(got[:, 1].max())])
    if getattr(timer, "sim", None) is not None:       # an engine: which one, which version
        row["engine"] = timer.sim.info.get("engine")
    elif getattr(timer, "pm", None) is not None:      # pbcm's own kernels: which source
        row["kernels"] = kernel_sources(timer.pm)
    if got.shape[1] > 2:
        row.update(newton_per_step=float(np.median(got[:, 2])),
                   cg_per_newton=float(np.median(got[:, 3])))
    return row


def run(models=None, quick=False, rounds=5, progress=print, family=None, failures=(),
        over_in_a_row=OVER_IN_A_ROW, label="bench: real-time family"):
    """The family's rows: one per (model, size), timed or marked not timed (over real time at
    OVER_IN_A_ROW smaller sizes in a row); ``models`` default the family's, ``family`` (an
    iterable of Loading, smallest first) the bench's cube family. A model whose set-up or
    sample raises one of ``failures`` is recorded as failed there (its ``failed`` the reason)
    and not timed further up; any other error stops the run. ``over_in_a_row``: the sizes
    over real time in a row after which a model is not timed up (one where each size is
    several times the last: its cost cannot come back under real time). ``label`` leads each
    size's progress line."""
    models = models or family_models(quick)
    over = {m: 0 for m in models}
    failed = {}
    rows = []
    for ld in (cube_family(quick) if family is None else family):
        mesh = ld.mesh
        live = [m for m in models if over[m] < over_in_a_row and m not in failed]
        progress(f"{label}, {mesh.n_tets} tetrahedra, {len(live)} models")
        timers, got, here = {}, {m: [] for m in live}, {}
        for m in live:
            try:
                timers[m] = _timer(m, ld)
            except failures as exc:
                here[m] = failed[m] = f"{type(exc).__name__}: {exc}"
        for _ in range(rounds):
            stop.checkpoint()
            for m, timer in list(timers.items()):
                try:
                    got[m].append(timer.sample())
                except failures as exc:
                    here[m] = failed[m] = f"{type(exc).__name__}: {exc}"
                    del timers[m]
        for m in models:
            if m not in timers:
                rows.append({"model": m, "tets": mesh.n_tets, "nodes": mesh.n_nodes,
                             "timed": False, **({"failed": here[m]} if m in here else {})})
                continue
            row = _row(m, mesh, timers[m], got[m], rounds)
            rows.append(row)
            over[m] = over[m] + 1 if best(row)[0] > REAL_TIME else 0
        del timers
    return rows
