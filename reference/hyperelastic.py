"""Static compressible neo-Hookean elasticity: Newton in load steps, P1 or P2 on the mesh
refined uniformly, in displacement form or mixed (Taylor-Hood P2/P1, u and p), and a
converged reference with its error estimate (as ``reference.linear.converged``).

W = mu/2 (tr C - 3) - mu ln J + lam/2 (ln J)^2, the first Piola-Kirchhoff stress
P = mu (F - F^-T) + lam ln J F^-T; for large deformation and rotation, where linear FEM is
wrong by construction. The mixed form carries p = lam ln J as a field of its own
(``reference._neohookean``), which keeps P2 accurate up to nu = 0.499.
"""
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from scipy.optimize import brentq
from skfem import Basis, ElementTetP1, FacetBasis

from model.bc import bc_arrays, load_fractions
from model.errors import ConvergenceError, ModelError
from model.material import as_material, neohookean_stress
from ._neohookean import neohookean
from .assembly import scalar_gradients
from .discretisation import (INTORDER, dirichlet_dofs, element_basis, parent_of, probe,
                             refine_with_data, skfem_mesh)
from .solvers import NewtonSolver, SaddleSolver, check_finite
from .stress import stress_measures, stress_on_input
from .linear import body_load, converged_from, dof_component, traction_load, transfer_to_nodes

# above this Poisson ratio ``converged(mixed="auto")`` solves the mixed (u, p) form: the
# displacement form's volumetric locking grows with lam / mu (9 at nu = 0.45, 49 at 0.49)
MIXED_ABOVE_NU = 0.45
# Newton from a coarser level's field (nested iteration) is given up after this many
# iterations for the load steps from rest
NESTED_MAX_ITER = 10
# inexact Newton (Eisenstat and Walker's second choice): an iteration's tangent is solved to a
# relative residual eta of at most ETA_MAX, tighter as Newton's residual falls, and never
# tighter than the step to the tolerance needs (ETA_FLOOR_SHARE x tolerance / residual) or
# than solvers.linear_solve's own 1e-10: AMG-CG does a third of the iterations, the solution
# is the same to the tolerance
ETA_MAX = 1e-3
ETA_FLOOR_SHARE = 0.1


@dataclass
class HyperelasticResult:
    """``u`` (n, 3) [m] at the input nodes; ``stress`` (m, 3, 3) Cauchy stress per input
    tetrahedron (volume average); ``von_mises``, ``max_shear``, ``pressure`` (m,); ``reaction``
    (n, 3) [N]; ``energy`` the stored energy [J]; ``iterations`` Newton iterations in all;
    ``info`` element, formulation, refinement, dofs, load steps and the AMG-CG iterations of
    its tangent solves (``cg_iterations``, 0 where they were solved directly); the mixed
    form's ``factorisations`` and the ``gmres_iterations`` preconditioned by them."""

    u: np.ndarray
    stress: np.ndarray
    von_mises: np.ndarray
    max_shear: np.ndarray
    pressure: np.ndarray
    reaction: np.ndarray
    iterations: int
    info: dict
    energy: float = 0.0
    basis: object = field(default=None, repr=False)
    dofs: np.ndarray = field(default=None, repr=False)
    kept: dict = field(default_factory=dict, repr=False)
    p_basis: object = field(default=None, repr=False)     # the mixed form's pressure
    p_dofs: np.ndarray = field(default=None, repr=False)

    def at(self, points, step=None):
        """The displacement (k, 3) at arbitrary ``points`` (k, 3) inside the mesh, by the
        solution's own basis (what compares it with results on another mesh): at the end,
        or at load ``step`` when the solve kept it (``keep_steps``)."""
        if step is not None and step not in self.kept:
            raise ModelError(f"load step {step} was not kept: pass keep_steps=[{step}] to "
                             f"solve (kept: {sorted(self.kept)})")
        return probe(self.basis, self.dofs if step is None else self.kept[step], points)


