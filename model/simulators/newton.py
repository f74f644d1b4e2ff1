"""The Newton engine's soft-body solvers as models (``pip install "pbcm[engines]"``).

Newton (on NVIDIA Warp) integrates tetrahedral soft bodies with three solvers, each a model here:

* ``newton-semi-implicit``: symplectic Euler on the forces of its ``eval_tetrahedra`` kernel, the
  stable neo-Hookean of B. Smith, F. de Goes and T. Kim, "Stable Neo-Hookean flesh simulation",
  ACM TOG 37(2), 2018, written as W = V0 [mu/2 (I_C - 3) - mu/2 ln(I_C + 1) + lam/2 (J - a)^2],
  a = 1 + 3 mu / (4 lam); explicit, at its own stable step;
* ``newton-xpbd``: extended position-based dynamics, each tetrahedron two constraints,
  C_dev = I_C - 3 and C_vol = J - 1, with compliances 1 / (V0 mu) and 1 / (V0 lam): the energy
  its iterations approach is W = V0 [mu/2 (I_C - 3)^2 + lam/2 (J - 1)^2];
* ``newton-vbd``: vertex block descent on W = V0 [mu/2 (I_C - 3) + (lam + mu)/2 (J - a)^2],
  a = 1 + mu / (lam + mu).

Newton's documentation calls ``k_mu`` and ``k_lambda`` the material's Lame parameters; they are
mapped so: k_mu = G, k_lambda = lam of the material's E and nu (:func:`lame`). Each law above is
transcribed from the engine's kernels (Newton 1.8) as :func:`piola`; its forces give the
reactions, the residual and the stresses a report needs, and the tests check them against the
engine's own. What that mapping makes of each law at small strain is a finding, not a choice
(the tests state it): VBD's is linear elasticity with (G, lam); the semi-implicit law's shear
modulus is 3/4 G; XPBD's constraints have no shear stiffness at first order.

The engine runs in single precision on Warp's CPU backend (or a GPU): positions resolve about
1e-7 of the body's size. Collisions are off (a body alone, no contact). The settings: the
solver iterations per step (XPBD, VBD) and the substeps of a frame (1/60 s), stated in each
run's ``info``.
"""
import math

import numpy as np

from ..bc import path
from ..errors import BlowUpError, ModelError
from ..geometry import smallest_heights
from ..terms._kernels import deformation_gradients_numpy, piola_tet_forces, rest_shape_inverse
from . import register
from .base import Simulator

FRAME_S = 1.0 / 60.0
SOLVERS = ("newton-semi-implicit", "newton-xpbd", "newton-vbd")
# the iteration counts at which pbcm measures each iterative solver: its default, then up by 4x
LADDER = {"newton-xpbd": (2, 8, 32), "newton-vbd": (10, 40, 160)}


def installed():
    """Whether the engines extra (newton, on warp) is installed."""
    import importlib.util
    return importlib.util.find_spec("newton") is not None


def spec(solver, iterations):
    """The model name of ``solver`` at ``iterations`` (at its default: the plain name)."""
    ladder = LADDER.get(solver)
    if ladder is None or iterations == ladder[0]:
        return solver
    return f"{solver}(iterations={iterations})"


def ladder_models(rungs=None):
    """The solvers as models: the semi-implicit one, each iterative one at the first ``rungs``
    of its ladder (every rung without)."""
    out = ["newton-semi-implicit"]
    for solver, counts in LADDER.items():
        out += [spec(solver, n) for n in counts[:rungs]]
    return tuple(out)


def lame(material):
    """(k_mu, k_lambda) as Newton's documentation defines them: the Lame parameters G and
    lam of the material."""
    return material.G, material.lam


def cofactor(F):
    """cof(F) = det(F) F^-T (m, 3, 3): column j is the cross product of the two other columns."""
    c = [F[:, :, j] for j in range(3)]
    return np.stack([np.cross(c[1], c[2]), np.cross(c[2], c[0]), np.cross(c[0], c[1])], axis=2)


def piola(solver, F, mu, lam):
    """The first Piola-Kirchhoff stress (m, 3, 3) of ``solver``'s law (the module's docstring)
    at F, with Newton's k_mu = mu and k_lambda = lam."""
    Ic = np.einsum("tij,tij->t", F, F)[:, None, None]
    J = np.linalg.det(F)[:, None, None]
    cof = cofactor(F)
    if solver == "semi-implicit":
        a = 1.0 + 3.0 * mu / (4.0 * lam)
        return mu * (1.0 - 1.0 / (Ic + 1.0)) * F + lam * (J - a) * cof
    if solver == "vbd":
        lam_nh = lam + mu
        return mu * F + lam_nh * (J - (1.0 + mu / lam_nh)) * cof
    if solver == "xpbd":
        return 2.0 * mu * (Ic - 3.0) * F + lam * (J - 1.0) * cof
    raise ModelError(f"no Newton solver {solver!r}")


