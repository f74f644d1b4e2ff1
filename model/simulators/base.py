"""The contract of a model, whoever integrates it: :class:`Simulator`.

pbcm's own models (:class:`model.system.ParticleModel`) satisfy it with their own integrators;
a simulator pbcm does not integrate itself (a physics engine) satisfies it with one adapter
class that implements :meth:`Simulator.simulate` and, where it can, :meth:`Simulator.tet_forces`;
the static equilibrium then comes by running it to rest (:func:`run_to_rest`).
"""
import math

import numpy as np

from ..bc import bc_arrays
from ..errors import ConvergenceError, ModelError


class Simulator:
    """What the cases and studies ask of a model.

    ``name``, ``mesh``, ``material``
        the model's label, its tetrahedral mesh (``model.mesh.TetMesh``) and material;
    ``info``
        a dict a report must state: what the model is, its settings;
    ``params``
        the settings a user may give (``name(key=value, ...)`` on the command line), with their
        defaults; every other keyword is refused;
    ``simulate(bc_of_t, t_end, dt=None, damping=0.0, f_ext=None, frames=101, x0=None,
    v0=None, t0=0.0)``
        positions over time (``model.integrate.Trajectory``): ``bc_of_t`` maps a time to the
        prescribed displacements ``{node: (ux, uy, uz)}`` (None for a free component; the same
        components at every time), ``f_ext`` (n, 3) constant nodal forces [N] (tractions and
        gravity as nodal loads), ``damping`` a mass-proportional damping [1/s], ``dt`` the step
        (None: the model's own), ``frames`` how many states to keep;
    ``solve_static(bc, f_ext=None, rtol=..., load_steps=1, ...)``
        the equilibrium (``model.static.StaticResult``: positions, displacements, reactions on
        the prescribed components, the residual force); by default :func:`run_to_rest`;
    ``tet_forces(x)``
        where the model can: the forces (m, 4, 3) [N] each tetrahedron alone puts on its four
        corners at positions x, whose sum over the tetrahedra at a node is the internal force
        there; a model that cannot say leaves it out (then no reaction, no net force or torque
        and no stress from forces is reported for it: those metrics read None);
    ``stable_dt(safety=0.5)``
        the step ``simulate`` takes when given none [s] (``safety``: the fraction of its
        stable step an explicit model takes).

    The rest follows from these: ``forces``, ``jacobian`` (coloured central differences of
    the forces), ``mass`` (lumped, rho V / 4 per corner), ``tet_stress``, ``tet_virial``,
    ``net_force_torque``.
    """

    name = ""
    params = {}
    # whether solve_static's load_steps change its answer (a Newton solve in load steps);
    # a simulator run to rest takes its loads in its own ramp
    splits_load = False
    # the smallest change of position the simulator resolves [m] (its arithmetic's), below
    # which run_to_rest cannot ask it to settle
    resolution = 0.0

    def __init__(self, mesh, material, name=None, **params):
        unknown = set(params) - set(self.params)
        if unknown:
            raise ModelError(f"model {self.name!r} has no setting(s) {', '.join(sorted(unknown))};"
                             f" it takes {', '.join(sorted(self.params)) or 'none'}")
        self.mesh, self.material = mesh, material
        self.name = name or self.name
        self.p = {**self.params, **params}
        self.info = {"model": self.name, **self.p}
        self._strain_probe = None

    # ------------------------------------------------------------------ to implement
    def simulate(self, bc_of_t, t_end, dt=None, damping=0.0, f_ext=None, frames=101,
                 x0=None, v0=None, t0=0.0):
        raise NotImplementedError(f"model {self.name!r} does not simulate")

    def tet_forces(self, x):
        raise NotImplementedError

    def stable_dt(self, safety=0.5):
        raise NotImplementedError

    # ------------------------------------------------------------------ what follows
    @property
    def gives_forces(self):
        """Whether the model says its internal forces (it implements ``tet_forces``)."""
        return type(self).tet_forces is not Simulator.tet_forces

    def solve_static(self, bc, f_ext=None, rtol=None, max_iter=None, load_steps=1,
                     on_step=None, stall=None):
        """The equilibrium under ``bc`` and ``f_ext``, run to rest (:func:`run_to_rest`)."""
        return run_to_rest(self, bc, f_ext=f_ext, rtol=rtol)

    def forces(self, x):
        """Internal forces (n, 3) [N] at x; an error for a model that cannot say."""
        if not self.gives_forces:
            raise ModelError(f"model {self.name!r} gives no internal forces (tet_forces)")
        ft = self.tet_forces(np.asarray(x, dtype=float))
        out = np.zeros_like(self.mesh.points)
        np.add.at(out, self.mesh.tets, ft)
        return out

    @property
    def mass(self):
        """Lumped nodal masses (n,) [kg]: a quarter of each tetrahedron's rho V0 per corner."""
        if getattr(self, "_mass", None) is None:
            self._mass = np.zeros(self.mesh.n_nodes)
            np.add.at(self._mass, self.mesh.tets,
                      np.repeat(self.material.rho * self.mesh.volumes[:, None] / 4, 4, 1))
        return self._mass

    def jacobian(self, x):
        """Sparse d f / d x (3n x 3n) of the model's forces, by coloured central differences."""
        from ..static import JacobianPattern, jacobian
        if getattr(self, "_jacobian_pattern", None) is None:    # mesh-only work, once
            self._jacobian_pattern = JacobianPattern(self.mesh)
        return jacobian(self.forces, self.mesh, x, self._jacobian_pattern)

    def tet_stress(self, x):
        """Per-tetrahedron ``max_tau`` = G max |gamma| over the 24 shear strains (the paper's
        Figure 1 measure) and ``pressure`` p = -K (V - V0) / V [Pa]: measures of the positions,
        whatever the model."""
        from ..terms._kernels import volume_gradient_numpy
        from ..terms.shear import Shear
        V, _ = volume_gradient_numpy(np.asarray(x, dtype=np.float64), self.mesh.tets)
        if self._strain_probe is None:
            self._strain_probe = Shear(self.mesh, self.material, reading="corner")
        return {"max_tau": self._strain_probe.max_tau(x),
                "pressure": -self.material.K * (V - self.mesh.volumes) / V}

    def tet_virial(self, x):
        """The model's own stress per tetrahedron (m, 3, 3) [Pa] from the forces it puts on the
        tetrahedron's corners: sigma_t = -(1 / V_t) sym sum_a (x_a - c_t) (x) f_a^(t); None for
        a model without ``tet_forces``."""
        from ..terms._kernels import volume_gradient_numpy
        if not self.gives_forces:
            return None
        x = np.asarray(x, dtype=np.float64)
        ft = self.tet_forces(x)
        xt = x[self.mesh.tets]
        arm = xt - xt.mean(axis=1, keepdims=True)
        V, _ = volume_gradient_numpy(x, self.mesh.tets)
        sigma = -np.einsum("tai,taj->tij", arm, ft) / V[:, None, None]
        return 0.5 * (sigma + np.swapaxes(sigma, 1, 2))

    def net_force_torque(self, x):
        """Net force and torque (about the centroid) of the internal forces at x, absolute and
        relative to sum |f_i| and sum |x_i - c| |f_i|; None for a model without forces."""
        if not self.gives_forces:
            return None
        f = self.forces(x)
        r = x - x.mean(axis=0)
        F, T = f.sum(axis=0), np.cross(r, f).sum(axis=0)
        fs = np.linalg.norm(f, axis=1)
        return {"force": F, "torque": T,
                "force_rel": float(np.linalg.norm(F) / max(fs.sum(), 1e-300)),
                "torque_rel": float(np.linalg.norm(T)
                                    / max((np.linalg.norm(r, axis=1) * fs).sum(), 1e-300))}


