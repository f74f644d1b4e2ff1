"""Linear elastodynamics (scikit-fem): the transient FEM reference of the particle runs.

    M a + zeta M v + K u = f,     u = u_D(t) on the prescribed dofs

integrated with Newmark's average acceleration (beta = 1/4, gamma = 1/2): unconditionally
stable, second order, and energy conserving without damping. ``zeta`` is the mass-proportional
damping rate [1/s] of the particle runs (MODEL.md "Time integration"): every mode decays as
exp(-zeta t / 2).
"""
from dataclasses import dataclass
import math

import numpy as np
import scipy.sparse as sp
from skfem import asm

from model.bc import bc_arrays
from model.errors import MaterialError, ModelError
from .fem import (dirichlet_dofs, dof_hats, element_basis, lame, skfem_mesh, spd_factor,
                  stiffness)
from .linear import body_load, dof_component
from .modal import lumped, mass_form


@dataclass
class DynamicResult:
    """``t`` (k,) frame times [s]; ``u`` and ``v`` (k, n, 3) displacements [m] and velocities
    [m/s] at the input nodes;
    ``reaction`` (k, n, 3) the force the supports exert on the body on the prescribed
    components [N] (elastic force plus the inertia and damping the free dofs couple into the
    prescribed ones; the prescribed dofs' own inertia excluded, as in the particle runs);
    ``kinetic`` and ``strain`` (k,) energies [J]; ``dt`` the step; ``info``."""

    t: np.ndarray
    u: np.ndarray
    v: np.ndarray
    reaction: np.ndarray
    kinetic: np.ndarray
    strain: np.ndarray
    dt: float
    info: dict


