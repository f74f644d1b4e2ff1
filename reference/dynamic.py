"""Linear elastodynamics (scikit-fem): the transient FEM reference of the particle runs.

    M a + zeta M v + K u = f,     u = u_D(t) on the prescribed dofs

integrated with Newmark's average acceleration (beta = 1/4, gamma = 1/2): unconditionally
stable, second order, and energy conserving without damping; or, for a ramped boundary
motion, solved exactly in time by superposing every mode (``method="modal"``). ``zeta`` is
the mass-proportional damping rate [1/s] of the particle runs (docs/model.md "Time integration"):
every mode decays as exp(-zeta t / 2).
"""
from dataclasses import dataclass
import math

import numpy as np
import scipy.linalg
import scipy.sparse as sp

from model.bc import bc_arrays
from model.errors import ModelError
from model.material import as_material
from .assembly import stiffness
from .discretisation import dirichlet_dofs, dof_hats, element_basis, skfem_mesh
from .linear import body_load, dof_component
from .modal import lumped, mass_matrix
from .solvers import spd_factor

# a mode whose stiffness is below this fraction of the largest is a rigid motion
RIGID_TOL = 1e-12


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


def solve(mesh, material, dirichlet_of_t, t_end, dt=None, damping=0.0, element="P1",
          mass="consistent", u0=None, v0=None, body_force=None, frames=None, method="newmark"):
    """Integrate from rest (or ``u0``, ``v0`` (n, 3) at the input nodes) to ``t_end`` [s].

    Parameters
    ----------
    material : the model.material.Material (E [Pa], nu, rho [kg/m^3]).
    dirichlet_of_t : callable t -> mapping node -> (ux, uy, uz) (None for a free component),
        the same ``bc_of_t`` the particle model takes (e.g. ``model.bc.Ramp``); the set of
        prescribed components must not change. P2 midpoints follow
        ``reference.discretisation.prescribed_edges`` at every step.
    dt : the step [s] of method "newmark"; default half the P-wave transit time of the
        smallest tetrahedron height, halved again for P2 (the explicit limit: every mode the
        mesh resolves is resolved in time; the trapezoidal rule hardly damps modes it does not
        resolve).
    damping : mass-proportional damping rate zeta [1/s].
    element : "P1" or "P2" on the input mesh; mass : "consistent" or "lumped" (HRZ).
    body_force : (3,) [N/m^3] or a callable of the points, constant in time.
    frames : None for every step, or the number of frames to keep (equally spaced steps);
        for "modal", the number of equally spaced frames (default 101).
    method : "newmark" (any ``dirichlet_of_t``) or "modal": exact in time for a
        ``model.bc.Ramp``, by superposition of every mode of the semi-discrete system
        (:func:`modal_ramp`); no step, so no step error and no cost growing with the mesh's
        smallest tetrahedron.
    """
    material = as_material(material, "reference.dynamic.solve")
    if method not in ("newmark", "modal"):
        raise ModelError(f"method must be 'newmark' or 'modal', got {method!r}")
    lam, mu, rho = *material.lame, material.rho
    if mass not in ("consistent", "lumped"):
        raise ModelError(f"mass must be 'consistent' or 'lumped', got {mass!r}")
    if not (math.isfinite(t_end) and t_end > 0):
        raise ModelError(f"t_end must be a positive time in seconds, got {t_end!r}")
    if not (math.isfinite(damping) and damping >= 0):
        raise ModelError(f"damping must be a rate >= 0 in 1/s, got {damping!r}")
    if method == "modal":
        if dt is not None:
            raise ModelError("dt is the step of method 'newmark'; method 'modal' is exact in "
                             "time and takes no step: leave dt out")
        if not (hasattr(dirichlet_of_t, "parts") and hasattr(dirichlet_of_t, "t_ramp")):
            raise ModelError("method 'modal' needs a model.bc.Ramp as dirichlet_of_t (its "
                             "path is piecewise linear in time, which the closed form needs); "
                             "use method 'newmark' for another motion")
    if dt is None and method == "newmark":   # P2 resolves modes about twice as high
        from model.geometry import smallest_heights
        c_p = math.sqrt((lam + 2 * mu) / rho)
        h = float(smallest_heights(mesh.points, mesh.tets).min())
        dt = 0.5 * h / c_p / (2 if element == "P2" else 1)
    if method == "newmark" and not (math.isfinite(dt) and dt > 0):
        raise ModelError(f"dt must be a positive time in seconds, got {dt!r}")

    m = skfem_mesh(mesh)
    basis = element_basis(m, element)
    K = stiffness(basis, lam, mu)
    M = mass_matrix(m, element, rho)
    M = (lumped(M) if mass == "lumped" else M).tocsr()
    f = body_load(basis, body_force) if body_force is not None else np.zeros(basis.N)
    u, v = _initial_state(basis, mesh.n_nodes, u0, v0)
    system = _System(basis, K, M, f, damping, mesh.n_nodes, element, mass)
    if method == "modal":
        return modal_ramp(system, dirichlet_of_t, t_end, u, v,
                          frames=101 if frames is None else frames)
    return _newmark(system, dirichlet_of_t, t_end, dt, u, v, frames)