class Discretisation:
    """The bases of one solve and the assembly of the neo-Hookean residual and tangent from
    the element kernel: the vector basis ``ub`` (P1 or P2) and, for the mixed form, the P1
    pressure basis ``pb`` on the same quadrature; unknowns [u dofs, p dofs]."""

    def __init__(self, m, element, mixed, lam, mu):
        self.ub = element_basis(m, element)
        self.mixed = bool(mixed)
        self.pb = Basis(m, ElementTetP1(), quadrature=self.ub.quadrature) if mixed else None
        self.lam, self.mu = float(lam), float(mu)
        self.grad, self.comp = scalar_gradients(self.ub)
        self.dx = np.ascontiguousarray(self.ub.dx)
        self.udofs = np.ascontiguousarray(self.ub.element_dofs.T)          # (nel, nb)
        nel, nq = self.dx.shape
        if mixed:
            self.psi = np.ascontiguousarray(np.stack(
                [f[0].value for f in self.pb.basis], axis=-1))            # (nel, nq, 4)
            self.pdofs = np.ascontiguousarray(self.pb.element_dofs.T) + self.ub.N
        else:
            self.psi = np.zeros((nel, nq, 0))
            self.pdofs = np.zeros((nel, 0), dtype=np.int64)
        self.N = self.ub.N + (self.pb.N if mixed else 0)
        dofs = np.hstack([self.udofs, self.pdofs])                          # (nel, nb + np)
        self.rows = np.repeat(dofs, dofs.shape[1], axis=1).ravel()
        self.cols = np.tile(dofs, (1, dofs.shape[1])).ravel()
        self.dofs = dofs

    def evaluate(self, x, tangent=True):
        """(residual (N,), tangent (CSR) or None, energy) at the unknowns ``x``."""
        nel, nb = self.udofs.shape
        npb = self.pdofs.shape[1]
        r_u, r_p = np.empty((nel, nb)), np.empty((nel, npb))
        shape = (nel, nb, nb), (nel, nb, npb), (nel, npb, npb)
        k_uu, k_up, k_pp = (np.empty(s) if tangent else np.empty((0, 0, 0)) for s in shape)
        energy, bad = neohookean(self.grad, self.comp, self.dx, x[self.udofs], self.psi,
                                 x[self.pdofs], self.lam, self.mu, self.mixed, tangent,
                                 r_u, r_p, k_uu, k_up, k_pp)
        if bad >= 0:
            raise ConvergenceError(f"neo-Hookean: element {bad} inverted (det F <= 0); use "
                                   "more load steps")
        res = np.bincount(self.dofs.ravel(), weights=np.hstack([r_u, r_p]).ravel(),
                          minlength=self.N)
        if not tangent:
            return res, None, energy
        local = np.concatenate([np.concatenate([k_uu, k_up], axis=2),
                                np.concatenate([np.transpose(k_up, (0, 2, 1)), k_pp], axis=2)],
                               axis=1)
        K = sp.csr_matrix((local.ravel(), (self.rows, self.cols)), shape=(self.N, self.N))
        return res, K, energy

    def cauchy(self, x):
        """The Cauchy stress (3, 3, nel, nq) of the unknowns ``x``: (mu (F F^T - I) + p I) / J
        with p = lam ln J, or the pressure field in the mixed form."""
        w = self.ub.interpolate(x[:self.ub.N])
        F = w.grad + np.eye(3)[:, :, None, None]
        J = np.linalg.det(np.moveaxis(F, (0, 1), (-2, -1)))
        # sigma = P F^T / J = (a F F^T + b I) / J of the law's P = a F + b F^-T; the mixed
        # form's pressure p takes the place of lam ln J in b
        a, b = neohookean_stress(np.log(J), self.lam, self.mu)
        if self.mixed:
            b = self.pb.interpolate(x[self.ub.N:]).value - self.mu
        FFt = np.einsum("ik...,jk...->ij...", F, F)
        return (a * FFt + b * np.eye(3)[:, :, None, None]) / J


