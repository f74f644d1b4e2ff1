"""Plumbing shared by the FEM references: the scikit-fem mesh of a TetMesh, refinement that
carries Dirichlet data along, element choice, Dirichlet dofs, linear solvers, stress measures.

Physics lives in the modules that use it (linear.py, hyperelastic.py, modal.py); the mesh and
the boundary-condition format come from ``model``, nothing else does.
"""
import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import spsolve
from skfem import Basis, ElementTetP1, ElementTetP2, ElementVector, MeshTet

from model.errors import ConvergenceError, MaterialError, ModelError

ELEMENTS = {"P1": ElementTetP1, "P2": ElementTetP2}
INTORDER = {"P1": 1, "P2": 2}  # exact for the stiffness, and for a constant body force
DIRECT_MAX_DOFS = 60_000       # beyond this scipy's direct solver runs out of memory and time


def lame(E, nu):
    """(lambda, mu) after checking E > 0 and -1 < nu < 0.5."""
    if not (np.isfinite(E) and E > 0):
        raise MaterialError(f"Young's modulus E must be a finite number > 0 Pa, got {E!r}")
    if not (np.isfinite(nu) and -1.0 < nu < 0.5):
        raise MaterialError(f"Poisson's ratio nu must satisfy -1 < nu < 0.5, got {nu!r}")
    return E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))


def skfem_mesh(mesh):
    return MeshTet(np.ascontiguousarray(mesh.points.T), np.ascontiguousarray(mesh.tets.T))


def refine_with_data(m, mask, vals, dirichlet_fn, levels):
    """Refine ``levels`` times; a new node at the midpoint of a boundary edge whose two ends
    carry a value in a component gets ``dirichlet_fn(point)`` there, or the mean of the ends.

    Also returns W (sparse, fine nodes x input nodes): the input mesh's P1 hat functions at
    every fine node, built as the mean of the two parents' rows (hats are linear on edges).
    """
    W = sp.identity(m.nvertices, format="csr")
    for _ in range(levels):
        e = m.edges[:, m.boundary_edges()]
        both = mask[e[0]] & mask[e[1]]                       # (k, 3)
        new_vals = 0.5 * (vals[e[0]] + vals[e[1]])
        mid = 0.5 * (m.p[:, e[0]] + m.p[:, e[1]]).T
        if dirichlet_fn is not None and len(mid):
            new_vals = np.asarray(dirichlet_fn(mid), dtype=float).reshape(-1, 3)
        n_old = m.nvertices
        nm, nv = np.zeros((m.edges.shape[1], 3), bool), np.zeros((m.edges.shape[1], 3))
        nm[m.boundary_edges()] = both
        nv[m.boundary_edges()] = np.where(both, new_vals, 0.0)
        W = sp.vstack([W, 0.5 * (W[m.edges[0]] + W[m.edges[1]])], format="csr")
        m = m.refined()
        assert m.nvertices == n_old + len(nm)  # new vertices are the old edges' midpoints
        mask, vals = np.vstack([mask, nm]), np.vstack([vals, nv])
    return m, mask, vals, W


def dof_hats(basis, W):
    """Sparse (N dofs x input nodes): the input mesh's P1 hats at every dof's location
    (vertex dofs take their node's row of W, P2 edge dofs the mean of their ends' rows)."""
    H = W
    dofs = [basis.nodal_dofs]
    if basis.edge_dofs.size:
        e = basis.mesh.edges
        H = sp.vstack([W, 0.5 * (W[e[0]] + W[e[1]])], format="csr")
        dofs.append(basis.edge_dofs)
    dof_index = np.concatenate([np.concatenate([d[k] for d in dofs]) for k in range(3)])
    place = sp.csr_matrix((np.ones(len(dof_index)), (dof_index, np.arange(len(dof_index)))),
                          shape=(basis.N, len(dof_index)))
    return place @ sp.vstack([H, H, H], format="csr")


def element_basis(m, element, intorder=None):
    if element not in ELEMENTS:
        raise ModelError(f"element must be one of {', '.join(ELEMENTS)}, got {element!r}")
    return Basis(m, ElementVector(ELEMENTS[element]()), intorder=intorder or INTORDER[element])