@dataclass
class _System:
    """The semi-discrete system M a + zeta M v + K u = f on ``basis`` and what turns its dof
    vectors into results at the input nodes."""
    basis: object
    K: sp.csr_matrix
    M: sp.csr_matrix
    f: np.ndarray
    damping: float
    n: int          # input mesh nodes
    element: str
    mass: str

    def result(self, D, t, u, v, a_I, I, dt, info):
        """The DynamicResult of frames ``t`` with dof vectors ``u``, ``v`` (k, N) and free
        accelerations ``a_I`` (k, len(I)): reactions as the supports exert them (elastic
        force plus the inertia and damping the free dofs couple into the prescribed ones)."""
        nodal = self.basis.nodal_dofs[:, :self.n]
        to_nodes = _transfer(self.basis, D, self.n)
        M_DI = self.M[D][:, I]
        r = (self.K[D] @ u.T).T - self.f[D] + (M_DI @ (a_I + self.damping * v[:, I]).T).T
        return DynamicResult(
            t=np.asarray(t, dtype=float), u=np.moveaxis(u[:, nodal], 1, 2).copy(),
            v=np.moveaxis(v[:, nodal], 1, 2).copy(),
            reaction=np.array([to_nodes(row) for row in r]),
            kinetic=0.5 * np.einsum("ki,ki->k", v, (self.M @ v.T).T),
            strain=0.5 * np.einsum("ki,ki->k", u, (self.K @ u.T).T), dt=dt,
            info={**info, "element": self.element, "mass": self.mass,
                  "dofs": int(self.basis.N), "damping": self.damping})


def _initial_state(basis, n, u0, v0):
    """Dof vectors of the initial displacement and velocity given at the input nodes (P2
    midpoints take the mean of the edge's two ends)."""
    u, v = np.zeros(basis.N), np.zeros(basis.N)
    for name, given, target in (("u0", u0, u), ("v0", v0, v)):
        if given is not None:
            g = np.asarray(given, dtype=float)
            if g.shape != (n, 3) or not np.isfinite(g).all():
                raise ModelError(f"{name} must be a finite (n, 3) array for {n} nodes, got "
                                 f"shape {g.shape}")
            target[basis.nodal_dofs[:, :n].T.ravel()] = g.ravel()
            if basis.edge_dofs.size:
                e = basis.mesh.edges
                target[basis.edge_dofs.T.ravel()] = (0.5 * (g[e[0]] + g[e[1]])).ravel()
    return u, v


