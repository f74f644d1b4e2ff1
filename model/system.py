"""A particle model: a mesh, a material and a list of force terms, with its lumped masses."""
import numba
import numpy as np

from .calibrate import calibrate
from .geometry import smallest_heights
from .errors import ModelError
from .terms import fused_units, make_term
from .integrate import simulate as rk4_simulate
from .simulators.base import Simulator
from .static import RTOL as STATIC_RTOL, JacobianPattern, jacobian, solve as static_solve


class ParticleModel(Simulator):
    """Forces, energy, per-tetrahedron stresses, static equilibrium and RK4 dynamics: the
    :class:`model.simulators.Simulator` contract with pbcm's own integrators.

    Build one with :func:`model.build`. ``info`` holds what a report must state: the terms,
    their parameters and calibration constants (``shear_c``, ``normal_edge_c``).
    """

    splits_load = True      # its Newton solve takes the load in load_steps

    def __init__(self, mesh, material, terms, name="custom", threads=1, implicit_dt=None):
        self.mesh, self.material, self.name = mesh, material, name
        # None: RK4 at the stable step; a step [s]: backward Euler at it (model.implicit)
        self.implicit_dt = implicit_dt
        if not (isinstance(threads, int) and 1 <= threads <= numba.config.NUMBA_NUM_THREADS):
            raise ModelError(f"threads must be an integer from 1 to {numba.config.NUMBA_NUM_THREADS}"
                             f" (numba's threads on this machine), got {threads!r}")
        self.threads = threads
        self.terms = [make_term(t, mesh, material, **p) for t, p in terms]
        if not self.terms:
            raise ModelError("a model needs at least one force term")
        fit = calibrate(self.terms, mesh, material)
        self._strain_probe = None   # built on the first tet_stress: 24 strains per tet
        self._jacobian_pattern = None
        # what the kernels run: the terms, two of them in one pass where they fuse
        self.units = fused_units(self.terms)
        self.info = {"model": name, "terms": [{"term": t.describe(), **t.info()}
                                              for t in self.terms], **fit}
        for t in self.terms:
            if getattr(t, "coef", None) is not None:
                self.info[f"{t.name}_c"] = t.coef

    @property
    def conservative(self):
        return all(t.conservative for t in self.terms)

    def forces(self, x):
        """Internal forces (n, 3) [N] at positions x (n, 3) [m]."""
        x = np.ascontiguousarray(x, dtype=np.float64)
        if x.shape != self.mesh.points.shape:
            raise ModelError(f"positions must have shape {self.mesh.points.shape}, got {x.shape}")
        out = np.zeros_like(x)
        for unit, (fn, args) in zip(self.units, self.kernels()):
            bad = fn(x, *args, out)
            if bad >= 0:
                raise unit.degenerate(bad)
        return out

    def kernels(self):
        """The kernels of ``units`` (the terms, fused where they fuse) as a tuple of ``(fn,
        args)`` for the compiled integrator; with ``threads`` > 1 a unit's threaded kernel
        where it has one (same bits as serial)."""
        if self.threads == 1:
            return tuple(u.kernel() for u in self.units)
        numba.set_num_threads(self.threads)
        return tuple(u.threaded_kernel() or u.kernel() for u in self.units)

    def energy(self, x):
        """Total stored energy [J]; an error for a model with a non-conservative term."""
        return sum(t.energy(x) for t in self.terms)

    def tet_forces(self, x):
        """The forces (m, 4, 3) the terms put on the four corners of each tetrahedron alone:
        the terms evaluated on the tetrahedra taken apart, each translated to a cell of its
        own (no term sees a translation), with the constants this model was calibrated to; a
        term whose forces do not split over tetrahedra (none built in) would need its own
        split."""
        parts = self._apart()
        xa = np.ascontiguousarray(x, dtype=np.float64)[self.mesh.tets].reshape(-1, 3) \
            + parts["offset"]
        f = np.zeros_like(xa)
        for t in parts["terms"]:
            t.forces(xa, out=f)
        return f.reshape(self.mesh.n_tets, 4, 3)

    def _apart(self):
        """The terms rebuilt on the mesh's tetrahedra taken apart (built once)."""
        if getattr(self, "_apart_cache", None) is None:
            from .mesh import TetMesh
            from .terms import make_term
            mesh, m = self.mesh, self.mesh.n_tets
            k = int(np.ceil(m ** (1 / 3)))
            cell = 3.0 * float(np.ptp(mesh.points, axis=0).max())
            idx = np.arange(m)
            offset = np.repeat(np.stack([idx % k, (idx // k) % k, idx // k**2], axis=1)
                               * cell, 4, axis=0)
            apart = TetMesh(mesh.points[mesh.tets].reshape(-1, 3) + offset,
                            np.arange(4 * m).reshape(m, 4))
            terms = []
            for t in self.terms:
                params = dict(t.p)
                if getattr(t, "coef", None) is not None and "c" in params:
                    if t.coef == 0:
                        continue            # dropped by the calibration: no force
                    params["c"] = t.coef
                terms.append(make_term(t.name, apart, self.material, scale=t.scale, **params))
            self._apart_cache = {"offset": offset, "terms": terms}
        return self._apart_cache

    def stable_dt(self, safety=0.5):
        """safety * min_T h_T / c_p, with h_T the smallest height and c_p the P-wave speed;
        for a model integrated by backward Euler its own fixed step (stable at any step)."""
        if self.implicit_dt is not None:
            return self.implicit_dt
        return safety * float(smallest_heights(self.mesh.points, self.mesh.tets).min()) \
            / self.material.p_wave_speed

    def jacobian(self, x):
        """Sparse d f / d x (3n x 3n): in closed form where every term has one (``tangent``:
        the FEM baselines), else by coloured central differences (any reading)."""
        if all(hasattr(t, "tangent") for t in self.terms):
            return sum(t.tangent(x) for t in self.terms).tocsr()
        if self._jacobian_pattern is None:  # mesh-only work, once per model
            self._jacobian_pattern = JacobianPattern(self.mesh)
        return jacobian(self.forces, self.mesh, x, self._jacobian_pattern)

    def solve_static(self, bc, f_ext=None, rtol=STATIC_RTOL, max_iter=50, load_steps=1,
                     on_step=None, stall=None):
        """Equilibrium f_int(x) + f_ext = 0 on the free components (see model.static.solve)."""
        return static_solve(self, bc, f_ext=f_ext, rtol=rtol, max_iter=max_iter,
                            load_steps=load_steps, on_step=on_step, stall=stall)

    def simulate(self, bc_of_t, t_end, dt=None, damping=0.0, f_ext=None, frames=101, safety=0.5,
                 x0=None, v0=None, t0=0.0):
        """Classical RK4 dynamics (see model.integrate.simulate), or backward Euler at the
        model's own step (``implicit_dt``, or ``dt`` where given; see model.implicit)."""
        if self.implicit_dt is not None:
            from .implicit import backward_euler
            return backward_euler(self, bc_of_t, t_end, self.implicit_dt if dt is None else dt,
                                  damping=damping, f_ext=f_ext, frames=frames, x0=x0, v0=v0,
                                  t0=t0)
        return rk4_simulate(self, bc_of_t, t_end, dt=dt, damping=damping, f_ext=f_ext,
                                  frames=frames, safety=safety, x0=x0, v0=v0, t0=t0)