def solve(mesh, E, nu, rho, dirichlet_of_t, t_end, dt=None, damping=0.0, element="P1",
          mass="consistent", u0=None, v0=None, body_force=None, frames=None):
    """Integrate from rest (or ``u0``, ``v0`` (n, 3) at the input nodes) to ``t_end`` [s].

    Parameters
    ----------
    dirichlet_of_t : callable t -> mapping node -> (ux, uy, uz) (None for a free component),
        the same ``bc_of_t`` the particle model takes (e.g. ``model.bc.Ramp``); the set of
        prescribed components must not change. P2 midpoints follow
        ``reference.fem.prescribed_edges`` at every step.
    dt : the step [s]; default half the P-wave transit time of the smallest tetrahedron
        height, halved again for P2 (the explicit limit: every mode the mesh resolves is
        resolved in time; the trapezoidal rule hardly damps modes it does not resolve).
    damping : mass-proportional damping rate zeta [1/s].
    element : "P1" or "P2" on the input mesh; mass : "consistent" or "lumped" (HRZ).
    body_force : (3,) [N/m^3] or a callable of the points, constant in time.
    frames : None for every step, or the number of frames to keep (equally spaced steps).
    """
    lam, mu = lame(E, nu)
    if not (np.isfinite(rho) and rho > 0):
        raise MaterialError(f"density rho must be > 0 kg/m^3, got {rho!r}")
    if mass not in ("consistent", "lumped"):
        raise ModelError(f"mass must be 'consistent' or 'lumped', got {mass!r}")
    if not (math.isfinite(t_end) and t_end > 0):
        raise ModelError(f"t_end must be a positive time in seconds, got {t_end!r}")
    if not (math.isfinite(damping) and damping >= 0):
        raise ModelError(f"damping must be a rate >= 0 in 1/s, got {damping!r}")
    if dt is None:   # P2 resolves modes about twice as high: half the step
        from model.geometry import smallest_heights
        c_p = math.sqrt((lam + 2 * mu) / rho)
        h = float(smallest_heights(mesh.points, mesh.tets).min())
        dt = 0.5 * h / c_p / (2 if element == "P2" else 1)
    if not (math.isfinite(dt) and dt > 0):
        raise ModelError(f"dt must be a positive time in seconds, got {dt!r}")
    steps = max(1, math.ceil(t_end / dt - 1e-9))
    dt = t_end / steps

    m = skfem_mesh(mesh)
    basis = element_basis(m, element)
    K = stiffness(basis, lam, mu)
    M = rho * asm(mass_form, basis)
    M = (lumped(M) if mass == "lumped" else M).tocsr()
    f = body_load(basis, body_force) if body_force is not None else np.zeros(basis.N)
    n = mesh.n_nodes

    def prescribed(t):
        mask, vals = bc_arrays(dirichlet_of_t(t), n)
        D, x = dirichlet_dofs(basis, mask, vals, None)
        return mask, D, x

    if hasattr(dirichlet_of_t, "parts"):
        # a Ramp: its dof values are start + scale(t) moving, the dof values being linear in
        # the nodal ones (P2 midpoints take the mean of their ends), so two evaluations serve
        # every step
        mask0, start, moving = dirichlet_of_t.parts(n)
        D, x_start = dirichlet_dofs(basis, mask0, start, None)
        x_start, x_moving = x_start[D], dirichlet_dofs(basis, mask0, moving, None)[1][D]

        def path(t):
            return x_start + dirichlet_of_t.scale(t) * x_moving
    else:
        mask0, D, _ = prescribed(0.0)

        def path(t):
            mask, D_t, x = prescribed(t)
            if not np.array_equal(mask, mask0):
                raise ModelError(f"dirichlet_of_t({t:g}) prescribes other components than at "
                                 "t = 0; the set of prescribed components must stay the same")
            return x[D]
    I = np.setdiff1d(np.arange(basis.N), D)

    # the prescribed velocity and acceleration: central differences of the path over one step
    # (exact on a piecewise-linear path but for its kinks; at t = 0 the path's own slope)
    def path_rates(t):
        now, after = path(t), path(t + dt)
        if t <= 0.0:
            return now, (after - now) / dt, np.zeros_like(now)
        before = path(t - dt)
        return now, (after - before) / (2 * dt), (after - 2 * now + before) / dt**2

    u, v, a = np.zeros(basis.N), np.zeros(basis.N), np.zeros(basis.N)
    for name, given, target in (("u0", u0, u), ("v0", v0, v)):
        if given is not None:
            g = np.asarray(given, dtype=float)
            if g.shape != (n, 3) or not np.isfinite(g).all():
                raise ModelError(f"{name} must be a finite (n, 3) array for {n} nodes, got "
                                 f"shape {g.shape}")
            target[basis.nodal_dofs[:, :n].T.ravel()] = g.ravel()
            if basis.edge_dofs.size:   # P2 midpoints: the mean of the edge's two ends
                e = m.edges
                target[basis.edge_dofs.T.ravel()] = (0.5 * (g[e[0]] + g[e[1]])).ravel()
    u[D], v[D], a[D] = path_rates(0.0)
    K_II, K_ID, M_II, M_ID = K[I][:, I], K[I][:, D], M[I][:, I], M[I][:, D]
    # initial acceleration of the free dofs from the equation of motion
    rhs0 = f[I] - K[I] @ u - damping * (M[I] @ v) - M_ID @ a[D]
    a[I] = spd_factor(M_II).solve(rhs0)

    c1 = 4.0 / dt**2 + 2.0 * damping / dt
    lu = spd_factor(K_II + c1 * M_II)

    keep = (np.arange(steps + 1) if frames is None else
            np.unique(np.linspace(0, steps, max(int(frames), 2)).round().astype(int)))
    ts, us, vs, rs, kin, pot = [], [], [], [], [], []
    K_D, M_DI, nodal = K[D], M[D][:, I], basis.nodal_dofs[:, :n]
    to_nodes = _transfer(basis, D, n)

    def record(k):
        ts.append(k * dt)
        us.append(u[nodal].T.copy())
        vs.append(v[nodal].T.copy())
        rs.append(to_nodes(K_D @ u - f[D] + M_DI @ (a[I] + damping * v[I])))
        kin.append(0.5 * v @ (M @ v))
        pot.append(0.5 * u @ (K @ u))

    record(0)
    f_I = f[I]
    for k in range(1, steps + 1):
        uD, vD, aD = path_rates(k * dt)
        uI, vI, aI = u[I], v[I], a[I]
        rhs = (f_I - K_ID @ uD - M_ID @ (aD + damping * vD)
               + M_II @ (4.0 / dt**2 * (uI + dt * vI) + aI + damping * (2.0 / dt * uI + vI)))
        uI1 = lu.solve(rhs)
        aI1 = 4.0 / dt**2 * (uI1 - uI - dt * vI) - aI
        v[I] = vI + 0.5 * dt * (aI + aI1)
        u[I], a[I] = uI1, aI1
        u[D], v[D], a[D] = uD, vD, aD
        if k in keep:
            record(k)
    return DynamicResult(t=np.array(ts), u=np.array(us), v=np.array(vs), reaction=np.array(rs),
                         kinetic=np.array(kin), strain=np.array(pot), dt=dt,
                         info={"element": element, "mass": mass, "dofs": int(basis.N),
                               "steps": steps, "damping": damping})


def _transfer(basis, D, n):
    """values on the prescribed dofs -> (n, 3) forces at the input nodes, by the input
    mesh's P1 hats (reference.linear.transfer_to_nodes, its matrices built once)."""
    hats = dof_hats(basis, sp.identity(n, format="csr"))[D]
    comp = dof_component(basis)[D]
    parts = [(k, comp == k, hats[comp == k].T.tocsr()) for k in range(3)]

    def to_nodes(values):
        out = np.zeros((n, 3))
        for k, sel, H in parts:
            out[:, k] = H @ values[sel]
        return out
    return to_nodes