def small_strain_moduli(solver, material, e=1e-6):
    """(shear modulus, Lame lambda) [Pa] of ``solver``'s law at small strain with the material
    mapped by :func:`lame`, read off its stress under a pure shear and a pure dilatation e."""
    shear = np.eye(3)[None].copy()
    shear[0, 0, 1] = shear[0, 1, 0] = e
    mu, lam = lame(material)
    P_s = piola(solver, shear, mu, lam)[0]
    P_d = piola(solver, (1.0 + e) * np.eye(3)[None], mu, lam)[0]
    G = P_s[0, 1] / (2.0 * e)
    return G, (P_d[0, 0] / e - 2.0 * G) / 3.0      # a dilatation e: P = (3 lam + 2 G) e I


def import_newton():
    """(newton, warp), or a ModelError saying how to install them."""
    try:
        import warp as wp
        wp.config.quiet = True
        import newton
    except ImportError as exc:
        raise ModelError(f"the Newton models need the engines extra: pip install "
                         f"\"pbcm[engines]\" ({exc})") from None
    return newton, wp


class NewtonModel(Simulator):
    """One of Newton's soft-body solvers on the mesh, with the material mapped by :func:`lame`."""

    solver = ""
    params = {"substeps": 10}

    def __init__(self, mesh, material, name=None, **params):
        super().__init__(mesh, material, name, **params)
        for k, v in self.p.items():
            if not (isinstance(v, int) and not isinstance(v, bool) and v >= 1):
                raise ModelError(f"{self.name} {k} must be an integer >= 1, got {v!r}")
        newton, wp = import_newton()
        mu, lam = lame(material)
        self.mu, self.lam = mu, lam
        b = newton.ModelBuilder(gravity=(0.0, 0.0, 0.0))
        b.add_soft_mesh(pos=(0.0, 0.0, 0.0), rot=wp.quat_identity(), scale=1.0,
                        vel=(0.0, 0.0, 0.0), vertices=[tuple(p) for p in mesh.points],
                        indices=mesh.tets.ravel().tolist(), density=material.rho, k_mu=mu,
                        k_lambda=lam, k_damp=0.0)
        if self.solver == "vbd":
            b.color()
        m = b.finalize(device="cpu")
        m.particle_grid = None          # a body alone: no particle contacts
        m.particle_max_radius = 0.0
        self._model = m
        self._engine_mass = m.particle_mass.numpy().copy(), m.particle_inv_mass.numpy().copy()
        self._solver = self._make_solver(newton)
        self.Dinv = rest_shape_inverse(mesh.points, mesh.tets)
        self.resolution = float(np.finfo(np.float32).eps * np.abs(mesh.points).max())
        self.info.update(engine=f"newton {newton.__version__}", solver=self.solver,
                         k_mu=mu, k_lambda=lam, dt=self.stable_dt(), precision="float32")

    def _make_solver(self, newton):
        raise NotImplementedError

    def stable_dt(self, safety=None):
        """A frame (1/60 s) over ``substeps`` (``safety``, the explicit models' factor on their
        stable step, does not apply)."""
        return FRAME_S / self.p["substeps"]

    def tet_forces(self, x):
        F = deformation_gradients_numpy(np.asarray(x, dtype=float), self.mesh.tets, self.Dinv)
        return piola_tet_forces(piola(self.solver, F, self.mu, self.lam), self.Dinv,
                                self.mesh.volumes)

    def simulate(self, bc_of_t, t_end, dt=None, damping=0.0, f_ext=None, frames=101,
                 x0=None, v0=None, t0=0.0):
        """The engine's steps from t0 to t_end; the prescribed components set before and after
        every step (a node prescribed whole is kinematic: no mass to the solver), the loads
        ``f_ext`` as the engine's external particle forces, the mass damping applied to the
        velocities after every step (exactly: v times exp(-damping dt))."""
        mesh = self.mesh
        if not (t_end > t0 and math.isfinite(t_end)):
            raise ModelError(f"t_end must be a time in seconds after t0 = {t0}, got {t_end!r}")
        dt = self.stable_dt() if dt is None else float(dt)
        steps = max(1, math.ceil((t_end - t0) / dt - 1e-9))
        dt = (t_end - t0) / steps
        mask, prescribed = path(bc_of_t, mesh.n_nodes, t0)
        X = mesh.points
        f_ext = np.zeros_like(X) if f_ext is None else np.asarray(f_ext, dtype=float)
        m = self._model
        mass, inv_mass = (a.copy() for a in self._engine_mass)
        mass[mask.all(axis=1)] = inv_mass[mask.all(axis=1)] = 0.0   # VBD reads the one, XPBD
        m.particle_mass.assign(mass)                                 # the other
        m.particle_inv_mass.assign(inv_mass)
        s0, s1, control = m.state(), m.state(), m.control()
        s0.particle_q.assign((X if x0 is None else np.asarray(x0)).astype(np.float32))
        s0.particle_qd.assign(np.zeros_like(X, dtype=np.float32) if v0 is None
                              else np.asarray(v0).astype(np.float32))

        def prescribe(state, t):
            u, u_next = prescribed(t), prescribed(t + dt)
            q, qd = state.particle_q.numpy(), state.particle_qd.numpy()   # views on the CPU
            q[mask] = (X + u)[mask]
            qd[mask] = ((u_next - u) / dt)[mask]

        frame_steps = set(np.unique(np.linspace(0, steps, max(int(frames), 2)).round()
                                    .astype(int)).tolist())
        ts, xs, rs = [], [], []
        f32 = f_ext.astype(np.float32)
        keep = math.exp(-damping * dt)
        prescribe(s0, t0)
        for k in range(steps + 1):
            if k in frame_steps:
                x = s0.particle_q.numpy().astype(np.float64)
                ts.append(t0 + k * dt)
                xs.append(x)
                rs.append(np.where(mask, -(self.forces(x) + f_ext), 0.0))
            if k == steps:
                break
            s0.clear_forces()
            s0.particle_f.assign(f32)
            self._solver.step(s0, s1, control, None, dt)
            s0, s1 = s1, s0
            prescribe(s0, t0 + (k + 1) * dt)
            if keep != 1.0:
                qd = s0.particle_qd.numpy()
                qd[~mask] *= keep
            if not np.isfinite(s0.particle_q.numpy()).all():
                raise BlowUpError(f"{self.name} blew up at step {k + 1} (t = "
                                  f"{t0 + (k + 1) * dt:.6g} s, dt = {dt:.3g} s): NaN or inf in "
                                  f"the state; try dt = {dt / 4:.3g} s", k + 1,
                                  t0 + (k + 1) * dt, dt / 4)
        from ..integrate import Trajectory
        return Trajectory(t=np.array(ts), x=np.array(xs), reaction=np.array(rs), dt=dt,
                          steps=steps, v=s0.particle_qd.numpy().astype(np.float64))


