"""A simulator pbcm does not integrate itself, as one adapter file: symplectic (semi-implicit)
Euler on the small-strain forces of FEM P1, the step most real-time engines take.

    pbcm run paper-cube --quick --model-file docs/example_simulator.py \\
        --models symplectic-p1 fem-linear

Its contract is ``model.simulators.Simulator``: ``simulate`` gives positions over time,
``tet_forces`` (optional) the forces each tetrahedron puts on its corners; the static
equilibrium then comes by running it to rest, and the reactions and stresses from its forces.
"""
import math

import numpy as np

from model.bc import bc_arrays
from model.integrate import Trajectory
from model.simulators import Simulator, register
from model.terms._kernels import deformation_gradients_numpy, piola_tet_forces, \
    rest_shape_inverse


@register
class SymplecticP1(Simulator):
    """v += dt (f / m - damping v); x += dt v, the prescribed components set after each step."""

    name = "symplectic-p1"
    params = {"safety": 0.5}      # the fraction of the stable step h_min / c_p it takes

    def __init__(self, mesh, material, label=None, **params):
        super().__init__(mesh, material, label, **params)
        self.Dinv = rest_shape_inverse(mesh.points, mesh.tets)

    def stable_dt(self, safety=None):
        from model.geometry import smallest_heights
        h = float(smallest_heights(self.mesh.points, self.mesh.tets).min())
        return (self.p["safety"] if safety is None else safety) * h \
            / self.material.p_wave_speed

    def tet_forces(self, x):
        """Small strain: P = 2 mu eps + lam tr(eps) I, eps = sym(F) - I."""
        F = deformation_gradients_numpy(x, self.mesh.tets, self.Dinv)
        eps = 0.5 * (F + np.swapaxes(F, 1, 2)) - np.eye(3)
        mu, lam = self.material.G, self.material.lam
        P = 2.0 * mu * eps + lam * np.trace(eps, axis1=1, axis2=2)[:, None, None] * np.eye(3)
        return piola_tet_forces(P, self.Dinv, self.mesh.volumes)

    def simulate(self, bc_of_t, t_end, dt=None, damping=0.0, f_ext=None, frames=101,
                 x0=None, v0=None, t0=0.0):
        X, n = self.mesh.points, self.mesh.n_nodes
        dt = self.stable_dt() if dt is None else dt
        steps = max(1, math.ceil((t_end - t0) / dt - 1e-9))
        dt = (t_end - t0) / steps
        f_ext = np.zeros_like(X) if f_ext is None else f_ext
        x = X.copy() if x0 is None else np.array(x0, dtype=float)
        v = np.zeros_like(X) if v0 is None else np.array(v0, dtype=float)
        m = self.mass[:, None]
        keep = np.linspace(0, steps, max(frames, 2)).round().astype(int)
        ts, xs, rs = [], [], []
        u_before = None
        for k in range(steps + 1):
            t = t0 + k * dt
            mask, u = bc_arrays(bc_of_t(t), n)
            if k:
                v = v + dt * ((self.forces(x) + f_ext) / m - damping * v)
                x = x + dt * v
                v[mask] = ((u - u_before) / dt)[mask]
            x[mask] = (X + u)[mask]
            u_before = u
            if k in keep:
                ts.append(t)
                xs.append(x.copy())
                rs.append(np.where(mask, -(self.forces(x) + f_ext), 0.0))
        return Trajectory(t=np.array(ts), x=np.array(xs), reaction=np.array(rs), dt=dt,
                          steps=steps, v=v)