def solve(mesh, material, dirichlet, body_force=None, element="P1", refine=0, dirichlet_fn=None,
          load_steps=1, rtol=1e-10, max_iter=30, on_step=None, mixed=False, traction=None,
          keep_steps=(), start=None):
    """Neo-Hookean equilibrium on ``mesh`` (a model.mesh.TetMesh) refined ``refine`` times, of
    ``material`` (the model.material.Material: E [Pa], nu; rho is not read).

    Newton in ``load_steps`` equal increments (or at the load fractions it lists, as
    ``model.bc.load_fractions`` reads them) of the prescribed displacement, body force and
    ``traction`` (a dead load: force per reference area, the callable
    ``reference.linear.solve`` takes),
    each converged to max |residual| <= rtol * E h^2 (h the mean edge of the solved mesh; the
    pressure equations of the mixed form to rtol * h^3). Raises ConvergenceError otherwise.
    ``element`` "P1" or "P2"; ``mixed`` solves the Taylor-Hood P2/P1 (u, p) form (P2 only).
    ``dirichlet`` and ``dirichlet_fn`` as ``reference.linear.solve`` takes them.
    ``on_step(step, u, reaction)``, when given, is called after every converged step with the
    nodal displacement (n, 3) and reaction (n, 3) at that load (a force-displacement curve in
    one solve). The displacement dofs of the steps in ``keep_steps`` are kept, for
    ``HyperelasticResult.at(points, step)``.

    ``start``, the result of the same problem on a coarser level (nested iteration; only
    where no step is reported or kept): Newton starts from its field, interpolated here, and
    takes the whole load at once; where that does not converge or inverts an element, the
    load steps run from rest as without it. The solution is the same to the tolerance."""
    material = as_material(material, "reference.hyperelastic.solve")
    lam, mu = material.lame
    if mixed and element != "P2":
        raise ModelError(f"the mixed (u, p) form is Taylor-Hood P2/P1: pass element='P2', got "
                         f"{element!r}")
    if int(refine) != refine or refine < 0:
        raise ModelError(f"refine must be a non-negative integer, got {refine!r}")
    fractions = load_fractions(load_steps)
    load_steps = len(fractions)
    mask, vals = bc_arrays(dirichlet, mesh.n_nodes)
    if not mask.any():
        raise ModelError("no Dirichlet condition: the problem is singular; prescribe nodes")
    m, mask_f, vals_f, W = refine_with_data(skfem_mesh(mesh), mask, vals, dirichlet_fn,
                                            int(refine))
    d = Discretisation(m, element, mixed, lam, mu)
    ub = d.ub
    D, x_D = dirichlet_dofs(ub, mask_f, vals_f, dirichlet_fn)
    f_body = np.zeros(d.N)
    if body_force is not None:
        f_body[:ub.N] = body_load(ub, body_force)
    if traction is not None:
        f_body[:ub.N] += traction_load(FacetBasis(m, ub.elem, intorder=INTORDER[element]),
                                       traction)
    comp = dof_component(ub)
    prescribed = np.zeros(d.N, dtype=bool)
    prescribed[D] = True
    I = np.flatnonzero(~prescribed)
    Iu, Ip = I[I < ub.N], I[I >= ub.N]
    h = np.linalg.norm(np.diff(m.p[:, m.edges], axis=1), axis=0).mean()
    floor_u, floor_p = rtol * material.E * h * h, rtol * h ** 3
    x = np.zeros(d.N)
    target = np.zeros(d.N)
    target[D] = x_D[D]
    iters = 0
    kept = {}
    newton_solve = SaddleSolver() if mixed else NewtonSolver()
    x0, schedule = x, fractions
    if start is not None and on_step is None and not keep_steps:
        x0, schedule = _interpolated(start, d), [1.0]
    try:     # from a coarser level's field, Newton converges in a few iterations or not
        x, iters, res, kept = _newton(d, x0, schedule, D, I, Iu, Ip, target, f_body,
                                      floor_u, floor_p, max_iter if schedule is fractions
                                      else min(max_iter, NESTED_MAX_ITER), newton_solve,
                                      keep_steps, on_step, ub, W, mesh)
    except ConvergenceError:
        if schedule is fractions:
            raise
        x, iters, res, kept = _newton(d, x, fractions, D, I, Iu, Ip, target, f_body,
                                      floor_u, floor_p, max_iter, newton_solve, keep_steps,
                                      on_step, ub, W, mesh)
    res, _, energy = d.evaluate(x, tangent=False)
    res -= f_body
    reaction = transfer_to_nodes(ub, W, D, res[D])
    stress, _ = stress_on_input(ub, W, mesh, d.cauchy(x))
    vm, tmax, p = stress_measures(stress)
    u_all = x[:ub.N]
    return HyperelasticResult(
        u=check_finite("displacement", u_all[ub.nodal_dofs[:, :mesh.n_nodes]].T.copy()),
        stress=stress, von_mises=vm, max_shear=tmax, pressure=p, reaction=reaction,
        iterations=iters, energy=float(energy), basis=ub, dofs=u_all, kept=kept,
        p_basis=d.pb, p_dofs=x[ub.N:].copy() if mixed else None,
        info={"element": element, "mixed": bool(mixed), "refine": int(refine),
              "dofs": int(d.N), "load_steps": int(load_steps),
              "cg_iterations": int(getattr(newton_solve, "cg_iterations", 0)),
              **({"factorisations": newton_solve.factorisations,
                  "gmres_iterations": newton_solve.krylov_iterations} if mixed else {})})


