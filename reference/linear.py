"""Static linear elasticity with scikit-fem (P1 or P2, optionally on a refined mesh)."""
from dataclasses import dataclass, field

import numpy as np
from skfem import FacetBasis, LinearForm, asm, condense
from skfem.helpers import dot, sym_grad
from skfem.models.elasticity import linear_elasticity, linear_stress

from model.bc import bc_arrays
from model.errors import ModelError
from .fem import (INTORDER, cell_average, check_finite, dirichlet_dofs, dof_hats,
                  element_basis, lame,
                  linear_solve, parent_of, refine_with_data, skfem_mesh, stress_measures)


@dataclass
class LinearResult:
    """Solution on the input mesh.

    ``u`` (n, 3) displacement at the mesh nodes [m]; ``stress`` (m, 3, 3) Cauchy stress per
    tetrahedron of the input mesh (its volume average: exact for P1, the centroid value for P2);
    ``stress_nodes`` (n, 3, 3) volume-weighted nodal average; ``von_mises``, ``max_shear``,
    ``pressure`` (m,) per tetrahedron [Pa]; ``reaction`` (n, 3) force the supports exert [N];
    ``energy`` strain energy [J]; ``info`` element, refinement, dofs and solver.
    """

    u: np.ndarray
    stress: np.ndarray
    stress_nodes: np.ndarray
    von_mises: np.ndarray
    max_shear: np.ndarray
    pressure: np.ndarray
    reaction: np.ndarray
    energy: float
    info: dict = field(default_factory=dict)


def body_load(b):
    @LinearForm
    def form(v, w):
        return dot(np.asarray(b, dtype=float)[:, None, None] * np.ones_like(v), v)
    return form


def traction_load(fn):
    @LinearForm
    def form(v, w):
        x = np.moveaxis(w.x, 0, -1)                   # (..., 3) points
        n = np.moveaxis(w.n, 0, -1)
        t = np.moveaxis(np.asarray(fn(x, n), dtype=float), -1, 0)
        return dot(t, v)
    return form


def solve(mesh, E, nu, dirichlet, body_force=None, traction=None, element="P1", refine=0,
          dirichlet_fn=None, solver="auto"):
    """Linear elastic equilibrium on ``mesh`` (a model.mesh.TetMesh).

    Parameters
    ----------
    dirichlet : mapping node -> (ux, uy, uz), None for a free component (as the model takes).
    body_force : (3,) force per unit volume [N/m^3], e.g. rho * g.
    traction : callable ``(points (..., 3), normals (..., 3)) -> (..., 3)`` [Pa] on the boundary
        facets (return zero where unloaded).
    element : "P1" or "P2".
    refine : uniform refinements before solving; results come back on the input mesh.
    dirichlet_fn : ``points (k, 3) -> (k, 3)``, the prescribed displacement at new boundary
        points (P2 midpoints, refined nodes) where both edge ends are prescribed; linear
        interpolation when None.
    solver : "auto" (direct up to 60 000 unknowns, else pyamg-preconditioned CG), "direct", "amg".
    """
    lam, mu = lame(E, nu)
    n = mesh.n_nodes
    mask, vals = bc_arrays(dirichlet, n)
    if not mask.any():
        raise ModelError("no Dirichlet condition: the linear system is singular (rigid motions "
                         "are free); prescribe at least three non-collinear nodes")
    if int(refine) != refine or refine < 0:
        raise ModelError(f"refine must be a non-negative integer, got {refine!r}")
    coarse = skfem_mesh(mesh)
    m, mask_f, vals_f, W = refine_with_data(coarse, mask, vals, dirichlet_fn, refine)
    basis = element_basis(m, element)
    D, x_D = dirichlet_dofs(basis, mask_f, vals_f, dirichlet_fn)
    K = asm(linear_elasticity(lam, mu), basis)
    f = np.zeros(basis.N)
    if body_force is not None:
        f += asm(body_load(body_force), basis)
    if traction is not None:
        fb = FacetBasis(m, basis.elem, intorder=INTORDER[element])
        f += asm(traction_load(traction), fb)
    A, b, x, I = condense(K, f, x=x_D, D=D)
    xI, sinfo = linear_solve(A, b, basis.doflocs.T[I], dof_component(basis)[I], solver)
    x[I] = check_finite("displacement", xI)
    u_all = x
    # reactions: K u - f on the prescribed dofs, carried to the input nodes by the P1 hats
    reaction = transfer_to_nodes(basis, W, D, (K @ u_all - f)[D])
    u = u_all[basis.nodal_dofs[:, :n]].T
    # stress: volume average over each input tetrahedron of the solution's stress
    w = basis.interpolate(u_all)
    sig = linear_stress(lam, mu)(sym_grad(w))
    sig_fine = np.moveaxis(cell_average(basis, sig), -1, 0)         # (m_fine, 3, 3)
    vol_fine = basis.dx.sum(axis=1)
    parent = parent_of(m, W, mesh.tets)
    vol = np.bincount(parent, weights=vol_fine, minlength=mesh.n_tets)
    stress = np.stack([np.bincount(parent, weights=vol_fine * sig_fine[:, i, j],
                                   minlength=mesh.n_tets)
                       for i in range(3) for j in range(3)], axis=1).reshape(-1, 3, 3)
    stress /= vol[:, None, None]
    vm, tmax, p = stress_measures(stress)
    node_vol = np.zeros(n)
    np.add.at(node_vol, mesh.tets, vol[:, None])
    stress_nodes = np.zeros((n, 3, 3))
    np.add.at(stress_nodes, mesh.tets, (vol[:, None, None] * stress)[:, None])
    stress_nodes /= node_vol[:, None, None]
    return LinearResult(u=u, stress=stress, stress_nodes=stress_nodes, von_mises=vm,
                        max_shear=tmax, pressure=p, reaction=reaction,
                        energy=float(0.5 * u_all @ (K @ u_all)),
                        info={"element": element, "refine": int(refine), "dofs": int(basis.N),
                              **sinfo})