# run to rest: the motion still to come, relative to the largest displacement, below which a
# simulator is at rest; and how many of the body's slowest periods it may take
REST_TOL = 1e-3
REST_PERIODS = 200
# periods without the motion shrinking below 0.9 of its least: a simulator that stalls
STALLED = 30
# the loads reach their value over the first period in this many equal steps
RAMP_PIECES = 10


def slowest_frequency(mesh, material, mask=None):
    """The body's lowest angular frequency [rad/s] with the components ``mask`` (n, 3)
    prescribed: linear FEM P1's on the mesh, lumped masses (the same for every simulator);
    where that has none (an unconstrained body) or its solve fails, a quarter shear wave
    across the largest extent, pi c_s / (2 L)."""
    import scipy.sparse as sp
    from scipy.sparse.linalg import eigsh
    from ..terms import make_term
    if mask is not None and mask.any():
        try:
            K = -make_term("fem_linear", mesh, material).tangent(mesh.points).tocsr()
            m = np.zeros(mesh.n_nodes)
            np.add.at(m, mesh.tets, np.repeat(material.rho * mesh.volumes[:, None] / 4, 4, 1))
            free = ~np.asarray(mask).ravel()
            lam = eigsh(K[free][:, free], k=1, M=sp.diags(np.repeat(m, 3)[free]), sigma=0.0,
                        which="LM", return_eigenvectors=False)[0]
            if lam > 0 and math.isfinite(lam):
                return math.sqrt(lam)
        except Exception:       # a singular or failed solve: the estimate below
            pass
    L = float(np.ptp(mesh.points, axis=0).max())
    return math.pi * math.sqrt(material.G / material.rho) / (2.0 * L)