def dirichlet_dofs(basis, mask, vals, dirichlet_fn):
    """Prescribed dof indices and the full vector of their values. For P2 the midpoint dof of a
    boundary edge whose two ends are prescribed in a component is prescribed too."""
    m = basis.mesh
    D = [basis.nodal_dofs.T[mask]]
    x = np.zeros(basis.N)
    x[basis.nodal_dofs.T[mask]] = vals[mask]
    if basis.edge_dofs.size:
        be = m.boundary_edges()
        e = m.edges[:, be]
        both = mask[e[0]] & mask[e[1]]
        mid = 0.5 * (m.p[:, e[0]] + m.p[:, e[1]]).T
        ev = (np.asarray(dirichlet_fn(mid), dtype=float).reshape(-1, 3)
              if dirichlet_fn is not None and len(mid) else 0.5 * (vals[e[0]] + vals[e[1]]))
        dofs = basis.edge_dofs.T[be]
        D.append(dofs[both])
        x[dofs[both]] = ev[both]
    return np.concatenate(D), x


def rigid_modes(points, comp):
    """Six rigid-body modes (N, 6) of dofs at ``points`` (N, 3) carrying component ``comp``."""
    c = points - points.mean(axis=0)
    B = np.zeros((len(points), 6))
    B[np.arange(len(points)), comp] = 1.0
    # rotations about z, x, y: (-y, x, 0), (0, -z, y), (z, 0, -x)
    for col, (a, b) in zip((3, 4, 5), ((0, 1), (1, 2), (2, 0))):
        B[comp == a, col] = -c[comp == a, b]
        B[comp == b, col] = c[comp == b, a]
    return B


def linear_solve(A, b, doflocs, comp, solver="auto", rtol=1e-10):
    """Solve the SPD system A x = b: scipy's direct solver up to DIRECT_MAX_DOFS unknowns,
    else CG preconditioned by pyamg smoothed aggregation with the rigid-body modes as
    near-null space. ``doflocs`` (N, 3) and ``comp`` (N,) locate each unknown."""
    n = A.shape[0]
    if solver == "auto":
        solver = "direct" if n <= DIRECT_MAX_DOFS else "amg"
    if solver == "direct":
        return spsolve(A.tocsc(), b), {"solver": "direct", "iterations": 0}
    if solver != "amg":
        raise ModelError(f"solver must be 'auto', 'direct' or 'amg', got {solver!r}")
    import pyamg

    ml = pyamg.smoothed_aggregation_solver(A.tocsr(), B=rigid_modes(doflocs, comp),
                                           symmetry="symmetric")
    residuals = []
    x = ml.solve(b, tol=rtol, accel="cg", maxiter=500, residuals=residuals)
    rel = residuals[-1] / max(residuals[0], 1e-300)
    if not rel <= 10 * rtol:
        raise ConvergenceError(f"AMG-preconditioned CG stopped at relative residual {rel:.2e} "
                               f"> {rtol:g} after {len(residuals) - 1} iterations; the system "
                               "may be singular (enough Dirichlet conditions?)")
    return x, {"solver": "amg-cg", "iterations": len(residuals) - 1}


def cell_average(basis, field):
    """Volume average per element of a quadrature field (..., nel, nqp)."""
    return np.einsum("...eq,eq->...e", field, basis.dx) / basis.dx.sum(axis=1)


def parent_of(m_fine, W, coarse_tets):
    """Index of the input tetrahedron containing each fine one: the input nodes whose hats do
    not vanish on a fine tetrahedron are exactly its parent's four vertices."""
    if m_fine.nelements == len(coarse_tets):
        return np.arange(len(coarse_tets))
    S = (W[m_fine.t[0]] + W[m_fine.t[1]] + W[m_fine.t[2]] + W[m_fine.t[3]]).tocsr()
    S.sort_indices()
    if not np.all(np.diff(S.indptr) == 4):
        raise AssertionError("a refined tetrahedron straddles two input tetrahedra")
    def key(t):  # one opaque, consistently ordered scalar per row of four node indices
        return np.ascontiguousarray(t, dtype=np.int64).view(np.dtype((np.void, 32))).ravel()

    fine_key = key(S.indices.reshape(-1, 4))
    coarse_key = key(np.sort(coarse_tets, axis=1))
    order = np.argsort(coarse_key)
    return order[np.searchsorted(coarse_key[order], fine_key)]


def stress_measures(sigma):
    """von Mises, maximum shear (sigma_1 - sigma_3) / 2 and pressure -tr/3 of (m, 3, 3)."""
    eig = np.linalg.eigvalsh(sigma)
    dev = sigma - np.trace(sigma, axis1=1, axis2=2)[:, None, None] * np.eye(3) / 3
    return (np.sqrt(1.5 * np.einsum("mij,mij->m", dev, dev)),
            0.5 * (eig[:, -1] - eig[:, 0]), -np.trace(sigma, axis1=1, axis2=2) / 3)


def check_finite(name, a):
    if not np.all(np.isfinite(a)):
        raise ConvergenceError(f"{name} is not finite: the solve failed (singular system?)")
    return a