def _ramp_dofs(basis, ramp, n):
    """(D, x_start, x_moving): a Ramp's prescribed dofs and their values start +
    scale(t) moving (dof values are linear in the nodal ones: P2 midpoints take the mean of
    their ends)."""
    mask0, start, moving = ramp.parts(n)
    D, x_start = dirichlet_dofs(basis, mask0, start, None)
    return D, x_start[D], dirichlet_dofs(basis, mask0, moving, None)[1][D]


def _newmark(system, dirichlet_of_t, t_end, dt, u, v, frames):
    basis, K, M, f, damping = system.basis, system.K, system.M, system.f, system.damping
    n = system.n
    steps = max(1, math.ceil(t_end / dt - 1e-9))
    dt = t_end / steps

    def prescribed(t):
        mask, vals = bc_arrays(dirichlet_of_t(t), n)
        D, x = dirichlet_dofs(basis, mask, vals, None)
        return mask, D, x

    if hasattr(dirichlet_of_t, "parts"):   # a Ramp: two evaluations serve every step
        D, x_start, x_moving = _ramp_dofs(basis, dirichlet_of_t, n)

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

    a = np.zeros(basis.N)
    u[D], v[D], a[D] = path_rates(0.0)
    K_II, K_ID, M_II, M_ID = K[I][:, I], K[I][:, D], M[I][:, I], M[I][:, D]
    # initial acceleration of the free dofs from the equation of motion
    rhs0 = f[I] - K[I] @ u - damping * (M[I] @ v) - M_ID @ a[D]
    a[I] = spd_factor(M_II).solve(rhs0)

    c1 = 4.0 / dt**2 + 2.0 * damping / dt
    lu = spd_factor(K_II + c1 * M_II)

    keep = (np.arange(steps + 1) if frames is None else
            np.unique(np.linspace(0, steps, max(int(frames), 2)).round().astype(int)))
    us, vs, aIs = [u.copy()], [v.copy()], [a[I].copy()]
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
            us.append(u.copy())
            vs.append(v.copy())
            aIs.append(aI1.copy())
    return system.result(D, keep * dt, np.array(us), np.array(vs), np.array(aIs), I, dt,
                         {"steps": steps, "method": "newmark"})