def run_to_rest(sim, bc, f_ext=None, rtol=None):
    """The equilibrium of a simulator under ``bc`` and ``f_ext``, run to rest: the prescribed
    displacements and the loads ramped over the body's slowest period under ``bc``
    (:func:`slowest_frequency`), mass damping twice that frequency (critical for that mode),
    then held, period by period, until the motion still to come (the last period's, continued
    as a geometric series at the ratio of the last two periods') is below ``REST_TOL`` of the
    largest displacement, or a period's motion is below what the simulator resolves. A
    ``ConvergenceError`` after ``REST_PERIODS`` periods, or where the motion has not shrunk
    below 0.9 of its least over ``STALLED`` periods (not coming to rest). The reactions and
    the residual (the largest free-node force) come from the simulator's own forces where it
    gives them (``tet_forces``), NaN where not. ``rtol`` is the static solver's and is not
    used: the rest criterion is the motion's."""
    mesh = sim.mesh
    mask, u_end = bc_arrays(bc, mesh.n_nodes)
    f_ext = np.zeros_like(mesh.points) if f_ext is None else np.asarray(f_ext, dtype=float)
    w = slowest_frequency(mesh, sim.material, mask)
    period = 2.0 * math.pi / w
    held = {int(n): tuple(float(u_end[n, k]) if mask[n, k] else None for k in range(3))
            for n in np.flatnonzero(mask.any(axis=1))}
    ramp = _RampedHeld(held, period)
    x, v = None, None
    for k in range(1, RAMP_PIECES + 1):     # the loads in equal steps (constant over each)
        tr = sim.simulate(ramp, k * period / RAMP_PIECES, damping=2.0 * w,
                          f_ext=k / RAMP_PIECES * f_ext, frames=2, x0=x, v0=v,
                          t0=(k - 1) * period / RAMP_PIECES)
        x, v = tr.x[-1], tr.v
    t = period
    before, least, since = 0.0, math.inf, 0
    floor = 8.0 * sim.resolution
    for _ in range(REST_PERIODS):
        tr = sim.simulate(ramp, t + period, damping=2.0 * w, f_ext=f_ext, frames=2, x0=x, v0=v,
                          t0=t)
        moved = float(np.abs(tr.x[-1] - x).max())
        x, v, t = tr.x[-1], tr.v, t + period
        scale = max(float(np.abs(x - mesh.points).max()), 1e-300)
        ratio = moved / before if before > 0 else math.inf    # inf: the first period
        # the motion still to come, were it to shrink by the same ratio every period
        to_come = moved * ratio / (1.0 - ratio) if ratio < 1.0 else math.inf
        before = moved
        if moved <= floor or to_come <= REST_TOL * scale:
            break
        least, since = (moved, 0) if moved < 0.9 * least else (least, since + 1)
        if since >= STALLED:
            raise ConvergenceError(
                f"{sim.name} is not coming to rest: over its last {STALLED} slowest periods "
                f"its motion did not shrink below 0.9 of its least ({least / scale:.2g} of its "
                f"largest displacement a period)")
    else:
        raise ConvergenceError(f"{sim.name} is not at rest after {REST_PERIODS} of its slowest "
                               f"periods ({REST_PERIODS * period:.3g} s): it moved "
                               f"{moved / scale:.2g} of its largest displacement over the last"
                               + (f", shrinking by {ratio:.3g} a period" if ratio < 1 else ""))
    from ..static import StaticResult
    if not sim.gives_forces:
        reaction, residual = np.full_like(x, np.nan), float("nan")
    else:
        f = sim.forces(x) + f_ext
        reaction = np.where(mask, -f, 0.0)
        residual = float(np.linalg.norm(np.where(mask, 0.0, f), axis=1).max())
    return StaticResult(x=x, u=x - mesh.points, reaction=reaction, residual=residual,
                        tol=max(REST_TOL * scale, floor), iterations=int(round(t / period)))


class _RampedHeld:
    """bc_of_t: the displacements ``held`` reached linearly over ``t_ramp``, then held."""

    def __init__(self, held, t_ramp):
        self.held, self.t_ramp = held, t_ramp
        self._end = (None,)

    def __call__(self, t):
        s = min(max(t / self.t_ramp, 0.0), 1.0)
        return {n: tuple(None if u is None else s * u for u in c) for n, c in self.held.items()}

    def arrays(self, t, n_nodes):
        """(mask, displacement) at t, as bc_arrays(self(t), n_nodes) gives them (the end state
        scaled, no mapping rebuilt)."""
        if self._end[0] != n_nodes:
            self._end = (n_nodes, *bc_arrays(self.held, n_nodes))
        _, mask, end = self._end
        return mask, min(max(t / self.t_ramp, 0.0), 1.0) * end