def _interpolated(coarse, d):
    """The unknowns of discretisation ``d`` from the ``coarse`` result's field (and pressure)
    at its dofs: exact where the spaces nest (one uniform refinement, :func:`prolong`)."""
    ub = d.ub
    x = np.zeros(d.N)
    nested = prolong(coarse.basis, coarse.dofs, ub)
    if nested is None:
        comp = dof_component(ub)
        x[:ub.N] = probe(coarse.basis, coarse.dofs, ub.doflocs.T)[np.arange(ub.N), comp]
    else:
        x[:ub.N] = nested
    if d.mixed and coarse.p_dofs is not None:
        pc, pf = coarse.p_basis, d.pb
        if _one_refinement(pc.mesh, pf.mesh):   # P1 at the new vertices: their edges' means
            p = np.zeros(pf.N)
            p[pf.nodal_dofs[0]] = _hats(pc.mesh) @ coarse.p_dofs[pc.nodal_dofs[0]]
        else:
            p = pc.probes(np.ascontiguousarray(pf.doflocs)) @ coarse.p_dofs
        x[ub.N:] = p
    return x


def _one_refinement(mc, mf):
    """Whether ``mf`` is ``mc`` refined once: its vertices ``mc``'s, then ``mc``'s edges'
    midpoints (the counts alone can agree by chance: the five lattice of 2 cells and of 4)."""
    nv = mc.nvertices
    if mf.nvertices != nv + mc.edges.shape[1] or mf.nelements != 8 * mc.nelements:
        return False
    mids = 0.5 * (mc.p[:, mc.edges[0]] + mc.p[:, mc.edges[1]])
    scale = np.abs(mc.p).max()
    return bool(np.allclose(mf.p[:, :nv], mc.p, rtol=0, atol=1e-12 * scale)
                and np.allclose(mf.p[:, nv:], mids, rtol=0, atol=1e-12 * scale))


def _hats(mc):
    """(fine vertices x coarse vertices): the coarse P1 hats at the vertices of ``mc``
    refined once (its vertices, then its edges' midpoints)."""
    e0, e1 = mc.edges
    eye = sp.identity(mc.nvertices, format="csr")
    return sp.vstack([eye, 0.5 * (eye[e0] + eye[e1])], format="csr")


# the vertex pairs of a tetrahedron's six edges in scikit-fem's order (MeshTet.t2e)
TET_EDGES = ((0, 1), (1, 2), (0, 2), (0, 3), (1, 3), (2, 3))