def modal_ramp(system, ramp, t_end, u, v, frames):
    """Exact-in-time response of the semi-discrete system to a Ramp, by superposition of
    every mode of the free dofs.

    With K_II phi = omega^2 M_II phi (phi M_II-orthonormal, dense generalised eigenproblem),
    each modal coordinate obeys eta'' + zeta eta' + omega^2 eta = a + b t between the ramp's
    kinks, with a and b from the prescribed path u_D = x_start + s(t) x_moving:
    ``a = phi.(f_I - K_ID x_start) - zeta s' phi.M_ID x_moving`` and
    ``b t = -s(t) phi.K_ID x_moving``. Each interval is the particular solution
    A + B t plus the free response (:func:`_free_response`); at the end of the ramp the kink
    s'' = -delta(t - T) / T through the consistent mass gives eta' a jump of
    phi.M_ID x_moving / T. At t = 0 the boundary starts moving with the free dofs at rest (as
    the Newmark path does). A frame at the kink takes the state just after it.
    """
    basis, K, M, f, zeta = system.basis, system.K, system.M, system.f, system.damping
    n = system.n
    D, x_start, x_moving = _ramp_dofs(basis, ramp, n)
    I = np.setdiff1d(np.arange(basis.N), D)
    K_II, K_ID, M_II, M_ID = K[I][:, I], K[I][:, D], M[I][:, I], M[I][:, D]
    w2, phi = scipy.linalg.eigh(K_II.toarray(), M_II.toarray())
    if not w2[0] > RIGID_TOL * w2[-1]:
        raise ModelError("the prescribed components leave the body free to move rigidly (a "
                         "zero stiffness mode); method 'modal' needs a constrained body: use "
                         "method 'newmark'")
    w2 = np.maximum(w2, 0.0)
    PhiM = phi.T @ M_II
    f0 = phi.T @ (f[I] - K_ID @ x_start)
    g_K, g_M = phi.T @ (K_ID @ x_moving), phi.T @ (M_ID @ x_moving)
    T = ramp.t_ramp
    t = np.linspace(0.0, t_end, max(int(frames), 2))
    eta, deta = PhiM @ u[I], PhiM @ v[I]
    pieces = [(0.0, f0 - zeta * g_M / T, -g_K / T), (T, f0 - g_K, np.zeros_like(f0))]
    q, dq, ddq = (np.empty((len(w2), len(t))) for _ in range(3))
    for k, (t0, a, b) in enumerate(pieces):
        t1 = pieces[k + 1][0] if k + 1 < len(pieces) else np.inf
        if t0 > t_end:
            break
        a = a + b * t0                    # the force in local time tau = t - t0
        B = b / w2
        A = (a - zeta * B) / w2
        sel = (t >= t0) & (t < t1)
        tau = t[sel] - t0
        C, S = _free_response(w2, zeta, tau)
        y0, dy0 = (eta - A)[:, None], (deta - B)[:, None]
        q[:, sel] = A[:, None] + B[:, None] * tau + y0 * C + (dy0 + 0.5 * zeta * y0) * S
        dq[:, sel] = B[:, None] + dy0 * C - (w2[:, None] * y0 + 0.5 * zeta * dy0) * S
        ddq[:, sel] = a[:, None] + b[:, None] * tau - zeta * dq[:, sel] - w2[:, None] * q[:, sel]
        if np.isfinite(t1):               # the state at the next kink, then its jump
            C, S = _free_response(w2, zeta, np.array([t1 - t0]))
            y0, dy0 = eta - A, deta - B
            eta = A + B * (t1 - t0) + y0 * C[:, 0] + (dy0 + 0.5 * zeta * y0) * S[:, 0]
            deta = B + dy0 * C[:, 0] - (w2 * y0 + 0.5 * zeta * dy0) * S[:, 0] + g_M / T
    s = np.clip(t / T, 0.0, 1.0)
    uu, vv = np.empty((len(t), basis.N)), np.empty((len(t), basis.N))
    uu[:, I], vv[:, I] = (phi @ q).T, (phi @ dq).T
    uu[:, D] = x_start + s[:, None] * x_moving
    vv[:, D] = np.where(t < T, 1.0 / T, 0.0)[:, None] * x_moving
    return system.result(D, t, uu, vv, (phi @ ddq).T, I, None,
                         {"modes": int(len(w2)), "method": "modal"})


def _free_response(w2, zeta, tau):
    """(C, S) (modes, times): the free response of y'' + zeta y' + omega^2 y = 0 is
    y0 C + (y0' + zeta y0 / 2) S, its rate y0' C - (omega^2 y0 + zeta y0' / 2) S, with
    C = exp(-zeta tau / 2) cosh(lam tau), S = exp(-zeta tau / 2) sinh(lam tau) / lam and
    lam^2 = zeta^2 / 4 - omega^2 (imaginary when underdamped: cos and sin / omega_d). Written
    with decaying exponentials only, and expm1 where lam tau is small (S -> tau at critical
    damping)."""
    lam = np.sqrt((0.25 * zeta**2 - w2).astype(complex))[:, None]
    tau = np.asarray(tau, dtype=float)[None, :]
    up, down = np.exp((lam - 0.5 * zeta) * tau), np.exp(-(lam + 0.5 * zeta) * tau)
    C = 0.5 * (up + down)
    small = np.abs(lam * tau) < 0.5
    safe = np.where(lam == 0, 1.0, lam)
    S = np.where(small, down * np.where(lam == 0, tau, np.expm1(2 * lam * tau) / (2 * safe)),
                 (up - down) / (2 * safe))
    return C.real, S.real


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