@register
class NewtonSemiImplicit(NewtonModel):
    """Newton's semi-implicit (symplectic Euler) solver, explicit, at its own stable step."""

    name, solver = "newton-semi-implicit", "semi-implicit"
    params = {}

    def _make_solver(self, newton):
        return newton.solvers.SolverSemiImplicit(self._model, enable_tri_contact=False)

    def stable_dt(self, safety=0.5):
        """safety * min_T h_T / c_p, as pbcm's explicit models."""
        return safety * float(smallest_heights(self.mesh.points, self.mesh.tets).min()) \
            / self.material.p_wave_speed


@register
class NewtonXPBD(NewtonModel):
    """Newton's extended position-based dynamics (XPBD).

    Defaults: the engine's 2 iterations per step; 32 substeps of a frame, its rigid-soft
    contact example's (at 10 its Jacobi iterations diverge on the library's cubes)."""

    name, solver = "newton-xpbd", "xpbd"
    params = {"substeps": 32, "iterations": 2}

    def _make_solver(self, newton):
        return newton.solvers.SolverXPBD(self._model, iterations=self.p["iterations"])


@register
class NewtonVBD(NewtonModel):
    """Newton's vertex block descent (VBD).

    Defaults: the engine's 10 iterations per step; 10 substeps of a frame, its hanging soft-body
    example's."""

    name, solver = "newton-vbd", "vbd"
    params = {"substeps": 10, "iterations": 10}

    def _make_solver(self, newton):
        return newton.solvers.SolverVBD(self._model, iterations=self.p["iterations"])