def prolong(coarse_basis, dofs, fine_basis):
    """The vector field ``dofs`` of ``coarse_basis`` (P1 or P2) as the dofs of ``fine_basis``
    (the same element on the coarse mesh refined once): each fine element's nodes evaluated
    in its parent by barycentric coordinates, exact (the coarse space is inside the fine
    one). None where the meshes are not one refinement apart."""
    mc, mf = coarse_basis.mesh, fine_basis.mesh
    p2 = coarse_basis.edge_dofs.size > 0
    if not _one_refinement(mc, mf) or p2 != (fine_basis.edge_dofs.size > 0):
        return None
    parent = parent_of(mf, _hats(mc), mc.t.T)
    tP = mc.t[:, parent]                                               # (4, nf)
    pairs = np.sort(mc.edges[:, mc.t2e[:, 0]], axis=0).T
    if [tuple(r) for r in pairs] != [tuple(sorted((mc.t[a, 0], mc.t[b, 0])))
                                     for a, b in TET_EDGES]:
        raise AssertionError("scikit-fem's local edge order is not TET_EDGES")
    nodal = dofs[coarse_basis.nodal_dofs]                               # (3, nv)
    values = [nodal[:, tP]]                                            # (3, 4, nf)
    if p2:
        values.append(dofs[coarse_basis.edge_dofs][:, mc.t2e[:, parent]])
    values = np.concatenate(values, axis=1)                            # (3, 4 or 10, nf)
    X0 = mc.p[:, tP[0]]
    A = np.stack([mc.p[:, tP[k]] - X0 for k in (1, 2, 3)], axis=-1)   # (3, nf, 3): edges
    Ainv = np.linalg.inv(np.moveaxis(A, 1, 0))                         # (nf, 3, 3)

    def at(points):                                  # (3, k, nf) -> field (3, k, nf)
        lam = np.einsum("fij,jkf->ikf", Ainv, points - X0[:, None, :])
        lam = np.concatenate([1.0 - lam.sum(axis=0, keepdims=True), lam])   # (4, k, nf)
        shape = [lam]
        if p2:
            shape = [lam * (2 * lam - 1)] + [4 * lam[a] * lam[b] for a, b in TET_EDGES]
            shape = [shape[0]] + [s[None] for s in shape[1:]]
        N = np.concatenate(shape)                                      # (4 or 10, k, nf)
        return np.einsum("cnf,nkf->ckf", values, N)

    out = np.zeros(fine_basis.N)
    tf = mf.t
    out[fine_basis.nodal_dofs[:, tf]] = at(mf.p[:, tf])
    if p2:
        mids = 0.5 * (mf.p[:, mf.edges[0, mf.t2e]] + mf.p[:, mf.edges[1, mf.t2e]])
        out[fine_basis.edge_dofs[:, mf.t2e]] = at(mids)
    return out


def _newton(d, x, fractions, D, I, Iu, Ip, target, f_body, floor_u, floor_p, max_iter,
            newton_solve, keep_steps, on_step, ub, W, mesh):
    """Newton through the load ``fractions`` from ``x``: (x, iterations, residual, kept)."""
    load_steps = len(fractions)
    iters = 0
    kept = {}
    mixed = d.mixed
    comp = dof_component(ub)
    rn = rp = np.inf
    for step, s in enumerate(fractions, start=1):
        last = None
        for _ in range(max_iter):
            res, K, _ = d.evaluate(x)
            res -= s * f_body
            rn = np.abs(res[Iu]).max(initial=0.0)
            rp = np.abs(res[Ip]).max(initial=0.0)
            if rn <= floor_u and rp <= floor_p and np.array_equal(x[D], s * target[D]):
                break
            # the first iteration of a step carries the load increment: its residual is no
            # measure of how far the solution is, so the step's forcing starts from there
            eta = ETA_MAX if last is None else forcing(rn, last, floor_u)
            last = rn
            # Newton step; its prescribed part carries the load increment (a tangent
            # predictor, so that the interior follows the boundary instead of inverting)
            dx = np.zeros(d.N)
            dx[D] = s * target[D] - x[D]
            b = -res[I] - K[I][:, D] @ dx[D]
            A = K[I][:, I]
            locs = (None, None) if mixed else (ub.doflocs.T[I], comp[I])
            dx[I] = newton_solve(A, b, *locs, rtol=eta)[0]
            x = x + dx
            x[D] = s * target[D]
            iters += 1
        else:
            raise ConvergenceError(f"neo-Hookean Newton did not converge in {max_iter} "
                                   f"iterations at load step {step}/{load_steps}: residual "
                                   f"{rn:.3e} N (pressure {rp:.3e} m^3); increase load_steps")
        if step in keep_steps:
            kept[step] = x[:ub.N].copy()
        if on_step is not None:
            on_step(step, x[ub.nodal_dofs[:, :mesh.n_nodes]].T,
                    transfer_to_nodes(ub, W, D, res[D]))
    return x, iters, res, kept