def transfer_to_nodes(basis, W, dofs, values):
    """Carry forces on ``dofs`` to the input mesh's nodes with its P1 hat functions
    (preserves their sum and first moments; the identity for P1 without refinement)."""
    hats = dof_hats(basis, W)[dofs]
    comp = dof_component(basis)[dofs]
    return np.column_stack([hats[comp == k].T @ values[comp == k] for k in range(3)])


def dof_component(basis):
    """The displacement component (0, 1, 2) each dof of a vector basis carries."""
    comp = np.empty(basis.N, dtype=int)
    for k in range(3):
        comp[basis.nodal_dofs[k]] = k
        if basis.edge_dofs.size:
            comp[basis.edge_dofs[k]] = k
    return comp


@dataclass
class ConvergedResult:
    """The finest P2 solution (``result``) of a refinement sequence, evaluated on the input
    mesh, with the reference's own error estimate: ``levels`` the refinements solved,
    ``increments`` relative nodal L2 change between successive levels, ``rate`` the observed
    convergence order, ``error_estimate`` the Richardson estimate of the finest level's
    relative nodal L2 error (the last increment when no rate can be observed)."""

    result: LinearResult
    levels: list
    increments: list
    rate: float
    error_estimate: float


def converged(mesh, E, nu, dirichlet, levels=2, **kw):
    """Solve with P2 on ``mesh`` refined 0..levels times and estimate the error of the finest."""
    if levels < 1:
        raise ModelError(f"converged needs levels >= 1 to estimate its error, got {levels}")
    sols = [solve(mesh, E, nu, dirichlet, element="P2", refine=k, **kw)
            for k in range(levels + 1)]
    norm = max(np.linalg.norm(sols[-1].u), 1e-300)
    inc = [float(np.linalg.norm(b.u - a.u) / norm) for a, b in zip(sols, sols[1:])]
    rate = float(np.log2(inc[-2] / inc[-1])) if len(inc) > 1 and inc[-1] > 0 else float("nan")
    if np.isfinite(rate) and rate > 0.5:
        est = inc[-1] / (2**rate - 1)
    else:
        est = inc[-1]
    return ConvergedResult(result=sols[-1], levels=list(range(levels + 1)), increments=inc,
                           rate=rate, error_estimate=float(est))