def forcing(rn, rn_last, floor):
    """The relative tolerance of the next tangent solve (Eisenstat and Walker 1996, choice 2,
    gamma 0.9, alpha 2): 0.9 (rn / rn_last)^2, at most ETA_MAX, and at least
    ETA_FLOOR_SHARE floor / rn (the accuracy a step to the tolerance ``floor`` needs) and
    1e-10; ETA_MAX where either residual is zero (the first iteration of a step from rest
    has none inside: its load is all in the prescribed increment)."""
    if not (rn > 0 and rn_last > 0):
        return ETA_MAX
    return float(max(min(0.9 * (rn / rn_last) ** 2, ETA_MAX), ETA_FLOOR_SHARE * floor / rn,
                     1e-10))


def uniaxial(stretch, material):
    """The law of ``material`` (the model.material.Material: E [Pa], nu) in homogeneous
    uniaxial ``stretch`` [-] with free lateral faces: (lateral stretch l, nominal axial stress
    P [Pa]). The lateral faces are free when mu (l - 1/l) +
    lam ln(J) / l = 0 with J = stretch l^2; then P = mu (stretch - 1/stretch) +
    lam ln(J) / stretch (negative in compression)."""
    lam, mu = as_material(material, "reference.hyperelastic.uniaxial").lame
    if not (np.isfinite(stretch) and stretch > 0):
        raise ModelError(f"a stretch must be a finite number > 0, got {stretch!r}")
    def nominal(along, lateral):
        """The law's nominal stress P = a F + b F^-T on the diagonal entry of stretch
        ``along``, the lateral stretches ``lateral``."""
        a, b = neohookean_stress(np.log(stretch * lateral * lateral), lam, mu)
        return a * along + b / along

    lat = brentq(lambda t: nominal(t, t), stretch ** -0.5 * 1e-3, stretch ** -0.5 * 1e3)
    return float(lat), float(nominal(stretch, lat))


def converged(mesh, material, dirichlet, levels=1, element="P2", mixed=True, **kw):
    """Solve on ``mesh`` refined 0..levels times and estimate the error of the finest, as
    ``reference.linear.converged`` does: the relative changes of the nodal displacement and
    of the stored energy between levels give an observed rate and a Richardson estimate; the
    larger of the two estimates is the reference's. ``mixed`` True, False or "auto" (mixed
    above nu = MIXED_ABOVE_NU); ``kw`` as :func:`solve` takes them."""
    material = as_material(material, "reference.hyperelastic.converged")
    if mixed == "auto":
        mixed = material.nu > MIXED_ABOVE_NU
    if levels < 1:
        raise ModelError(f"converged needs levels >= 1 to estimate its error, got {levels}")
    sols = []
    for k in range(levels + 1):     # each level started from the one before (nested)
        sols.append(solve(mesh, material, dirichlet, element=element, mixed=mixed, refine=k,
                          start=sols[-1] if sols else None, **kw))
    return converged_from(sols)


__all__ = ["solve", "converged", "uniaxial", "HyperelasticResult", "Discretisation"]
